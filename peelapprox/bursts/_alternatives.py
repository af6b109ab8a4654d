"""The power law against other heavy-tailed forms on the same tail: :func:`compare_power_law` and its result
:class:`LikelihoodRatio` (Clauset, Shalizi & Newman 2009, Sec. 5 and Appendix C).

Each alternative is fitted by maximum likelihood to the tail ``[xmin, xmax]`` the power law was fitted to,
normalised on it (continuous sizes; a discrete fit gets the same laws on the integers, ``_discrete``):

* ``exponential`` — ``p ∝ exp(-λ x)``;
* ``lognormal`` — ``p ∝ exp(-(ln x - μ)² / 2σ²) / x`` (μ searched within ±50 of ln xmin, σ in [0.01, 100]:
  on power-law data the lognormal's maximum runs off to μ → -∞, σ → ∞, where it becomes a power law; a bound
  reached is said in the message);
* ``truncated_power_law`` — ``p ∝ x^-α exp(-λ x)``, λ >= 0 (normaliser by quadrature in ln x).

The test: R = Σ ln p_pl(x_i) - ln p_alt(x_i) over the tail (R > 0 favours the power law).  For the two
non-nested alternatives, Vuong's test: ``z = R / (s √n)`` with s the standard deviation of the pointwise
differences, two-sided p-value ``erfc(|z| / √2)``.  The power law is nested in the truncated one (λ = 0, on the
boundary of λ >= 0): there the likelihood-ratio statistic ``2 (ℓ_alt - ℓ_pl)`` is referred to the
χ̄² mixture ½χ²₀ + ½χ²₁ of a parameter on its boundary (Self & Liang 1987), ``p = ½ P(χ²₁ > 2 (ℓ_alt - ℓ_pl))``,
and ``normalized`` is the signed root of the statistic.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy import integrate, optimize, special

from .._checks import choice
from ..io import fmt_number, write_rows

__all__ = ["ALTERNATIVES", "LikelihoodRatio", "compare_power_law", "vuong"]

#: The alternatives :func:`compare_power_law` fits.
ALTERNATIVES = ("lognormal", "exponential", "truncated_power_law")

#: The p-value below which a test picks a side (CSN: 0.1).
SIGNIFICANCE = 0.1


@dataclass(frozen=True)
class LikelihoodRatio:
    """The power law against an alternative on one tail (:func:`compare_power_law`).

    Attributes
    ----------
    alternative : str
        One of :data:`ALTERNATIVES`.
    R : float
        ``ℓ_pl - ℓ_alt``, the log-likelihood ratio summed over the tail (> 0 favours the power law).
    normalized : float
        Vuong's ``R / (s √n)`` (non-nested), or the signed root of ``2 |R|`` (nested: sign of R).
    p_value : float
        Two-sided Vuong p-value, or the χ̄² p-value of the nested test (module docstring).
    test : str
        ``"vuong"`` or ``"nested chi-bar-squared"``.
    favoured : str
        ``"power_law"``, the alternative's name, or ``"neither"`` (p >= 0.1, or for the nested test: the
        alternative when it is significantly better, else ``"power_law"``, the simpler one).
    params : dict
        The alternative's fitted parameters.
    loglik_power_law, loglik_alternative : float
        The tail's log-likelihoods.
    n : int
        Sizes in the tail.
    message : str
        Caveats (a parameter on its search bound).
    """

    alternative: str
    R: float
    normalized: float
    p_value: float
    test: str
    favoured: str
    params: dict
    loglik_power_law: float
    loglik_alternative: float
    n: int
    message: str

    def as_dict(self) -> dict[str, Any]:
        """One flat row (the parameters as ``param_<name>``)."""
        d = asdict(self)
        for k, v in d.pop("params").items():
            d[f"param_{k}"] = v
        return d

    def write(self, path: str) -> str:
        """Write :meth:`as_dict` as a CSV or JSON row."""
        return write_rows(path, [self.as_dict()])

    def __repr__(self) -> str:
        return (f"LikelihoodRatio(power_law vs {self.alternative}: R={fmt_number(self.R, 4)}, "
                f"p={fmt_number(self.p_value, 3)}, {self.test}, favoured={self.favoured})")


def vuong(ll1: np.ndarray, ll2: np.ndarray) -> tuple[float, float, float]:
    """``(R, z, p)`` of Vuong's test of pointwise log-likelihoods ``ll1`` against ``ll2`` (module docstring)."""
    d = ll1 - ll2
    R = float(np.sum(d))
    s = float(np.std(d))
    if s == 0.0:
        return R, 0.0, 1.0
    z = R / (s * math.sqrt(d.size))
    return R, z, float(special.erfc(abs(z) / math.sqrt(2.0)))


