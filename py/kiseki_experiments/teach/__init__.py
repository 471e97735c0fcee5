# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The teaching-and-playback thesis' experiments (000_7c5a0f8de3fa28f5.txt): Exp. 1-3 in the
simulated factory, the layouts sweep, Fig. 3.14's likelihood check and the merge rules on real
logs."""
