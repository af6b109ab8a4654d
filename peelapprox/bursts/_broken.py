"""Two scaling regimes: the broken power law :func:`fit_broken_power_law` and its result :class:`BrokenPowerLawFit`.

The law, continuous, on ``[xmin, ∞)`` with a break at ``xb``::

    p(x) = C x^-alpha1                      xmin <= x < xb
    p(x) = C xb^(alpha2 - alpha1) x^-alpha2  x >= xb         (continuous at xb; alpha2 > 1, alpha1 any)

Fit: for each candidate break (distinct sizes leaving at least ``min_regime`` sizes on each side; at most K
candidates spaced evenly in ln x, then at most K more between the best one's neighbours, as the xmin scan), the
two exponents by maximum likelihood (the likelihood depends on the data through four sums, so each evaluation is
O(1)); the break is the candidate of largest likelihood.

Against one power law on the same ``[xmin, ∞)``: the single law is nested in the broken one (alpha1 = alpha2),
but the break is then not identified, so the likelihood-ratio statistic ``2 (ℓ_broken - ℓ_single)`` does not
follow Wilks' χ² law (Davies 1977, 1987: a nuisance parameter present only under the alternative; with the
break also maximised over, χ²₂ understates p).  The p-value is therefore a parametric bootstrap: catalogues of
the same size drawn from the fitted single law, both fits redone, ``p = (1 + #{LR* >= LR}) / (1 + B)``.
Intervals of both exponents and the break: the nonparametric bootstrap's 95 % percentiles.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from scipy import special

from .._checks import in_range, integer, optional, positive
from ..io import fmt_number, optional_import, write_rows
from ._fit import MAX_XMIN_CANDIDATES, MIN_BOOTSTRAP, _sizes, reporter, sample_power_law
from ._scan import _subsample

__all__ = ["BrokenPowerLawFit", "fit_broken_power_law"]

_A1 = (-20.0, 20.0)
_A2 = (1.0 + 1e-6, 20.0)


@dataclass(frozen=True, eq=False)
class BrokenPowerLawFit:
    """A broken power law against a single one (:func:`fit_broken_power_law`; module docstring).

    Attributes
    ----------
    alpha1, alpha2 : float
        The exponents below and above the break.
    x_break, xmin : float
        The break and the start of the fitted range.
    n, n_below, n_above : int
        Sizes >= xmin, and those below and above the break.
    loglik : float
        The broken law's log-likelihood.
    alpha_single, loglik_single : float
        The single power law on the same range (CSN eq. 3.1) and its log-likelihood.
    lr_statistic : float
        ``2 (loglik - loglik_single)`` (>= 0).
    p_value : float or None
        The parametric-bootstrap p-value of the single law (small: two regimes); None with ``n_null = 0``.
    n_null : int
        Synthetic single-law catalogues behind ``p_value``.
    alpha1_interval, alpha2_interval, x_break_interval : (float, float) or None
        Bootstrap 95 % percentile intervals (None: fewer than 20 replicates).
    n_bootstrap : int
        Bootstrap replicates done.
    candidates : int
        Break candidates scored on the data.
    status : int
        0 done; 1 ``max_wall`` stopped a bootstrap (what was done is used).
    message : str
        What was done, and caveats.
    wall_time : float
        Seconds.
    seed : int
        The random generator's seed.
    """

    alpha1: float
    alpha2: float
    x_break: float
    xmin: float
    n: int
    n_below: int
    n_above: int
    loglik: float
    alpha_single: float
    loglik_single: float
    lr_statistic: float
    p_value: float | None
    n_null: int
    alpha1_interval: tuple[float, float] | None
    alpha2_interval: tuple[float, float] | None
    x_break_interval: tuple[float, float] | None
    n_bootstrap: int
    candidates: int
    status: int
    message: str
    wall_time: float
    seed: int
    data: np.ndarray = field(repr=False)

    def ccdf(self, x: Any) -> np.ndarray:
        """The broken law's ``P(X >= x)`` (1 below xmin)."""
        y = np.maximum(np.asarray(x, dtype=float), self.xmin) / self.xmin
        yb = self.x_break / self.xmin
        a, b = self.alpha1, self.alpha2
        lz = _log_z(a, b, math.log(yb))
        ly = np.log(y)
        below = np.exp(_log_i1(a, np.minimum(ly, math.log(yb))) - lz)
        above = np.exp((b - a) * math.log(yb) + (1.0 - b) * ly - math.log(b - 1.0) - lz)
        return np.clip(np.where(y < yb, 1.0 - below, above), 0.0, 1.0)

    def as_dict(self) -> dict[str, Any]:
        """One flat row (intervals as ``*_lo``/``*_hi``), without the data."""
        d = {k: v for k, v in asdict(self).items() if k != "data"}
        for name in ("alpha1_interval", "alpha2_interval", "x_break_interval"):
            lo_hi = d.pop(name)
            base = name.removesuffix("_interval")
            d[f"{base}_lo"] = None if lo_hi is None else lo_hi[0]
            d[f"{base}_hi"] = None if lo_hi is None else lo_hi[1]
        return d

    def write(self, path: str) -> str:
        """Write :meth:`as_dict` as a CSV or JSON row."""
        return write_rows(path, [self.as_dict()])

    def to_dataframe(self):
        """:meth:`as_dict` as a one-row :class:`pandas.DataFrame`."""
        pd = optional_import("pandas", "BrokenPowerLawFit.to_dataframe")
        row = self.as_dict()
        return pd.DataFrame([row], columns=list(row))

    def __repr__(self) -> str:
        p = "None" if self.p_value is None else fmt_number(self.p_value, 3)
        return (f"BrokenPowerLawFit(alpha1={fmt_number(self.alpha1, 4)}, alpha2={fmt_number(self.alpha2, 4)}, "
                f"x_break={fmt_number(self.x_break, 4)}, LR={fmt_number(self.lr_statistic, 4)}, p={p})")


