# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's private support modules, for every module of the project and of the experiments
beside it: atomic writes (`atomic`), bounded reads of inputs (`inputs`, `chunk_limits`,
`input_refs`), the one validation layer of file models (`schema`, `yaml`, `csv`, `table`), the
output guard of the commands (`outputs`, `guard`), the command-line options' bounds
(`options`) and the handling of Ctrl-C and SIGTERM (`interrupt`, `signal_hold`). Nothing here
imports an area of kiseki above core, and this ``__init__`` imports nothing, so that a module
that needs one helper loads only that one."""
