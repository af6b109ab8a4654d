"""The escape return of a weakly unstable orbit of the reduced map, with the multiplier of the full chain.

An unstable periodic orbit of the reduced map (:func:`peelapprox.approximate_attractor`) is left at the return where
the amplitude law ``A_k = A_k0 |μ|^((k - k0)/n)`` brings the envelope of the AB→CD force's deviation from the orbit
to the orbit's force drop (:data:`peelapprox._reduced._approx_start.ESCAPE_FRACTION`): ``k = k0 + n ln(thr/A_k0) /
ln|μ|``, so a relative error ε in ``|μ| - 1`` is a relative error ε in ``k - k0``. Airy1 + approxvdot (the default at
high inertia until the full chain became the default everywhere) drops the O(α) terms: at the weakly unstable small
modes of the escape benchmark its ``|μ| - 1`` is 0.6–74 % below :func:`exact.periodic_orbit`'s (5.6e-4 against 2.13e-3
at V = 2.48 m/s, I = 4.4e-3).  The full
branch dynamics linearised in α (genalpha + fullvdot, the chain ``FULL_CHAIN`` of
:mod:`peelapprox._reduced._approx_start`), Newton on its own map from the default orbit's section point, gives
``|μ| - 1`` within 0.32 % of the exact one at the benchmark's ten points of seed 1 and 0.22 % at seed 2's
(``python -m comparisons.benchmark.approx_targets --points 100 --seed 1 --escapes 10``), for about a millisecond
(a period-1 Newton).  The escape law keeps the default map's amplitude ``A_k0`` (its own deviation in its own
eigen-coordinates, :func:`peelapprox._reduced._reducedmap.envelope`) and takes its rate from the full chain, only
where the default map's leading ``|μ|`` is within :data:`REFINE_ABOVE` of 1 (there the rate's relative error
matters most, and the escape is slow enough to be worth predicting), and where the default map finds the orbit
weakly stable, within :data:`REFINE_BELOW` below 1 (the exact orbit is weakly unstable there: such an orbit stays the
prediction and gets the escape return of the full chain's rate).  The map's own multipliers, which the ranking and
the confidence rules read, are left as they are: the primary prediction's observables do not change.
"""

from __future__ import annotations

import math

import numpy as np

from ._reducedmap import NEWTON_RTOL, ReturnMap, envelope, newton

__all__ = ["REFINE_ABOVE", "REFINE_BELOW", "escape_return", "refined_multipliers"]

#: A chain: ``((AB α model, AB v equation), (CD α model, CD v equation))``.
Chain = tuple[tuple[str, str], tuple[str, str]]

#: The escape's rate comes from the full chain where the default map's leading |μ| is in (1, 1 + this].
REFINE_ABOVE = 0.02
#: ... and where it is in [1 - this, 1): a period-1 orbit the default map finds weakly stable (|μ| 0.9976-0.99993)
#: is weakly unstable in the exact model (|μ| - 1 from 4.7e-5 to 3.1e-3) at the 14 such points of the first 50 of
#: seed 1 and 30 of seed 2, and in the full chain within 7 % of that; the default chain's |μ| lies up to 4.5e-3 below
#: the full chain's there.  Such an orbit stays the prediction (the map does not leave it) and gets an escape return.
REFINE_BELOW = 0.01


def refined_multipliers(lo: ReturnMap, xs: np.ndarray, n: int, full: Chain) -> tuple[complex, ...] | None:
    """The multipliers of the period-n orbit of the map of the chain ``full`` (genalpha + fullvdot) near the
    default map's orbit point ``xs``: Newton on ``P^n(x) = x`` at Newton's segment tolerance (``NEWTON_RTOL``), the
    same machinery, the plans of ``lo`` shared and its wall-clock deadline kept.  None where that Newton does not
    converge (a segment stops, the deadline passes, or no orbit within half the orbit's scale)."""
    m = ReturnMap(lo.params, lo.law, full, NEWTON_RTOL, lo.deadline, lo.book)
    res = newton(m, np.array(xs, dtype=float), n)
    if res is None:
        return None
    return tuple(complex(mu) for mu in np.linalg.eigvals(res[1]))


def escape_return(lo: ReturnMap, J: np.ndarray, x: np.ndarray, xs: np.ndarray, n: int, rho: float,
                  threshold: float, full: Chain, since: int) -> tuple[float | None, complex | None]:
    """The return (counted from the start, ``lo.returns`` done) at which the map's deviation ``x`` from the period-n
    orbit through ``xs`` (``J = D P^n`` there, leading |μ| = ``rho``) reaches ``threshold`` in force, and the
    multiplier that set its rate: the leading one of the chain ``full`` (genalpha + fullvdot,
    :func:`refined_multipliers`) where ``rho`` is in [1 - :data:`REFINE_BELOW`, 1 + :data:`REFINE_ABOVE`], ``lo``'s
    chain is not already ``full`` and ``full``'s orbit is unstable; else None (the rate is ``rho``, the map's own).
    The return is None where neither the map's orbit nor the full chain's is unstable, and where the map's deviation
    at ``lo.returns`` (its Newton), so corrected, is already at ``threshold``, whether the map settled on the orbit
    or leaves it: the law has no e-fold to run and would say ``lo.returns``, the map's own return, while the exact
    run leaves within the map's own transient, beyond a linear law (measured: 40 predicted against the exact 31, 147
    and 172, 73-77 % off both ways; the same three orbits, stayed on with Airy1 + approxvdot, left with the full
    chain); the multiplier (where it is not the map's own) is still returned, the map's multipliers still say the
    orbit is unstable.

    With the full chain's rate the amplitude is the map's envelope times ``(|μ_full|/rho)^(since/n)``: the map's
    deviation grew (or decayed) at its own rate over the ``since`` returns since it set out towards the orbit (from
    the start, or from the last orbit it left), the exact one at the exact rate.  Measured on the calibration points
    (seed 1, the 14 orbits the map leaves): the largest error 19.2 % without this factor, 7.9 % with it."""
    mu: complex | None = None
    rate = rho
    if 1.0 - REFINE_BELOW <= rho <= 1.0 + REFINE_ABOVE and tuple(lo.models) != tuple(full):
        got = refined_multipliers(lo, xs, n, full)
        if got is not None and max(abs(m) for m in got) > 1.0:
            mu = max(got, key=abs)
            rate = abs(mu)
    if rate <= 1.0:
        return None, None
    amp = envelope(lo, J, x, xs) * (rate / rho) ** (since / n)
    if not amp < threshold:  # the map's deviation at its Newton is already as large as the orbit, settled or left:
        return None, mu  # the law has no e-fold to run (3 of 3 such escapes were 73-77 % off, both ways)
    k = lo.returns + (n * math.log(threshold / amp) / math.log(rate) if 0.0 < amp else 0.0)
    return k, mu