def _exponential(y: np.ndarray, ymax: float) -> tuple[np.ndarray, dict, str]:
    """Pointwise log-likelihoods of the exponential fitted to y >= 1 (scaled sizes), its parameter (per scaled
    size), and a caveat."""
    def logp(lam: float) -> np.ndarray:
        norm = -math.log(-math.expm1(-lam * (ymax - 1.0))) if math.isfinite(ymax) else 0.0
        return math.log(lam) - lam * (y - 1.0) + norm

    lam0 = 1.0 / max(float(np.mean(y - 1.0)), 1e-300)
    if math.isfinite(ymax):
        res = optimize.minimize_scalar(lambda s: -float(np.sum(logp(math.exp(s)))),
                                       bounds=(math.log(lam0) - 30, math.log(lam0) + 30), method="bounded")
        lam0 = math.exp(float(res.x))
    return logp(lam0), {"lambda": lam0}, ""


def _lognormal(y: np.ndarray, ymax: float) -> tuple[np.ndarray, dict, str]:
    ly = np.log(y)
    lmax = math.log(ymax) if math.isfinite(ymax) else math.inf

    def log_mass(mu: float, sig: float) -> float:
        """ln P(0 <= ln y <= ln ymax) of the normal law of ln y, from the side where it does not round to 1."""
        z0, z1 = (0.0 - mu) / sig, (lmax - mu) / sig
        if not math.isfinite(z1):
            return float(special.log_ndtr(-z0))
        if z0 > 0:
            top, d = float(special.log_ndtr(-z0)), float(special.log_ndtr(-z1) - special.log_ndtr(-z0))
        else:
            top, d = float(special.log_ndtr(z1)), float(special.log_ndtr(z0) - special.log_ndtr(z1))
        return top + math.log(-math.expm1(d)) if d < 0 else -math.inf

    def logp(p: np.ndarray) -> np.ndarray:
        mu, sig = float(p[0]), math.exp(float(p[1]))
        return -ly - math.log(sig) - 0.5 * math.log(2 * math.pi) - 0.5 * ((ly - mu) / sig) ** 2 - log_mass(mu, sig)

    def nll(p: np.ndarray) -> float:
        v = -float(np.sum(logp(p)))
        return v if math.isfinite(v) else 1e300  # a mass that rounds to 0: never the maximum

    start = np.array([float(np.mean(ly)), math.log(max(float(np.std(ly)), 0.05))])
    bounds = [(-50.0, 50.0), (math.log(0.01), math.log(100.0))]
    res = optimize.minimize(nll, start, method="L-BFGS-B", bounds=bounds)
    p = res.x
    on_bound = any(abs(p[i] - b) < 1e-6 for i in range(2) for b in bounds[i])
    return logp(p), {"mu": float(p[0]), "sigma": math.exp(float(p[1]))}, (
        "lognormal on its search bound (mu -> -inf, sigma -> inf: it tends to a power law)" if on_bound else "")


def _log_z_truncated(alpha: float, lam: float, ymax: float) -> float:
    """ln ∫_1^ymax y^-alpha e^(-lam (y - 1)) dy, by quadrature in s = ln y."""
    smax = math.log(ymax) if math.isfinite(ymax) else math.inf
    if lam == 0.0 and not math.isfinite(smax):
        return -math.log(alpha - 1.0) if alpha > 1.0 else math.inf

    def f(s: float) -> float:
        if lam > 0.0 and s > 700.0:  # e^(-lam e^s): nothing left (and e^s would overflow)
            return 0.0
        return math.exp(min((1.0 - alpha) * s - lam * math.expm1(s), 700.0))

    val, _ = integrate.quad(f, 0.0, smax, limit=200)
    return math.log(val) if val > 0 else math.inf


