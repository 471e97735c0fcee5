# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The command line's numbers and options, checked while the command line is parsed.

* Every numeric option names its range as its parser
  (``typer.Option(None, parser=Count("--beams", 0, BEAM_LIMIT, "0 = every beam"))``): a
  :class:`Count` (an integer) or a :class:`Quantity` (a finite number in its unit:
  :func:`Metres`, :func:`Seconds`, :func:`Degrees`, :func:`Fraction`), or a :class:`Seed`.
  Each range fits the C++ type the number reaches (``int``, ``std::size_t``, ``uint64_t``,
  ``double``) and a physical or compute limit; the shared limits below say why. A value outside
  it, or not a number, is an :class:`OptionValueError` naming the option, raised while the
  command line is parsed, before the command does anything: ``kiseki: error: --beams must be
  an integer in 0..100,000 (0 = every beam), got 2147483648``, ``--dwell must be a finite number
  in [0, 3,600] s, got 1e308`` (the library's words: :func:`integer_rule`, :func:`number_rule`)
  and exit status 1, as every bad value (:func:`kiseki.cli.main`); never a NaN, an overflow in
  C++ or a numpy warning later.
* :func:`refuse_given`: options that do not apply to the chosen mode are errors too. An option
  counts as given when the command line set it, not its default (click's parameter source).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from kiseki import _core
from kiseki._support.counts import integer_rule
from kiseki._support.numbers_text import parse_float, parse_int
from kiseki._support.real_numbers import number_rule
from kiseki.core import SEED_RULE
from kiseki.errors import KisekiError

__all__ = [
    "BEAM_LIMIT",
    "CELL_LIMITS",
    "PARTICLE_LIMIT",
    "REACH_LIMIT",
    "RUN_LIMIT",
    "SIM_SECONDS_LIMIT",
    "THREAD_LIMIT",
    "WORKER_LIMIT",
    "Count",
    "Degrees",
    "Fraction",
    "Metres",
    "OptionValueError",
    "Quantity",
    "Seconds",
    "Seed",
    "given",
    "refuse_given",
]

# The limits several options share (an option's own limit is written, with its reason, at it).
PARTICLE_LIMIT = 10_000_000
"""Particles of a Monte Carlo filter (C++ std::size_t): MclConfig's, PlaybackConfig's and the
experiments' limit; 10^7 poses are 240 MB of (x, y, theta) before their weights."""
BEAM_LIMIT = 100_000
"""Beams used per scan, nav2's max_beams (C++ int): the densest 2-D lasers give a few thousand
beams a scan (0.1 deg over 360 deg is 3,600), so this keeps every beam of any real scan."""
THREAD_LIMIT: int = _core.MAX_THREADS
"""Threads a request may ask for (the C++ core's kMaxThreads, 1024, which its filters, matcher
and searches check too): beyond the cores they only add overhead."""
RUN_LIMIT = 100_000
"""Trials of an experiment: the experiment configs' limit (kiseki_experiments.harness.config)."""
WORKER_LIMIT = 256
"""Local Dask workers, a process each: beyond a large machine's cores they only add memory."""
SIM_SECONDS_LIMIT = 86_400.0
"""Simulated seconds: a run is at most a day of simulated time (kiseki.sim.run)."""
CELL_LIMITS = (0.001, 10.0)
"""A grid's cell or voxel, m: 1 mm to 10 m. How many cells a map then has over its extent is
checked by its builder against its own memory limit (kiseki.mapping.MAX_MAP_CELLS, the
magnetic field map's MAX_CELLS, sim show's MAX_OCTREE_VOXELS)."""
REACH_LIMIT = 1000.0
"""How far a laser reaches (or a region of a scan does), m: the longest 2-D lasers reach a few
hundred metres."""


class OptionValueError(KisekiError):
    """A command-line value outside its option's range, or an option that does not apply: one
    line naming the option, exit status 1. Not a ValueError: typer turns a ValueError raised by
    a parser into a usage error (exit status 2, a box of text)."""


def _shown(value: Any) -> str:
    """The value as the user wrote it (``1e308``, not ``1e+308``)."""
    return value.strip() if isinstance(value, str) else repr(value)


class _Bounded:
    """A parser: called with the text of the command line (or the default), it returns the
    number, or raises OptionValueError "NAME must be RULE, got VALUE"."""

    def __init__(self, name: str, lo: float, hi: float, lo_open: bool, hi_open: bool) -> None:
        self.name, self.lo, self.hi, self.lo_open, self.hi_open = name, lo, hi, lo_open, hi_open

    def _number(self, value: Any) -> int | float | None:
        raise NotImplementedError

    def rule(self) -> str:
        raise NotImplementedError

    def contains(self, number: float) -> bool:
        """Whether a number lies in the range (a NaN never does)."""
        low = number > self.lo if self.lo_open else number >= self.lo
        high = number < self.hi if self.hi_open else number <= self.hi
        return low and high

    def __call__(self, value: Any) -> int | float:
        number = None if isinstance(value, bool) else self._number(value)
        if number is None or not self.contains(number):
            raise OptionValueError(f"{self.name} must be {self.rule()}, got {_shown(value)}")
        return number

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name} {self.rule()})"


