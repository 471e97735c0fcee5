# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The configs of the teaching experiments exp1-corridor, exp2-turn and exp3-boxes
(kiseki_experiments.teach.teach_playback) and their negative controls' ``plays``: a method
played under another's name."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated

from kiseki.apps.teach import PlaybackConfig
from kiseki.teach.local_maps import METHODS
from kiseki_experiments.harness.config import Boxes, Count, Factor, NonEmpty, Particles
from kiseki_experiments.harness.paths import WORLDS

__all__ = ["RAY_MODEL", "Exp1Config", "Exp2Config", "Exp3Config", "stand_ins"]


@dataclass(frozen=True)
class Exp1Config:
    scene: str = str(WORLDS / "factory_corridor.yaml")
    methods: Annotated[list[str], NonEmpty] = field(default_factory=lambda: ["proposal2"])
    particles: Particles = 1000
    boxes: Boxes = 0  # unknown boxes placed at random for playback (Exp. 3)
    merge: str = "thesis"  # the taught maps' merge rule: thesis or evidence
    # negative controls: "proposal2=conventional" plays the method named proposal2 with
    # conventional's local map and expected map (its records keep the name); "" = none
    plays: str = ""


@dataclass(frozen=True)
class Exp2Config:
    scene: str = str(WORLDS / "factory_turn.yaml")
    methods: Annotated[list[str], NonEmpty] = field(
        default_factory=lambda: ["conventional", "proposal1", "proposal2", "both"]
    )
    particles: Particles = 1000
    boxes: Boxes = 0
    merge: str = "thesis"
    plays: str = ""  # negative controls, as in Exp1Config


@dataclass(frozen=True)
class Exp3Config:
    scene: str = str(WORLDS / "factory_turn.yaml")
    methods: Annotated[list[str], NonEmpty] = field(default_factory=lambda: ["proposal2"])
    particles: Particles = 1000
    boxes: Boxes = 3
    # each run played again without the boxes (same teaching and seeds): table boxes_final_leg
    without_boxes: bool = True
    merge: str = "thesis"
    plays: str = ""  # negative controls, as in Exp1Config
    # also play each method with kiseki's ray space observation model (PlaybackConfig.model)
    # on the same teaching, boxes and seeds, reading L as a scan of ray_beams rays
    ray: bool = False
    ray_beams: Count = PlaybackConfig.scan_beams
    # the ray model's readings times this (1: as read; the control's miscalibrated range)
    ray_range_scale: Factor = PlaybackConfig.scan_range_scale


RAY_MODEL = "ray-space-observation"


def stand_ins(config) -> dict[str, str]:
    """The config's `plays`: method name -> the method played under that name."""
    out = {}
    for item in filter(None, (p.strip() for p in getattr(config, "plays", "").split(","))):
        name, _, played = (v.strip() for v in item.partition("="))
        if name not in METHODS or played not in METHODS:
            raise ValueError(
                f"plays: expected method=method pairs of {', '.join(METHODS)}, got {item!r}"
            )
        out[name] = played
    return out
