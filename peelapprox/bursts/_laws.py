"""The power law's likelihood, its maximum and its Kolmogorov-Smirnov distance: the pieces :func:`fit_power_law`
scans, bootstraps and compares with.

Continuous: ``p(x) = x^-α / Z`` on ``[xmin, xmax]`` with ``Z = ∫ x^-α dx`` (``xmax = inf``: ``Z = xmin^(1-α) /
(α - 1)``, α > 1; finite ``xmax``: any α, normalised on the interval, the fix of powerlaw's issue #89).  The MLE
is Clauset, Shalizi & Newman's (2009) eq. (3.1), ``α = 1 + n / Σ ln(x/xmin)``, when ``xmax = inf``, else the
root of the score found by bounded minimisation.

Discrete: ``p(k) = k^-α / Z`` on the integers ``xmin..xmax`` with ``Z = ζ(α, xmin) - ζ(α, xmax + 1)`` (Hurwitz
ζ): the exact likelihood, maximised numerically; never the approximation ``1 + n / Σ ln(k / (xmin - ½))``
(CSN eq. 3.7), whose error reaches tens of per cent at small xmin (powerlaw's issue #104).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, special

__all__ = ["ALPHA_BOUNDS", "alpha_mle", "ccdf", "ks_distance", "log_norm", "logpdf"]

#: The exponents searched by the numerical maxima [-, -]: any catalogue's exponent lies inside (a fit that ends
#: on a bound says so in its message).
ALPHA_BOUNDS = (1.0 + 1e-9, 20.0)


def log_norm(alpha: float, xmin: float, xmax: float, discrete: bool) -> float:
    """ln Z: the normaliser of ``x^-alpha`` on ``[xmin, xmax]`` (integers for ``discrete``)."""
    if discrete:
        z = float(special.zeta(alpha, xmin))
        if math.isfinite(xmax):
            z -= float(special.zeta(alpha, xmax + 1.0))
        return math.log(z) if z > 0 else -math.inf
    u = 1.0 - alpha
    if not math.isfinite(xmax):
        return u * math.log(xmin) - math.log(alpha - 1.0)
    L = math.log(xmax / xmin)
    # Z = ∫ x^-α dx = xmin^u (e^{uL} - 1)/u = xmin^u L exprel(uL): smooth through α = 1
    return u * math.log(xmin) + math.log(L) + math.log(float(special.exprel(u * L)))


def logpdf(x: np.ndarray, alpha: float, xmin: float, xmax: float, discrete: bool) -> np.ndarray:
    """``ln p(x)`` of the power law at each x of the (already cut) tail."""
    return -alpha * np.log(x) - log_norm(alpha, xmin, xmax, discrete)


def _nll(alpha: float, n: int, sum_log: float, xmin: float, xmax: float, discrete: bool) -> float:
    return alpha * sum_log + n * log_norm(alpha, xmin, xmax, discrete)


def alpha_mle(n: int, sum_log: float, xmin: float, xmax: float, discrete: bool) -> tuple[float, int]:
    """The maximum-likelihood exponent of a tail of ``n`` points with ``Σ ln x = sum_log``, and the number of
    likelihood evaluations it took (0 for the closed form)."""
    if not discrete and not math.isfinite(xmax):
        return 1.0 + n / (sum_log - n * math.log(xmin)), 0
    lo = ALPHA_BOUNDS[0] if (discrete or not math.isfinite(xmax)) else -ALPHA_BOUNDS[1]
    res = optimize.minimize_scalar(_nll, bounds=(lo, ALPHA_BOUNDS[1]), method="bounded",
                                   args=(n, sum_log, xmin, xmax, discrete), options={"xatol": 1e-10})
    return float(res.x), int(res.nfev)


def ccdf(x: np.ndarray, alpha: float, xmin: float, xmax: float, discrete: bool) -> np.ndarray:
    """``P(X >= x)`` of the fitted law at each x in ``[xmin, xmax]``."""
    x = np.asarray(x, dtype=float)
    if discrete:
        z = special.zeta(alpha, xmin)
        zx = special.zeta(alpha, np.ceil(x))
        if math.isfinite(xmax):
            top = special.zeta(alpha, xmax + 1.0)
            return np.clip((zx - top) / (z - top), 0.0, 1.0)
        return np.clip(zx / z, 0.0, 1.0)
    u = 1.0 - alpha
    if not math.isfinite(xmax):
        return np.clip((x / xmin) ** u, 0.0, 1.0)
    L = math.log(xmax / xmin)
    with np.errstate(over="ignore"):
        frac = np.log(np.maximum(x, xmin) / xmin) / L  # the share of [ln xmin, ln xmax] below x
        # 1 - ∫_xmin^x / ∫_xmin^xmax, as exprel ratios (smooth through α = 1)
        num = frac * special.exprel(u * L * frac)
        den = special.exprel(u * L)
    return np.clip(1.0 - num / den, 0.0, 1.0)


def ks_distance(tail: np.ndarray, alpha: float, xmin: float, xmax: float, discrete: bool) -> float:
    """The Kolmogorov-Smirnov distance between the sorted ``tail`` and the fitted law: the largest gap between
    the empirical and the fitted CDF, on both sides of each step (continuous), at each distinct value
    (discrete: CDFs ``P(X <= k)`` of the integers)."""
    m = tail.size
    if discrete:
        values, counts = np.unique(tail, return_counts=True)
        emp = np.cumsum(counts) / m  # P(X <= k)
        fit = 1.0 - ccdf(values + 1.0, alpha, xmin, xmax, True)
        return float(np.max(np.abs(emp - fit)))
    F = 1.0 - ccdf(tail, alpha, xmin, xmax, False)
    i = np.arange(m)
    return float(max(np.max((i + 1) / m - F), np.max(F - i / m)))
