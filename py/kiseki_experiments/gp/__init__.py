# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The magnetic-navigation thesis' chapter 6 (002_74cea16d239c028f.txt): GP magnetic maps (Table
6.2, the robotized floor mapping), magnetic-map MCL, and the pipeline on recorded data
(gp-aalto)."""
