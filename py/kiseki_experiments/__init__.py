# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's experiments, beside the library: one command per paper table or figure.

An experiment is a typed config, a trial function (one seeded trial -> a record) and an
analysis (records -> tables, figures, claims). The harness runs and reports them:
:func:`kiseki_experiments.harness.runner.run_experiment` runs an experiment's trials in-process
or on Dask and writes a results folder, :func:`kiseki_experiments.harness.report.write_reproduction`
gathers every experiment's claims, :mod:`kiseki_experiments.harness.registry` names them all.

One package per paper or topic, each using the library's public API and the harness:
``teach`` (the teaching-and-playback thesis), ``magnav`` and ``gp`` (the magnetic-navigation
thesis' chapters 4-5 and 6), ``terrain`` (the rubble paper), ``coop`` (cooperative
positioning), ``speed`` (occlusion-aware speed limits), ``mcl`` (the localization engine on
real logs and the kidnapped robot), ``mapping`` (the map builder's self-checks).
A paper's package imports no other paper's package: what two share is in the harness.
The library (``kiseki``) never imports this package; only its command line does.
"""
