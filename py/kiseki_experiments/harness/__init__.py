# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The experiment harness: what an experiment is (:mod:`.base`), its typed config
(:mod:`.config`), where its inputs are (:mod:`.paths`), what its records carry
(:mod:`.records`), its claims' verdicts (:mod:`.verdict`) and its scenes' calibration marks
(:mod:`.calibration`); and above the papers, the registry of every experiment
(:mod:`.registry`), the runner (:mod:`.runner`), the reports (:mod:`.report`) and the negative
controls (:mod:`.controls`).

This module imports nothing, so that a paper's module can import the harness modules below it
without loading the registry, which imports every paper."""
