# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 004's occlusion- and width-aware speed limits: Fig. 4, the three situations (Figs. 5-7)
and the pedestrian safety check."""
