"""Grid axes of a sweep from the command line's ``start:stop:num[:log]`` or comma-list specs, and the limit on a
grid's size (:data:`MAX_SWEEP_POINTS`), checked before any work."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["MAX_SWEEP_POINTS", "check_grid_size", "grid_length", "parse_grid"]

#: Most points of one sweep (and values of one axis): a point costs ~0.1-1 s of a core for the exact measures
#: (jumps, period), a minute for lyapunov, so 1e6 points are days on a cluster, while the phase diagrams of the
#: docs have ~100; and the engine builds its plan (a key per point, the resume bookkeeping) in memory before
#: writing the manifest.  A larger grid is a typo (a zero too many), refused before anything is built.
MAX_SWEEP_POINTS = 10**6

_WHY = "days of computing on a cluster: more is most likely a typo"


class _TooLarge(ValueError):
    """A spec asking for more than :data:`MAX_SWEEP_POINTS` values (its message is the error's, not "cannot parse")."""


def grid_length(values: Any) -> int:
    """The number of values of an axis without converting it (``len``, or ``size`` for an array; 0 when it has
    neither: the axis' own check then names it)."""
    if isinstance(values, np.ndarray):
        return int(values.size)
    try:
        return len(values)
    except TypeError:
        return 0


def check_grid_size(axes: Mapping[str, int]) -> None:
    """ValueError naming the axes (as the caller spells them: ``I_values``, ``--I``, ...) unless the grid, their
    product, holds at most :data:`MAX_SWEEP_POINTS` points."""
    total = math.prod(axes.values())
    if total > MAX_SWEEP_POINTS:
        names, sizes = " x ".join(axes), " x ".join(str(n) for n in axes.values())
        raise ValueError(f"{names}: a sweep must hold at most MAX_SWEEP_POINTS = {MAX_SWEEP_POINTS} points ({_WHY}), "
                         f"got {sizes} = {total}")


def parse_grid(spec: str, *, name: str = "values") -> np.ndarray:
    """Grid values from ``"start:stop:num"`` (linspace), ``"start:stop:num:log"`` (geometric, exact endpoints)
    or a comma list ``"0.4,1,2"``, at most :data:`MAX_SWEEP_POINTS` of them.

    Raises ValueError naming ``name`` on a malformed spec or a ``num`` above the limit (before the values are
    made).
    """
    s = str(spec).strip()
    try:
        if ":" in s:
            parts = s.split(":")
            if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
                raise ValueError("expected start:stop:num or start:stop:num:log")
            a, b = float(parts[0]), float(parts[1])
            n = int(parts[2])
            if n < 1:
                raise ValueError(f"num must be >= 1, got {n}")
            if n > MAX_SWEEP_POINTS:
                raise _TooLarge(f"{name}: num must be at most MAX_SWEEP_POINTS = {MAX_SWEEP_POINTS} ({_WHY}), "
                                    f"got {n} in {spec!r}")
            if len(parts) == 4 and parts[3] == "log":
                if not (a > 0 and b > 0):
                    raise ValueError("a log range needs start > 0 and stop > 0")
                return np.geomspace(a, b, n)
            return np.linspace(a, b, n)
        if s.count(",") >= MAX_SWEEP_POINTS:
            raise _TooLarge(f"{name}: a list must hold at most MAX_SWEEP_POINTS = {MAX_SWEEP_POINTS} values "
                                f"({_WHY}), got {s.count(',') + 1}")
        vals = [float(x) for x in s.split(",") if x.strip()]
        if not vals:
            raise ValueError("empty list")
        return np.asarray(vals)
    except _TooLarge as exc:
        raise ValueError(str(exc)) from None
    except ValueError as exc:
        raise ValueError(f"{name}: cannot parse {spec!r} ({exc}); use start:stop:num[:log] or a comma list") \
            from None
