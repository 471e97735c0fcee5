# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Exception classes raised by kiseki.

Every error derives from :class:`KisekiError`; the format errors also derive from
:class:`ValueError` so that callers catching ``ValueError`` for bad input keep working.
"""

from __future__ import annotations

__all__ = ["KisekiError", "MapFormatError", "LogFormatError", "RelocalizationError"]


class KisekiError(Exception):
    """Base class of every kiseki error."""


class MapFormatError(KisekiError, ValueError):
    """A map file (ROS YAML + image, CMU .dat, ...) is missing a field, truncated or corrupt."""


class LogFormatError(KisekiError, ValueError):
    """A sensor log (CARMEN, ...) is truncated, corrupt or has no usable records."""


class RelocalizationError(KisekiError, ValueError):
    """A relocalization request whose map, scan or settings cannot be searched."""
