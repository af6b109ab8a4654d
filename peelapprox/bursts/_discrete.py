"""The alternatives of :func:`compare_power_law` for a discrete fit: laws on the integers ``kmin..kmax``.

* ``exponential`` — the geometric law ``p(k) ∝ e^(-λ (k - kmin))``, normalised in closed form;
* ``lognormal`` — ``p(k) ∝ exp(-(ln k - μ)² / 2σ²) / k`` (the same bounds on μ and σ as the continuous one);
* ``truncated_power_law`` — ``p(k) ∝ k^-α e^(-λ (k - kmin))``, λ >= 0.

The last two are normalised by summing the terms from kmin on, at most :data:`MAX_TERMS` of them, and the rest
by the integral of the same function from the last term + ½ to kmax + ½ (the midpoint rule, whose relative
error per term is ~ f''/24f ~ α²/24k², below 1e-8 past 10⁴ terms).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, optimize, special

__all__ = ["MAX_TERMS", "discrete_alternative"]

#: Terms summed exactly in a normaliser (the rest as an integral).
MAX_TERMS = 10_000


def _log_sum(logf, kmin: int, kmax: float, tail) -> float:
    """ln (Σ_{k=kmin}^{K} f(k) + ∫_{K+1/2}^{kmax+1/2} f) with K = min(kmax, kmin + MAX_TERMS - 1)."""
    K = int(min(kmax, kmin + MAX_TERMS - 1))
    lf = logf(np.arange(kmin, K + 1, dtype=float))
    m = float(np.max(lf))
    s = float(np.sum(np.exp(lf - m)))
    if K < kmax:
        s += tail(K + 0.5, kmax + 0.5) * math.exp(-m)
    return m + math.log(s)


def _lognormal(k: np.ndarray, kmin: int, kmax: float) -> tuple[np.ndarray, dict, str]:
    lk = np.log(k)
    s_lk = float(np.sum(lk))

    def log_z(mu: float, sig: float) -> float:
        def tail(a: float, b: float) -> float:
            za, zb = (math.log(a) - mu) / sig, (math.log(b) - mu) / sig if math.isfinite(b) else math.inf
            return sig * math.sqrt(2 * math.pi) * float(special.ndtr(-za) - (special.ndtr(-zb) if zb < math.inf
                                                                              else 0.0))
        return _log_sum(lambda x: -np.log(x) - 0.5 * ((np.log(x) - mu) / sig) ** 2, kmin, kmax, tail)

    def nll(p: np.ndarray) -> float:
        mu, sig = float(p[0]), math.exp(float(p[1]))
        return s_lk + float(np.sum(0.5 * ((lk - mu) / sig) ** 2)) + k.size * log_z(mu, sig)

    bounds = [(math.log(kmin) - 50.0, math.log(kmin) + 50.0), (math.log(0.01), math.log(100.0))]
    start = np.array([float(np.mean(lk)), math.log(max(float(np.std(lk)), 0.05))])
    res = optimize.minimize(nll, start, method="L-BFGS-B", bounds=bounds)
    mu, sig = float(res.x[0]), math.exp(float(res.x[1]))
    on_bound = any(abs(res.x[i] - b) < 1e-6 for i in range(2) for b in bounds[i])
    ll = -lk - 0.5 * ((lk - mu) / sig) ** 2 - log_z(mu, sig)
    return ll, {"mu": mu, "sigma": sig}, ("lognormal on its search bound (mu -> -inf, sigma -> inf: it tends to "
                                          "a power law)" if on_bound else "")


def _exponential(k: np.ndarray, kmin: int, kmax: float) -> tuple[np.ndarray, dict, str]:
    d = k - kmin
    span = kmax - kmin + 1.0

    def log_z(lam: float) -> float:  # Σ_{j=0}^{span-1} e^(-λ j)
        top = math.log(-math.expm1(-lam * span)) if math.isfinite(span) else 0.0
        return top - math.log(-math.expm1(-lam))

    def nll(s: float) -> float:
        lam = math.exp(s)
        return lam * float(np.sum(d)) + k.size * log_z(lam)

    m = max(float(np.mean(d)), 1e-12)
    lam = math.log1p(1.0 / m)  # the geometric law's closed-form maximum without kmax
    if math.isfinite(span):
        res = optimize.minimize_scalar(nll, bounds=(math.log(lam) - 30, math.log(lam) + 30), method="bounded")
        lam = math.exp(float(res.x))
    return -lam * d - log_z(lam), {"lambda": lam}, ""


def _truncated(k: np.ndarray, kmin: int, kmax: float, alpha0: float) -> tuple[np.ndarray, dict, str]:
    lk = np.log(k)
    s_lk, s_d = float(np.sum(lk)), float(np.sum(k - kmin))

    def log_z(a: float, lam: float) -> float:
        if lam == 0.0 and a <= 1.0 and not math.isfinite(kmax):
            return math.inf

        def f(s: float) -> float:  # x^-a e^(-lam (x - kmin)) dx with x = e^s
            if lam == 0.0:
                return math.exp(min((1.0 - a) * s, 700.0))
            if s > 700.0:
                return 0.0
            return math.exp(min((1.0 - a) * s - lam * (math.exp(s) - kmin), 700.0))

        def tail(lo: float, hi: float) -> float:
            return integrate.quad(f, math.log(lo), math.log(hi) if math.isfinite(hi) else math.inf, limit=200)[0]
        return _log_sum(lambda x: -a * np.log(x) - lam * (x - kmin), kmin, kmax, tail)

    def nll(p: np.ndarray) -> float:
        a, lam = float(p[0]), float(p[1])
        lz = log_z(a, lam)
        return a * s_lk + lam * s_d + k.size * lz if math.isfinite(lz) else 1e300

    best = None
    for start in (np.array([max(alpha0, 1.001), 0.0]), np.array([1.0, 1.0 / max(s_d / k.size, 1e-9)])):
        res = optimize.minimize(nll, start, method="L-BFGS-B", bounds=[(-20.0, 20.0), (0.0, None)])
        if best is None or res.fun < best.fun:
            best = res
    assert best is not None
    a, lam = float(best.x[0]), float(best.x[1])
    return -a * lk - lam * (k - kmin) - log_z(a, lam), {"alpha": a, "lambda": lam}, ""


def discrete_alternative(k: np.ndarray, kmin: int, kmax: float, alternative: str, alpha0: float
                         ) -> tuple[np.ndarray, dict, str]:
    """Pointwise log-likelihoods of the alternative fitted to the integer tail ``k`` (module docstring), its
    parameters and a caveat."""
    if alternative == "exponential":
        return _exponential(k, kmin, kmax)
    if alternative == "lognormal":
        return _lognormal(k, kmin, kmax)
    return _truncated(k, kmin, kmax, alpha0)
