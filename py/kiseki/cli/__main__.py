# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``python -m kiseki.cli``: the ``kiseki`` command."""

from kiseki.cli import main

if __name__ == "__main__":  # not when a tool walks the package and imports every module
    main()
