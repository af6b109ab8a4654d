"""The crest event of a periodic orbit: an interior crest of the level ``G = F (1 + c(α))`` reaching a fold.

On AB the level G rises, in the α oscillation, to the fold value ``f_max`` where the AB→CD jump happens.  An
orbit's AB stay may contain earlier crests of G below ``f_max`` (local maxima); on CD, earlier troughs above
``f_min``.  When a parameter moves so that such a crest reaches the fold level, the hybrid solution jumps there,
one oscillation earlier: the orbit continued so far stops being a solution (its return map is discontinuous
there, and Newton fails just past it).  This is the non-smooth event that ends most short branches at low
inertia (docs/orbits.md).  :func:`crest_margin` measures how far an orbit is from it: the smallest gap between
an interior crest and its fold level, relative to ``f_max - f_min``.  The gap falls linearly in the parameter to
0 at the event, so two points of a branch locate it by linear extrapolation.  It also measures the orbit's
distance from the model's breakdown (``floor``: the lowest level on AB above f(0+)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from peelapprox import branch_structure

__all__ = ["Crest", "crest_margin"]


@dataclass(frozen=True)
class Crest:
    """The interior crest nearest its fold (:func:`crest_margin`).

    Attributes
    ----------
    margin : float
        ``(f_max - G_crest) / (f_max - f_min)`` for an AB crest, ``(G_trough - f_min) / (f_max - f_min)`` for a
        CD trough; ``inf`` when the orbit has no interior crest.
    branch : str
        "AB", "CD" or "" (none).
    t : float
        Time of the crest after the orbit's first AB→CD jump [s] (nan when none).
    floor : float
        ``(min G on AB - f(0+)) / (f_max - f_min)``: how far the orbit is from the model's breakdown (CONSTR
        losing its root on AB, ``ModelBreakdown("no_root")``), the other event that ends branches.
    """

    margin: float
    branch: str
    t: float
    floor: float = math.inf


def _vertex(t: np.ndarray, g: np.ndarray) -> tuple[float, float]:
    """The vertex ``(t, g)`` of the parabola through three samples (the middle one is the sampled extremum)."""
    (t0, t1, t2), (g0, g1, g2) = t, g
    d = (t1 - t0) * (g1 - g2) - (t1 - t2) * (g1 - g0)
    if d == 0:
        return float(t1), float(g1)
    num = (t1 - t0) ** 2 * (g1 - g2) - (t1 - t2) ** 2 * (g1 - g0)
    tv = t1 - 0.5 * num / d
    if not t0 <= tv <= t2:
        return float(t1), float(g1)
    gv = g1 + (g2 - g1) * ((tv - t1) * (tv - t0)) / ((t2 - t1) * (t2 - t0)) \
        + (g0 - g1) * ((tv - t1) * (tv - t2)) / ((t0 - t1) * (t0 - t2))
    return float(tv), float(gv)


def crest_margin(orbit: Any, *, rtol: float = 1e-12) -> Crest:
    """The interior crest of ``G = F (1 + c(α))`` nearest its fold along one period of ``orbit`` (module docstring).

    Parameters
    ----------
    orbit : exact.PeriodicOrbit
    rtol : float
        Tolerance of the one-period run (``PeriodicOrbit.trajectory``), whose every step is a sample; the crest
        between samples is the vertex of the parabola through the extreme sample and its neighbours.

    Returns
    -------
    Crest
    """
    tr = orbit.trajectory(rtol=rtol, save="steps")
    p = orbit.params
    folds = branch_structure(p.V, force=p.force)
    G = tr.F * (1.0 + np.asarray(p.closure(tr.alpha)[0]))
    b, t = tr.branch, tr.t
    if folds.f_max is None or folds.f_min is None or folds.f_zero is None:
        raise ValueError(f"orbit: f(v, V={p.V}) has no folds: no crest to measure")
    f_max, f_min = float(folds.f_max), float(folds.f_min)
    span = f_max - f_min
    best = Crest(math.inf, "", math.nan)
    inner = (b[1:-1] == b[:-2]) & (b[1:-1] == b[2:]) & (t[:-2] < t[1:-1]) & (t[1:-1] < t[2:])
    g0, g1, g2 = G[:-2], G[1:-1], G[2:]
    peak = inner & (b[1:-1] == 0) & (g1 > g0) & (g1 >= g2)
    trough = inner & (b[1:-1] == 1) & (g1 < g0) & (g1 <= g2)
    for i in np.flatnonzero(peak | trough) + 1:
        tv, gv = _vertex(t[i - 1:i + 2], G[i - 1:i + 2])
        ab = b[i] == 0
        m = (f_max - gv) / span if ab else (gv - f_min) / span
        if m < best.margin:
            best = Crest(max(m, 0.0), "AB" if ab else "CD", tv - float(t[0]))
    on_ab = b == 0
    floor = (float(np.min(G[on_ab])) - float(folds.f_zero)) / span if on_ab.any() else math.inf
    return Crest(best.margin, best.branch, best.t, floor)
