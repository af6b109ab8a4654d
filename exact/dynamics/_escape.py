"""How long a run sitting on an unstable periodic orbit stays there: the amplitude law of :func:`exact.attractor_set`.

Near a period-n orbit with the section fixed point ``z*`` (AB→CD section, scaled coordinates ``z = (α, ω R/V)``,
:mod:`exact.orbits._section`) a run's deviation ``d_k = z_k - z*`` after k periods (k returns of ``P^n``) follows
the linearised map, ``d_{k+1} = DP^n d_k``.  In the basis of the dominant eigenvectors of ``DP^n`` its amplitude
grows by the largest multiplier's modulus per period: for a complex pair ``μ = |μ| e^{iθ}`` the coordinates in
``(Re w, Im w)`` turn by θ and stretch by |μ|; for a real μ the coordinate along its eigenvector (the left
eigenvector's projection) is multiplied by μ.  Hence the amplitude law

    A_k = A_k0 |μ|^(k - k0),

whose constant ``A_k0`` is fitted to the window's periods with |μ| known (the median of ``ln A_k - k ln|μ|``).
The run has *escaped* when the envelope of its return-map deviation, ``|x_k - x*|`` with x the force at the AB→CD
jump (``F = f_max / (1 + c(α))``), reaches :data:`ESCAPE_DEVIATION` of ``x*``; the linear map gives that envelope
as ``|g·P| A_k`` (g the gradient of the section force), so the predicted escape is
``k_esc = k0 + ln(δ x* / (|g·P| A_k0)) / ln|μ|`` periods.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from peelapprox import PeelParams

__all__ = ["ESCAPE_DEVIATION", "EscapePrediction", "predict_escape", "escape_index"]

#: A run has left an orbit when a return-map value (the force at an AB→CD jump) differs from the orbit's by this
#: fraction of it: the definition the prediction and the measured escape share.  At 1 % the deviation is still
#: small enough for the linearised map (the fitted growth and |μ| agree) and far above the window's rounding.
ESCAPE_DEVIATION = 1e-2


@dataclass(frozen=True)
class EscapePrediction:
    """The predicted escape from an unstable periodic orbit (module docstring).

    Attributes
    ----------
    multiplier : complex
        The largest Floquet multiplier μ of the orbit (``|μ| > 1``).
    deviation : float
        The envelope of the return-map deviation at the window's last period, relative to the orbit's force.
    returns : float
        AB→CD jumps from the window's last one to the predicted escape (``n`` per period); 0 when the window's
        envelope already reaches :data:`ESCAPE_DEVIATION`.
    time : float
        The predicted escape time [s] (absolute, like the run's): the window's last AB→CD jump plus ``returns``
        periods' worth of the orbit's time.
    return_index : int
        The predicted escape's AB→CD jump counted from the run's start (t = 0).
    growth : float or None
        The per-period growth of the amplitude fitted freely over the window (least squares of ``ln A_k`` on k),
        beside ``|μ|``: where they differ much the run is not on the linear regime of the orbit.
    """

    multiplier: complex
    deviation: float
    returns: float
    time: float
    return_index: int
    growth: float | None


def _basis(M: np.ndarray) -> tuple[complex, np.ndarray]:
    """The largest multiplier and the matrix taking a deviation to its dominant coordinates: for a complex pair
    the inverse of ``[Re w, Im w]`` (2 x 2), for a real μ the left eigenvector's row (1 x 2)."""
    mu, W = np.linalg.eig(M)
    i = int(np.argmax(np.abs(mu)))
    if abs(mu[i].imag) > 1e-12 * abs(mu[i]):
        w = W[:, i]
        return complex(mu[i]), np.linalg.inv(np.column_stack([w.real, w.imag]))
    left = np.linalg.inv(W.real)
    return complex(mu[i].real), left[i:i + 1, :]


def predict_escape(params: PeelParams, monodromy: np.ndarray, z_star: np.ndarray, x_star: float,
                   alphas: np.ndarray, omegas: np.ndarray, times: np.ndarray, period: float, n: int,
                   index0: int) -> EscapePrediction | None:
    """The escape predicted from a window's section states at one phase of a period-n orbit (module docstring).

    Parameters
    ----------
    params : PeelParams
    monodromy : ndarray, shape (2, 2)
        ``DP^n`` at ``z_star`` in ``(α, ω)``.
    z_star : ndarray, shape (2,)
        The orbit's section state ``(α, ω)`` of this phase; ``x_star`` its force [N].
    alphas, omegas, times : ndarray
        The window's section states and times at this phase, one per period, in order (at least 3).
    period : float
        The orbit's period [s]; ``n`` its AB→CD jumps per period.
    index0 : int
        The AB→CD jump count from t = 0 of the first of ``times``.

    Returns
    -------
    EscapePrediction or None
        None when the multiplier is not above 1 or the deviations are all zero.
    """
    s = np.array([1.0, params.V / params.R])
    Ms = monodromy * s[None, :] / s[:, None]
    mu, P = _basis(Ms)
    r = abs(mu)
    if not r > 1.0 or alphas.size < 3:
        return None
    d = np.column_stack([alphas - z_star[0], (omegas - z_star[1]) / s[1]])
    A = np.linalg.norm(d @ P.T, axis=1)
    ok = A > 0
    if not ok.any():
        return None
    k = np.arange(alphas.size, dtype=float)
    ln_a0 = float(np.median(np.log(A[ok]) - k[ok] * math.log(r)))
    growth = float(np.exp(np.polyfit(k[ok], np.log(A[ok]), 1)[0])) if ok.sum() >= 3 else None
    # the envelope of x - x* per unit amplitude: |g · Q| with Q the dominant directions (P's inverse)
    h = 1e-7
    c = params.closure(np.array([z_star[0] - h, z_star[0], z_star[0] + h]))[0]
    f_max = x_star * (1.0 + float(c[1]))  # F = f_max / (1 + c(α)) on the section
    dF = f_max * (1.0 / (1.0 + c[2]) - 1.0 / (1.0 + c[0])) / (2 * h)
    Q = np.linalg.pinv(P)  # columns: the dominant directions in scaled z (a deviation d = Q·coords)
    gain = float(np.linalg.norm(np.array([dF, 0.0]) @ Q))
    last = k[-1]
    env_last = gain * math.exp(ln_a0 + last * math.log(r))
    target = ESCAPE_DEVIATION * abs(x_star)
    more = max(0.0, math.log(target / env_last) / math.log(r)) if env_last > 0 and gain > 0 else math.inf
    if not math.isfinite(more):
        return None
    return EscapePrediction(multiplier=mu, deviation=env_last / abs(x_star), returns=more * n,
                            time=float(times[-1]) + more * period, return_index=int(round(index0 + (last + more) * n)),
                            growth=growth)


def escape_index(x: np.ndarray, cycle: np.ndarray, start: int = 0) -> int | None:
    """The first return ``k >= start`` whose value differs from every value of the orbit's ``cycle`` (its
    return-map values) by more than :data:`ESCAPE_DEVIATION` of it: the measured escape (None if none)."""
    cyc = np.asarray(cycle, dtype=float).reshape(1, -1)
    dev = np.min(np.abs(np.asarray(x, dtype=float)[:, None] - cyc) / np.abs(cyc), axis=1)
    out = np.flatnonzero(dev[start:] > ESCAPE_DEVIATION)
    return int(out[0]) + start if out.size else None
