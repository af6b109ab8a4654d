"""Where :func:`exact.periodic_orbit` starts Newton: its ``start`` argument checked, the seed run, and the section
state of the nearest recurrence in it.

``start`` is None (a run from the default start), an :class:`exact.State` (a run from it) or an
:class:`exact.Trajectory` (used as it is).  :func:`check_start` refuses, before any work, what would seed Newton
from something other than an orbit of ``params``: a State with a field out of its range (``t``, ``alpha``,
``omega``, ``F``, ``v``, ``branch``) or with a pull speed ``Vp`` under velocity control, and a Trajectory run
with other parameters or another peel-force law.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from peelapprox import BRANCHES, PeelParams, periodicity
from peelapprox.validate import choice, duration, state

from .._model import model_of
from .._simulate import simulate
from .._trajectory import State, Trajectory

__all__ = ["check_start", "seed"]


def check_start(params: PeelParams, start: Any) -> None:
    """Refuse a ``start`` that is not a start of ``params`` (module docstring).

    Raises
    ------
    TypeError
        ``start`` is none of None, a State, a Trajectory.
    ValueError
        Naming ``start.<field>`` and its valid range: a State's ``t`` outside [0, TIME_MAX] or NaN, ``alpha``,
        ``omega``, ``F``, ``v`` outside ``STATE_RANGES`` (``v`` > 0) or NaN, ``branch`` not "AB"/"CD", ``Vp`` set
        under velocity control (the pull speed is then ``params.V``); a Trajectory whose ``params`` are not
        ``params`` (``start.params.force`` for another law, else the fields that differ).
    """
    if start is None:
        return
    if isinstance(start, Trajectory):
        theirs = start.params
        if theirs.force != params.force:
            raise ValueError(f"start.params.force must be params.force (a Trajectory of the same peel-force law), "
                             f"got {theirs.force!r}, params.force = {params.force!r}: pass a run of params, a State "
                             "or None")
        if theirs != params:
            diff = ", ".join(f"{f.name}={getattr(theirs, f.name)!r} (params: {getattr(params, f.name)!r})"
                             for f in dataclasses.fields(params) if getattr(theirs, f.name) != getattr(params, f.name))
            raise ValueError(f"start.params must be params (a Trajectory run with the same parameters), got {diff}: "
                             "pass a run of params, a State or None")
        return
    if not isinstance(start, State):
        raise TypeError(f"start must be None, an exact.Trajectory or an exact.State, got {type(start).__name__}")
    duration("start.t", start.t, zero=True)
    for name in ("alpha", "omega", "F", "v"):
        state(f"start.{name}", getattr(start, name), name)
    choice("start.branch", start.branch, BRANCHES)
    model = model_of(params)
    if start.Vp is not None and not model.under_load:
        raise ValueError(f"start.Vp must be None for {model.about} (the pull speed is params.V = {params.V!r} m/s), "
                         f"got {start.Vp!r}")


def seed(params: PeelParams, start: Any, n: int | None, t_transient: float, window: float, max_period: int,
         rtol: float, max_wall: float | None = None) -> tuple[np.ndarray, int]:
    """``(x0, n)``: the section state to start Newton from and the jumps per period (:func:`exact.periodic_orbit`;
    ``start`` checked by :func:`check_start`).  ``max_wall`` [s] bounds the seed run (None: unbounded)."""
    if isinstance(start, Trajectory):
        tr, t0 = start, start.t_transient
    else:
        kw: dict = {}
        if isinstance(start, State):
            kw = dict(alpha0=start.alpha, omega0=start.omega, F0=start.F, branch0=start.branch)
        tr = simulate(params, t_transient + window, rtol=rtol, save="jumps", t_transient=t_transient,
                      max_wall=max_wall, **kw)
        t0 = t_transient
    j = tr.jumps
    up = (j.from_branch == 0) & (j.t >= t0)
    a, w, F = j.alpha[up], j.omega[up], j.F[up]
    if F.size < 2:
        raise ValueError(f"start: the run has {F.size} AB->CD jumps after its transient; a periodic orbit needs "
                         "stick-slip (at least two returns): lengthen window or check params")
    if n is None:
        per = periodicity(F, max_period=max_period)
        if per.period is None:
            why = ("too short to test every period" if per.kind == "too short" else
                   f"its smallest mismatch {per.mismatch:.2g} relative is above {per.rtol:g}")
            raise ValueError(f"start: no period up to max_period={max_period} found in the run's return map "
                             f"({F.size} returns, {why}): raise max_period (a long period, e.g. 49 at V = 4, "
                             "I = 1e-2), lengthen the window, or give n (the jumps per period) to look for an "
                             "unstable orbit near a recurrence")
        n = int(per.period)
    if F.size <= n:
        raise ValueError(f"n={n} needs more than {n} AB->CD jumps after the transient; the run has {F.size}")
    z = np.column_stack([a, w * params.R / params.V])
    gap = np.linalg.norm(z[n:] - z[:-n], axis=1)
    k = int(np.argmin(gap))  # the nearest recurrence: exact for a periodic attractor, a seed for an unstable one
    return np.array([a[k], w[k]]), n
