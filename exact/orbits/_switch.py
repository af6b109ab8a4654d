"""Branch switching at a period doubling: :func:`switch_branch` finds the period-2n orbit born where a period-n
branch of :func:`exact.continue_orbit` has a Floquet multiplier through -1 (the bordered corrector of
:mod:`exact.orbits._corrector` with an amplitude condition along the multiplier's eigenvector).
"""

from __future__ import annotations

import numpy as np

from peelapprox.errors import SolverBudgetExceeded, WallBudget
from peelapprox.validate import in_range, optional, positive

from .._shared import DEFAULT_MAX_WALL
from ._continuation import FAILURES, Bifurcation, Stepper
from ._periodic import PeriodicOrbit, minimal_period

__all__ = ["SWITCH_DLAM", "switch_branch"]

#: Largest move of λ per Newton step in :func:`switch_branch`, relative to λ: the doubled orbit at a small
#: amplitude lies next to the bifurcation (λ - λ* ~ a²); a free λ can otherwise wander where returns fail.
SWITCH_DLAM = 1e-2


def switch_branch(bifurcation: Bifurcation, *, amplitude: float = 1e-3, tol: float = 1e-10,
                  rtol: float = 1e-12, max_wall: float | None = DEFAULT_MAX_WALL) -> PeriodicOrbit:
    """The period-2n orbit born at a period doubling of a period-n branch.

    Solves ``P^{2n}(x; λ) = x`` with ``e · (z - z*) = a`` (:func:`exact.orbits._corrector.bordered_newton`): ``z*`` the
    scaled section state of the orbit at the bifurcation, ``e`` the eigenvector of its multiplier -1, ``a`` the
    ``amplitude`` (then a/4 and 4a if Newton fails or returns the period-n orbit itself), λ free.  Continue the
    result with :func:`exact.continue_orbit` (its parameter is ``bifurcation.parameter``; the doubled branch lies on
    the side of λ where the result is).

    Parameters
    ----------
    bifurcation : Bifurcation
        Of kind "period_doubling" (``OrbitBranch.bifurcations``).
    amplitude : float
        Distance from the period-n orbit along ``e`` in scaled section coordinates, in (0, 0.1].
    tol, rtol : float
        As :func:`exact.periodic_orbit`: in [1e-14, 1e-3] and [1e-14, 1e-6].
    max_wall : float or None
        Wall-clock budget [s] of the whole call, all amplitudes tried (None: unbounded; default
        :data:`exact.DEFAULT_MAX_WALL`, 3600 s), checked before each Newton iteration.

    Returns
    -------
    PeriodicOrbit
        With ``n`` twice the bifurcating orbit's.

    Raises
    ------
    ValueError
        Not a period doubling, or no doubled orbit found near it.
    peelapprox.SolverBudgetExceeded
        ``max_wall`` spent (``budget="max_wall"``): the call returns one orbit or nothing, so a spent budget is
        an exception, as in :func:`exact.periodic_orbit`.
    """
    if not isinstance(bifurcation, Bifurcation) or not bifurcation.doubles:
        raise ValueError(f"bifurcation must be a period_doubling Bifurcation, got {bifurcation!r:.80}")
    amplitude = in_range("amplitude", amplitude, 0.0, 0.1, lo_open=True)
    tol = in_range("tol", tol, 1e-14, 1e-3)
    rtol = in_range("rtol", rtol, 1e-14, 1e-6)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    o, lam = bifurcation.orbit, bifurcation.value
    st = Stepper(o, bifurcation.parameter, max(abs(lam), 1e-300), tol, rtol, wall)
    Js = o.monodromy * st.scale[None, :] / st.scale[:, None]
    mu, vec = np.linalg.eig(Js)
    e = np.real(vec[:, int(np.argmin(np.abs(mu + 1.0)))])
    e /= np.linalg.norm(e)
    z = o.section_states[0] / st.scale
    tau = np.concatenate([e, [0.0]])
    errors = []
    for a in (amplitude, amplitude / 4, 4 * amplitude):
        w_ref = np.concatenate([z + a * e, [lam / st.ls]])
        try:
            pt = st.correct(w_ref, tau, n=2 * o.n, max_iter=20, max_dlam=SWITCH_DLAM * max(abs(lam), 1e-300))
        except SolverBudgetExceeded as exc:
            if exc.budget == "max_wall":  # the call's budget (the returns have none of their own)
                raise SolverBudgetExceeded(f"switch_branch: more than {wall.limit:g} s of wall time (max_wall) "
                                           f"looking for the period-{2 * o.n} orbit near the period doubling at "
                                           f"{bifurcation.parameter}={lam:.10g}; pass a larger max_wall, or None",
                                           budget="max_wall", limit=exc.limit, t=exc.t, state=exc.state) from None
            errors.append(f"a={a:.3g}: {exc}")
            continue
        except FAILURES as exc:
            errors.append(f"a={a:.3g}: {exc}")
            continue
        if minimal_period(pt.orbit) == 2 * o.n:
            return pt.orbit
        errors.append(f"a={a:.3g}: Newton returned the period-{o.n} orbit")
    raise ValueError(f"no period-{2 * o.n} orbit found near the period doubling at {bifurcation.parameter}="
                     f"{lam:.10g}: " + "; ".join(errors))
