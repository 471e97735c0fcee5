# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""File formats that are not a recorded dataset: ROS map YAML and images (`ros_map`, with
their model in `map_schema`), trajectory CSVs (`trajectory_csv`) and the run log, kiseki's
MCAP file of a run (`runlog`), which the simulator writes and the readers read.

This ``__init__`` imports nothing: the formats are independent, and the map files need
mapping's size limit while mapping needs the map file's model, so a module here is imported
by its own path (``from kiseki.io.ros_map import load_map``)."""
