"""Where a continued branch ends (:func:`exact.continue_orbit`): the crest, breakdown and grazing events its last
points extrapolate to, and the stop reason and message of a branch whose corrector fails at the smallest step
(the module docstring of :mod:`exact.orbits._continuation` describes the events).

``points`` are the branch's :class:`exact.BranchPoint` objects (``value``, ``orbit``), in the order continued,
and ``crests`` their :class:`exact.Crest` margins.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from peelapprox.errors import ModelBreakdown

from ._crest import Crest, crest_margin
from ._kinds import ENDS
from ._periodic import PeriodicOrbit

__all__ = ["NO_CREST", "event_message", "events_ahead", "failure_end", "near"]

#: The crest margin of a point whose crest was not measured (``crest_tol = 0``, or a grazing point).
NO_CREST = Crest(math.inf, "", math.nan)


def near(event: float, value: float, previous: float, span: float) -> float:
    """An extrapolated event's parameter value if it lies within two steps (or 1e-3 of the span) of the last
    point ``value``, else ``value``."""
    return event if abs(event - value) <= max(2 * abs(value - previous), 1e-3 * span) else value


def events_ahead(points: Sequence[Any], crests: list[Crest]) -> dict[str, float]:
    """The parameter values where the last two points' test values of the non-smooth ends (:data:`ENDS`: crest
    margin, floor, squared slowest fold rate), falling, extrapolate linearly to 0 (:mod:`exact.orbits._continuation`);
    only the falling ones."""
    if len(points) < 2:
        return {}
    a, b = points[-2].value, points[-1].value
    out = {}
    for kind in ENDS:
        ma, mb = (kind.test(p.orbit, c) for p, c in zip(points[-2:], crests[-2:]))
        if math.isfinite(ma) and math.isfinite(mb) and mb < ma and b != a:
            out[kind.name] = b + mb * (b - a) / (ma - mb)
    return out


def event_message(event: str, c: Crest, value: float, parameter: str, orbit: PeriodicOrbit | None = None) -> str:
    """The stop message of a branch that ends in ``event`` ("crest", "breakdown" or "grazing") at ``value``."""
    if event == "grazing" and orbit is not None:
        return (f"the orbit's slowest arrival at a fold, dG/dt = {np.min(np.abs(orbit.fold_rates)):.3g} N/s, "
                f"extrapolates to 0 at {parameter} ~ {value:.10g} (dG/dt squared linear): the branch ends in a "
                "grazing bifurcation, where its multipliers diverge")
    if event == "breakdown":
        return (f"the lowest level F (1 + sin alpha) on AB comes within {c.floor:.3g} (f_max - f_min) of f(0+); it "
                f"reaches it at {parameter} ~ {value:.10g} (linear extrapolation), where CONSTR loses its root and "
                "the model breaks down")
    level = "f_max" if c.branch == "AB" else "f_min"
    return (f"an interior {'crest' if c.branch == 'AB' else 'trough'} of F (1 + sin alpha) on {c.branch} comes within "
            f"{c.margin:.3g} (f_max - f_min) of {level}; it reaches it at {parameter} ~ {value:.10g} (linear "
            "extrapolation), where the solution jumps one oscillation earlier and this orbit ends")


def failure_end(exc: Exception, points: Sequence[Any], crests: list[Crest], parameter: str, span: float
                ) -> tuple[str, str, float]:
    """Why a branch whose corrector fails at the smallest step ends: a crest, breakdown or grazing event
    extrapolated ahead (within two steps or 1e-3 of the span; past a grazing the corrector's orbits break down),
    else a breakdown of the corrector's orbit, else no convergence (:mod:`exact.orbits._continuation`)."""
    if len(points) >= 2:
        if not math.isfinite(crests[-1].margin + crests[-1].floor):  # crest_tol = 0: measure now
            crests[-2:] = [crest_margin(p.orbit) for p in points[-2:]]
        for event, value in sorted(events_ahead(points, crests).items(), key=lambda e: abs(e[1] - points[-1].value)):
            if near(value, points[-1].value, points[-2].value, span) == value:
                return event, event_message(event, crests[-1], value, parameter, points[-1].orbit), value
    if isinstance(exc, ModelBreakdown):  # with no event ahead: the corrector's orbit breaks down
        return "breakdown", str(exc), math.nan
    return "no_convergence", str(exc), math.nan
