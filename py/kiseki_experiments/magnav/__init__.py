# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The magnetic-navigation thesis' chapters 4-5 (002_74cea16d239c028f.txt): travel-distance
localization (Table 4.2), the navigators outdoors (Figs. 4.9-4.13) and LIDAR MCL with the magnetic
heading (Figs. 5.4-5.6)."""
