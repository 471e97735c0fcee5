# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The config of layouts-exp2-exp3 (kiseki_experiments.teach.layouts) and the exp2-turn and
exp3-boxes configs it makes of it for one layout."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

from kiseki_experiments.harness.config import Boxes, NonEmpty, Particles, Runs
from kiseki_experiments.teach.teach_playback_config import Exp2Config, Exp3Config

__all__ = ["LayoutsConfig", "experiment_configs"]


@dataclass(frozen=True)
class LayoutsConfig:
    # Runs of each experiment per layout. The thesis' claims are means and counts over runs:
    # 2 is the fewest with a mean over runs and an SD (Exp. 3). 150 layouts x 2 runs took
    # 50 min on two workers (1000 particles); 3 runs per layout would take a third longer.
    runs_per_layout: Runs = 2
    methods: Annotated[list[str], NonEmpty] = field(
        default_factory=lambda: ["conventional", "proposal1", "proposal2", "both"]
    )
    particles: Particles = 1000
    boxes: Boxes = 3
    without_boxes: bool = True  # exp3-boxes' runs again without the boxes (Exp3Config)
    merge: str = "thesis"
    plays: str = ""  # negative controls: exp2-turn's methods played as others (Exp2Config)


def experiment_configs(config: LayoutsConfig, scene: Path, method: str | None = None) -> dict:
    """exp2-turn's and exp3-boxes' configs on layout `scene` (every method, or `method`)."""
    common = {"scene": str(scene), "particles": config.particles, "merge": config.merge}
    methods = list(config.methods) if method is None else [method]
    return {
        "exp2": Exp2Config(methods=methods, plays=config.plays, **common),
        "exp3": Exp3Config(boxes=config.boxes, without_boxes=config.without_boxes, **common),
    }
