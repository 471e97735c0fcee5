# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Teaching and playback in a simulated scene: a teaching run (`teaching`, by script or by
keyboard in `keyboard`) builds the environment maps and waypoints of `kiseki.teach`, and a
playback run (`playback`) follows a taught route with the localization engine. The methods
(maps, local maps, waypoints, the playback log) are in `kiseki.teach`."""

from __future__ import annotations

from kiseki.apps.teach.playback import PlaybackConfig, PlaybackResult, playback
from kiseki.apps.teach.teaching import teach
from kiseki.apps.teach.teaching_files import TeachResult

__all__ = ["PlaybackConfig", "PlaybackResult", "TeachResult", "playback", "teach"]