def _log_i1(a: float, ly: Any) -> Any:
    """ln ∫_1^y t^-a dt for ln y = ly > 0 (smooth through a = 1)."""
    ly = np.asarray(ly, dtype=float)
    with np.errstate(divide="ignore"):
        return np.log(ly) + np.log(special.exprel((1.0 - a) * ly))


def _log_z(a: float, b: float, L: float) -> float:
    """ln of the broken law's normaliser on y >= 1 (break at ln yb = L)."""
    lo = float(_log_i1(a, L))
    hi = (1.0 - a) * L - math.log(b - 1.0)
    return float(np.logaddexp(lo, hi))


def _profile(a: np.ndarray, L: np.ndarray, n: int, s1: np.ndarray, n2: np.ndarray, s2: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """``(alpha2, loglik)`` at exponents ``a`` below breaks ``ln yb = L``, alpha2 maximised in closed form.

    With A = ∫_1^yb y^-a dy, c = yb^(1-a) and T2 = Σ ln(y/yb) above the break, ∂ℓ/∂alpha2 = 0 is the quadratic
    A β² + c β - n c / T2 = 0 in β = alpha2 - 1, whose positive root is taken in its cancellation-free form.
    """
    A = L * special.exprel((1.0 - a) * L)
    c = np.exp((1.0 - a) * L)
    t2 = np.maximum(s2 - n2 * L, 1e-300)
    q = n * c / t2
    beta = 2.0 * q / (c + np.sqrt(c * c + 4.0 * A * q))
    b = 1.0 + beta
    ll = -a * s1 - b * s2 + n2 * (b - a) * L - n * np.log(A + c / beta)
    return b, ll


def _fit_breaks(L: np.ndarray, n: int, s1: np.ndarray, n2: np.ndarray, s2: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(alpha1, alpha2, loglik)`` at each break ``ln yb = L``: alpha1 by golden-section search on
    :data:`_A1` of the profile likelihood (:func:`_profile`), all breaks at once (90 steps: width 40 · 0.618^90,
    below 1e-17)."""
    g = (math.sqrt(5.0) - 1.0) / 2.0
    lo = np.full(L.shape, _A1[0])
    hi = np.full(L.shape, _A1[1])
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = _profile(x1, L, n, s1, n2, s2)[1], _profile(x2, L, n, s1, n2, s2)[1]
    for _ in range(90):
        right = f1 < f2  # the maximum lies in [x1, hi]
        lo = np.where(right, x1, lo)
        hi = np.where(right, hi, x2)
        x1n = np.where(right, x2, hi - g * (hi - lo))
        x2n = np.where(right, lo + g * (hi - lo), x1)
        fn = _profile(np.where(right, x2n, x1n), L, n, s1, n2, s2)[1]
        f1, f2 = np.where(right, f2, fn), np.where(right, fn, f1)
        x1, x2 = x1n, x2n
    a = 0.5 * (lo + hi)
    b, ll = _profile(a, L, n, s1, n2, s2)
    return a, b, ll


def _broken(y: np.ndarray, min_regime: int, max_candidates: int) -> tuple[float, float, float, float, int, int]:
    """``(alpha1, alpha2, yb, loglik, n_below, candidates)`` of the sorted scaled sizes y >= 1 (module
    docstring); ValueError when no break leaves ``min_regime`` sizes on each side."""
    n = y.size
    first = np.flatnonzero(np.r_[True, y[1:] != y[:-1]])
    idx = first[(first >= min_regime) & (n - first >= min_regime) & (y[first] > 1.0)]
    if idx.size == 0:
        raise ValueError(f"sizes: too few for a broken power law: no break leaves min_regime = {min_regime} sizes "
                         f"on each side ({n} sizes >= xmin)")
    ly = np.log(y)
    cs = np.r_[0.0, np.cumsum(ly)]
    total = float(cs[-1])

    def run(indices: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s1 = cs[indices]
        return _fit_breaks(ly[indices], n, s1, (n - indices).astype(float), total - s1)

    coarse = _subsample(idx, y, max_candidates)
    ll = run(coarse)[2]
    pos = int(np.argmax(ll))
    lo, hi = int(coarse[max(pos - 1, 0)]), int(coarse[min(pos + 1, coarse.size - 1)])
    fine = np.union1d(coarse, _subsample(idx[(idx >= lo) & (idx <= hi)], y, max_candidates))
    a, b, ll = run(fine)
    k = int(np.argmax(ll))
    return float(a[k]), float(b[k]), float(y[fine[k]]), float(ll[k]), int(fine[k]), int(fine.size)


def _single(y: np.ndarray) -> tuple[float, float]:
    """The single power law on y >= 1: ``(alpha, loglik)`` (CSN eq. 3.1)."""
    s = float(np.sum(np.log(y)))
    a = 1.0 + y.size / s
    return a, y.size * math.log(a - 1.0) - a * s


def _bootstrap(y, x0, min_regime, max_candidates, n_bootstrap, rng, deadline, tick) -> list:
    """``(alpha1, alpha2, x_break)`` of up to ``n_bootstrap`` nonparametric replicates (a replicate without two
    regimes of ``min_regime`` is skipped)."""
    boot: list[tuple[float, float, float]] = []
    for k in range(n_bootstrap):
        if time.perf_counter() > deadline:
            break
        tick(k + 1)
        yr = np.sort(rng.choice(y, y.size, replace=True))
        try:
            b1, b2, bb, *_ = _broken(yr, min_regime, max_candidates)
        except ValueError:
            continue
        boot.append((b1, b2, bb * x0))
    return boot


def _null(y, a_s, lr, min_regime, max_candidates, n_null, rng, deadline, tick) -> tuple[int, int]:
    """The parametric bootstrap of the likelihood ratio: ``(catalogues with LR* >= lr, catalogues done)``, each
    drawn from the fitted single law (exponent ``a_s``)."""
    worse = done = 0
    for k in range(n_null):
        if time.perf_counter() > deadline:
            break
        tick(k + 1)
        ys = np.sort(sample_power_law(rng, y.size, a_s, 1.0))
        try:
            llb = _broken(ys, min_regime, max_candidates)[3]
        except ValueError:
            continue
        done += 1
        worse += 2.0 * (llb - _single(ys)[1]) >= lr
    return worse, done


def fit_broken_power_law(sizes: Any, *, xmin: float | None = None, n_bootstrap: int = 50, n_null: int = 50,
                         seed: int = 0, min_regime: int = 50, max_candidates: int = 40,
                         max_wall: float = 120.0, progress: bool | Callable[[int, int], None] = False
                         ) -> BrokenPowerLawFit:
    """Fit a broken (two-regime) power law and test it against a single one (module docstring).

    Parameters
    ----------
    sizes : array_like
        Burst sizes: a 1-D array of finite values > 0.
    xmin : float, optional
        The start of the fitted range (default: the smallest size: the whole catalogue).
    n_bootstrap : int
        Nonparametric bootstrap replicates for the intervals (0 to 100000; 50).
    n_null : int
        Synthetic single-law catalogues for the likelihood-ratio p-value (0 to 100000; 50).
    seed : int
        Seed of the random generator.
    min_regime : int
        The fewest sizes on either side of the break (5 to 10**9; 50).
    max_candidates : int
        K, break candidates per pass (2 to 10000; 40): cost O(2 K) two-parameter fits per catalogue.
    max_wall : float
        Wall-time limit of the two bootstrap loops together [s].
    progress : bool or callable
        Report the two bootstrap loops (as :func:`peelapprox.fit_power_law`).

    Returns
    -------
    BrokenPowerLawFit

    Raises
    ------
    ValueError
        Bad sizes (empty, NaN, infinite, <= 0), too few sizes for two regimes of ``min_regime``, an option out
        of range.
    """
    t0 = time.perf_counter()
    x = _sizes(sizes, False)
    xmin = optional(positive, "xmin", xmin)
    n_bootstrap = integer("n_bootstrap", n_bootstrap, lo=0, hi=100_000)
    n_null = integer("n_null", n_null, lo=0, hi=100_000)
    seed = integer("seed", seed, lo=0, hi=2**63 - 1)
    min_regime = integer("min_regime", min_regime, lo=5, hi=10**9)
    max_candidates = integer("max_candidates", max_candidates, lo=2, hi=MAX_XMIN_CANDIDATES)
    max_wall = in_range("max_wall", max_wall, 0.0, 1e6, lo_open=True)
    reporter(progress, "", 0)  # checks progress before the work
    x0 = float(x[0]) if xmin is None else xmin
    y = x[x >= x0] / x0
    a1, a2, yb, ll, n1, cands = _broken(y, min_regime, max_candidates)  # ValueError if too few: before _single
    a_s, ll_s = _single(y)
    lr = max(2.0 * (ll - ll_s), 0.0)
    rng = np.random.default_rng(seed)
    deadline = t0 + max_wall
    boot = _bootstrap(y, x0, min_regime, max_candidates, n_bootstrap, rng, deadline,
                      reporter(progress, "broken-law bootstrap", n_bootstrap))
    worse, done = _null(y, a_s, lr, min_regime, max_candidates, n_null, rng, deadline,
                        reporter(progress, "broken-law null catalogues", n_null))
    notes = [f"{cands} break candidates; LR p-value by parametric bootstrap ({done} single-law catalogues)"]
    status = 1 if (len(boot) < n_bootstrap or done < n_null) and time.perf_counter() > deadline else 0
    if status:
        notes.append(f"max_wall = {max_wall:g} s reached: {len(boot)} of {n_bootstrap} bootstrap and {done} of "
                     f"{n_null} null replicates done")
    arr = np.asarray(boot).reshape(-1, 3)
    ok = arr.shape[0] >= MIN_BOOTSTRAP

    def ci(j: int) -> tuple[float, float] | None:
        return (float(np.percentile(arr[:, j], 2.5)), float(np.percentile(arr[:, j], 97.5))) if ok else None

    if any(abs(v - b) < 1e-6 for v, bs in ((a1, _A1), (a2, _A2)) for b in bs):
        notes.append("an exponent is on its search bound")
    return BrokenPowerLawFit(
        alpha1=a1, alpha2=a2, x_break=yb * x0, xmin=x0, n=int(y.size), n_below=int(n1), n_above=int(y.size - n1),
        loglik=ll - y.size * math.log(x0), alpha_single=a_s, loglik_single=ll_s - y.size * math.log(x0),
        lr_statistic=lr, p_value=(1.0 + worse) / (1.0 + done) if done else None, n_null=done,
        alpha1_interval=ci(0), alpha2_interval=ci(1), x_break_interval=ci(2), n_bootstrap=arr.shape[0],
        candidates=cands, status=status, message="; ".join(notes), wall_time=time.perf_counter() - t0, seed=seed,
        data=x)