def _truncated(y: np.ndarray, ymax: float, alpha0: float) -> tuple[np.ndarray, dict, str]:
    ly = np.log(y)
    s_ly, s_y, n = float(np.sum(ly)), float(np.sum(y - 1.0)), y.size

    def nll(p: np.ndarray) -> float:
        a, lam = float(p[0]), float(p[1])
        lz = _log_z_truncated(a, lam, ymax)
        return a * s_ly + lam * s_y + n * lz if math.isfinite(lz) else 1e300

    lo_a = 1.0 + 1e-9 if not math.isfinite(ymax) else -20.0
    best = None
    for lam0 in (0.0, 1.0 / max(float(np.mean(y - 1.0)), 1e-9)):
        res = optimize.minimize(nll, np.array([max(alpha0, lo_a + 1e-3) if lam0 == 0 else 1.0, lam0]),
                                method="L-BFGS-B", bounds=[(-20.0, 20.0), (0.0, None)])
        # the power-law limit needs alpha > 1 only where lambda = 0
        if best is None or res.fun < best.fun:
            best = res
    assert best is not None
    a, lam = float(best.x[0]), float(best.x[1])
    lz = _log_z_truncated(a, lam, ymax)
    return -a * ly - lam * (y - 1.0) - lz, {"alpha": a, "lambda": lam}, ""


def compare_power_law(fit: Any, alternative: str) -> LikelihoodRatio:
    """Test a :class:`PowerLawFit` against an alternative law on its tail (module docstring).

    Parameters
    ----------
    fit : PowerLawFit
        A power-law fit (:func:`peelapprox.fit_power_law`); a discrete one is compared with the alternatives'
        discrete forms on the integers.
    alternative : str
        One of :data:`ALTERNATIVES`.

    Returns
    -------
    LikelihoodRatio

    Raises
    ------
    ValueError
        An unknown alternative.
    TypeError
        ``fit`` not a :class:`PowerLawFit`.
    """
    alternative = choice("alternative", alternative, ALTERNATIVES)
    if not isinstance(getattr(fit, "discrete", None), bool) or not hasattr(fit, "tail"):
        raise TypeError(f"fit must be a PowerLawFit (peelapprox.fit_power_law), got {type(fit).__name__}")
    if fit.discrete:
        return _discrete_ratio(fit, alternative)
    y = fit.tail / fit.xmin  # scaled: ln p(x) = ln p(y) - ln xmin for every law, so R does not change
    ymax = math.inf if fit.xmax is None else fit.xmax / fit.xmin
    ll_pl = fit.logpdf(fit.tail) + math.log(fit.xmin)
    if alternative == "exponential":
        ll_alt, params, note = _exponential(y, ymax)
        params = {"lambda": params["lambda"] / fit.xmin}
    elif alternative == "lognormal":
        ll_alt, params, note = _lognormal(y, ymax)
        params = {"mu": params["mu"] + math.log(fit.xmin), "sigma": params["sigma"]}
    else:
        ll_alt, params, note = _truncated(y, ymax, fit.alpha)
        params = {"alpha": params["alpha"], "lambda": params["lambda"] / fit.xmin}
    return _ratio(alternative, ll_pl, ll_alt, params, note, -y.size * math.log(fit.xmin))


def _discrete_ratio(fit: Any, alternative: str) -> LikelihoodRatio:
    """:func:`compare_power_law` for a discrete fit: the alternatives on the integers (``_discrete``)."""
    from ._discrete import discrete_alternative

    k = fit.tail
    kmax = math.inf if fit.xmax is None else float(fit.xmax)
    ll_alt, params, note = discrete_alternative(k, int(fit.xmin), kmax, alternative, fit.alpha)
    return _ratio(alternative, fit.logpdf(k), ll_alt, params, note, 0.0)


def _ratio(alternative: str, ll_pl: np.ndarray, ll_alt: np.ndarray, params: dict, note: str, shift: float
           ) -> LikelihoodRatio:
    """The test of the pointwise log-likelihoods (module docstring); ``shift`` turns scaled log-likelihoods into
    the sizes' own (``-n ln xmin``)."""
    if alternative == "truncated_power_law":
        R = float(np.sum(ll_pl - ll_alt))
        stat = max(-2.0 * R, 0.0)  # the alternative's maximum is at least the power law's (nested)
        p = 0.5 * float(special.chdtrc(1, stat)) if stat > 0 else 1.0
        z = -math.copysign(math.sqrt(stat), -R) if stat > 0 else 0.0
        test = "nested chi-bar-squared"
        favoured = alternative if p < SIGNIFICANCE else "power_law"
    else:
        R, z, p = vuong(ll_pl, ll_alt)
        test = "vuong"
        favoured = "neither" if p >= SIGNIFICANCE else ("power_law" if R > 0 else alternative)
    return LikelihoodRatio(alternative=alternative, R=R, normalized=float(z), p_value=float(p), test=test,
                           favoured=favoured, params={k: float(v) for k, v in params.items()},
                           loglik_power_law=float(np.sum(ll_pl) + shift),
                           loglik_alternative=float(np.sum(ll_alt) + shift), n=int(ll_pl.size), message=note)
