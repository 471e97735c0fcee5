# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Hold Ctrl-C (SIGINT) and SIGTERM while a record is being written, and deliver them when it is
whole. Python runs signal handlers in the main thread between any two bytecodes, so an
interruption can land inside a library's write: the MCAP writer had then counted a message in
its statistics without writing it, and the summary written on close disagreed with the file
("the summary counts 46 messages, the file has 38"). A per-thread signal mask cannot prevent
this: the operating system hands a process-directed signal to any thread that does not block it
(the math libraries' workers), and Python still runs the handler in the main thread.

A :class:`SignalHold` installs, once, handlers that record a signal arriving inside
:meth:`SignalHold.section` and pass any other straight on to the handler that was there before;
the section's end delivers what it recorded. Only the main thread can install handlers and only
it receives Python's signal exceptions, so elsewhere a hold does nothing."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator

__all__ = ["SignalHold"]

HELD = (signal.SIGINT, signal.SIGTERM)


class SignalHold:
    """Handlers for SIGINT and SIGTERM that hold a signal during :meth:`section`."""

    def __init__(self) -> None:
        self._previous: dict[int, object] = {}
        self._depth = 0
        self._pending: list[int] = []
        if threading.current_thread() is not threading.main_thread():
            return
        try:
            for signum in HELD:
                self._previous[signum] = signal.signal(signum, self._receive)
        except (OSError, ValueError):  # not allowed here: leave the handlers as they were
            self.release()

    def _receive(self, signum: int, frame) -> None:
        if self._depth:
            self._pending.append(signum)
        else:
            self._deliver(signum, frame)

    def _deliver(self, signum: int, frame) -> None:
        handler = self._previous.get(signum, signal.SIG_DFL)
        if callable(handler):
            handler(signum, frame)  # Python's default raises KeyboardInterrupt for SIGINT
        elif handler != signal.SIG_IGN:  # the default action (or a handler set outside Python)
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)

    @contextlib.contextmanager
    def section(self) -> Iterator[None]:
        """A signal arriving inside waits until the outermost section ends."""
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
            if not self._depth and self._pending:
                pending, self._pending = self._pending, []
                for signum in dict.fromkeys(pending):
                    self._deliver(signum, None)

    def release(self) -> None:
        """Puts the previous handlers back (where ours are still installed); idempotent."""
        for signum, handler in self._previous.items():
            with contextlib.suppress(OSError, ValueError, TypeError):
                if signal.getsignal(signum) == self._receive:
                    signal.signal(signum, handler)  # type: ignore[arg-type]
        self._previous = {}
