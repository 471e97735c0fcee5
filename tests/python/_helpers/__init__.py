# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What several test folders share: reading pictures back (`pixels`), the route page's server and
browser (`serve_pages`), the speed papers' reference figures (`speed_reference`) and the small
room and its run log that the command-line tests feed the commands (`room_log`); and what the
test files of one folder share: the modules and imports the house-layout checks read
(`module_imports`), the output guard's command runs and refusals (`output_guard`) and the
command-line boundary tests' (`boundaries_cli`). Importable as ``_helpers`` because pyproject's
pytest section puts tests/python on the path."""
