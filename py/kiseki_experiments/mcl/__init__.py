# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The localization engine beyond the papers: excursions on real logs, the kidnapped robot, KLD
sampling."""