class Count(_Bounded):
    """An integer in lo..hi (both included); ``note`` says what a special value means."""

    def __init__(self, name: str, lo: int, hi: int, note: str = "") -> None:
        super().__init__(name, lo, hi, False, False)
        self.note = note

    def _number(self, value: Any) -> int | None:
        if isinstance(value, int):
            return value
        if isinstance(value, str):
            try:
                return parse_int(value.strip())  # 1_0 is not 10
            except ValueError:
                return None
        return None

    def rule(self) -> str:
        return integer_rule(self.lo, self.hi, self.note)


class Seed(Count):
    """A seed: numpy's and the C++ core's 64-bit generators (uint64_t) take [0, 2**64); worded
    as :func:`kiseki.core.check_seed` words it."""

    def __init__(self, name: str = "--seed") -> None:
        super().__init__(name, 0, 2**64 - 1)

    def rule(self) -> str:
        return SEED_RULE.removeprefix("must be ")


class Quantity(_Bounded):
    """A finite number in its interval (``lo_open``/``hi_open``: that end excluded), in
    ``unit`` (a C++ double)."""

    def __init__(
        self,
        name: str,
        lo: float,
        hi: float,
        unit: str = "",
        *,
        lo_open: bool = False,
        hi_open: bool = False,
    ) -> None:
        super().__init__(name, lo, hi, lo_open, hi_open)
        self.unit = unit

    def _number(self, value: Any) -> float | None:
        if isinstance(value, int | float):
            number = float(value)
        elif isinstance(value, str):
            try:
                number = parse_float(value.strip())  # 1_0 is not 10
            except ValueError:
                return None
        else:
            return None
        # + 0.0 makes -0.0 (``-0``, ``-0.0``) the zero it means: numpy's samplers refuse a
        # scale whose sign bit is set ("scale < 0") though -0.0 >= 0 holds
        return number + 0.0 if math.isfinite(number) else None

    def rule(self) -> str:
        return number_rule(
            self.lo, self.hi, low_open=self.lo_open, high_open=self.hi_open, unit=self.unit
        )


def Metres(name: str, lo: float, hi: float, **ends: bool) -> Quantity:  # noqa: N802 (a type)
    """A length in metres."""
    return Quantity(name, lo, hi, "m", **ends)


def Seconds(name: str, lo: float, hi: float, **ends: bool) -> Quantity:  # noqa: N802
    """A duration in seconds."""
    return Quantity(name, lo, hi, "s", **ends)


def Degrees(name: str, lo: float, hi: float, **ends: bool) -> Quantity:  # noqa: N802
    """An angle in degrees."""
    return Quantity(name, lo, hi, "deg", **ends)


def Fraction(name: str, lo: float, hi: float, **ends: bool) -> Quantity:  # noqa: N802
    """A share or a factor, without a unit."""
    return Quantity(name, lo, hi, **ends)


_TYPED = ("COMMANDLINE", "ENVIRONMENT", "PROMPT")  # sources that are not a default


def _flag(param: Any) -> str:
    longs = [o for o in getattr(param, "opts", ()) if o.startswith("--")]
    return longs[0] if longs else "--" + str(param.name).replace("_", "-")


def given(ctx: Any, *names: str) -> list[str]:
    """The flags of the options among ``names`` (the command's parameter names) that the command
    line set, in the command's order; not those left at their default."""
    found = []
    for param in ctx.command.params:
        source = ctx.get_parameter_source(param.name) if param.name in names else None
        if getattr(source, "name", None) in _TYPED:
            found.append(_flag(param))
    return found


def _listed(flags: Sequence[str]) -> str:
    return flags[0] if len(flags) == 1 else ", ".join(flags[:-1]) + " and " + flags[-1]


def refuse_given(ctx: Any, names: Sequence[str], context: str) -> None:
    """OptionValueError naming every option of ``names`` the command line gave: ``"--kld and
    --beams do not apply to --method odometry (...)"``, ``context`` being the words after
    "apply"."""
    flags = given(ctx, *names)
    if flags:
        verb = "does" if len(flags) == 1 else "do"
        raise OptionValueError(f"{_listed(flags)} {verb} not apply {context}")
