"""Power-law fits of burst sizes: :func:`fit_power_law` and its result :class:`PowerLawFit`.

The method is Clauset, Shalizi & Newman (2009; CSN): the exponent by maximum likelihood (continuous, or the exact
discrete likelihood), xmin by the bounded KS scan (``_scan``), intervals by the nonparametric bootstrap (the whole
procedure, xmin's choice included, repeated on resampled catalogues: percentile intervals), and optionally CSN's
goodness-of-fit p-value by their semi-parametric bootstrap.  Every loop stops at ``max_wall`` seconds; a fit
cut short says so in ``status``/``message`` and keeps what it finished.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from .._checks import flag, function, in_range, integer, optional, positive, reals
from .._progress import ProgressLine
from ..io import fmt_number, optional_import, write_rows
from ._laws import ALPHA_BOUNDS, alpha_mle, ccdf, ks_distance, logpdf
from ._scan import ks_scan

__all__ = ["MAX_XMIN_CANDIDATES", "MIN_BOOTSTRAP", "PowerLawFit", "fit_power_law", "sample_power_law"]

#: The largest ``max_candidates`` (K) accepted: the scan costs O(2 K n).
MAX_XMIN_CANDIDATES = 10_000
#: Bootstrap replicates needed for an interval (fewer: the interval is None, and the message says why).
MIN_BOOTSTRAP = 20


@dataclass(frozen=True, eq=False)
class PowerLawFit:
    """A power law fitted to a catalogue's sizes (:func:`fit_power_law`).

    Attributes
    ----------
    alpha : float
        The exponent of ``p(x) ∝ x^-alpha`` on ``[xmin, xmax]`` (maximum likelihood).
    xmin : float
        The start of the power-law tail (given, or chosen by the KS scan).
    xmax : float or None
        The end of the law (given; None: none, the law runs to infinity).
    discrete : bool
        Integer sizes, exact discrete likelihood (Hurwitz ζ normaliser).
    n, n_tail : int
        Sizes given, and those in ``[xmin, xmax]``.
    ks : float
        The Kolmogorov-Smirnov distance between the tail and the fitted law.
    loglik : float
        The tail's log-likelihood under the fit.
    alpha_se : float
        The asymptotic standard error of alpha at fixed xmin, ``abs(alpha - 1)/sqrt(n_tail)`` (CSN eq. 3.2; for a
        discrete or truncated law the same expression, an approximation).
    alpha_interval, xmin_interval : (float, float) or None
        The bootstrap's 95 % percentile intervals (None: fewer than :data:`MIN_BOOTSTRAP` replicates).
    xmin_std : float or None
        The standard deviation of xmin over the bootstrap replicates (0 when xmin was given).
    gof_p : float or None
        CSN's goodness-of-fit p-value (the share of synthetic catalogues from the fit farther from their own fit
        than the data, semi-parametric bootstrap); None unless asked for.  p < 0.1: the power law is ruled out.
    n_bootstrap, n_gof : int
        Replicates done (fewer than asked if ``max_wall`` stopped them).
    xmin_method : str
        ``"given"`` or ``"KS scan over <c> candidates"``.
    candidates, evaluations : int
        Candidate xmin scored in the data's scan; likelihood evaluations of the numerical maxima there.
    status : int
        0: done; 1: stopped by ``max_wall`` (the replicates done are used).
    message : str
        What was done, and any caveat (an exponent on its search bound, a cut loop).
    wall_time : float
        Seconds of wall time.
    seed : int
        The random generator's seed (bootstrap and goodness of fit): the same seed, the same numbers.
    """

    alpha: float
    xmin: float
    xmax: float | None
    discrete: bool
    n: int
    n_tail: int
    ks: float
    loglik: float
    alpha_se: float
    alpha_interval: tuple[float, float] | None
    xmin_interval: tuple[float, float] | None
    xmin_std: float | None
    gof_p: float | None
    n_bootstrap: int
    n_gof: int
    xmin_method: str
    candidates: int
    evaluations: int
    status: int
    message: str
    wall_time: float
    seed: int
    data: np.ndarray = field(repr=False)

    @property
    def tail(self) -> np.ndarray:
        """The sorted sizes in ``[xmin, xmax]``."""
        hi = math.inf if self.xmax is None else self.xmax
        return self.data[(self.data >= self.xmin) & (self.data <= hi)]

    def ccdf(self, x: Any) -> np.ndarray:
        """The fitted law's ``P(X >= x)`` within the tail (x in ``[xmin, xmax]``; 1 below xmin)."""
        hi = math.inf if self.xmax is None else self.xmax
        x = np.asarray(x, dtype=float)
        return np.where(x < self.xmin, 1.0, ccdf(np.maximum(x, self.xmin), self.alpha, self.xmin, hi,
                                                 self.discrete))

    def logpdf(self, x: Any) -> np.ndarray:
        """``ln p(x)`` of the fitted law at sizes in the tail."""
        hi = math.inf if self.xmax is None else self.xmax
        return logpdf(np.asarray(x, dtype=float), self.alpha, self.xmin, hi, self.discrete)

    def compare(self, alternative: str):
        """The likelihood-ratio test of this power law against ``alternative`` (``"lognormal"``,
        ``"exponential"``, ``"truncated_power_law"``) on the same tail: :func:`peelapprox.compare_power_law`."""
        from ._alternatives import compare_power_law

        return compare_power_law(self, alternative)

    def as_dict(self) -> dict[str, Any]:
        """The fit as one flat row (intervals as ``*_lo``/``*_hi``), without the data."""
        d = {k: v for k, v in asdict(self).items() if k != "data"}
        for name in ("alpha_interval", "xmin_interval"):
            lo_hi = d.pop(name)
            d[name.replace("interval", "lo")] = None if lo_hi is None else lo_hi[0]
            d[name.replace("interval", "hi")] = None if lo_hi is None else lo_hi[1]
        return d

    def write(self, path: str) -> str:
        """Write :meth:`as_dict` as one CSV or JSON row (by the extension; :func:`peelapprox.io.write_rows`)."""
        return write_rows(path, [self.as_dict()])

    def to_dataframe(self):
        """:meth:`as_dict` as a one-row :class:`pandas.DataFrame` (``pip install 'peelapprox[data]'``)."""
        pd = optional_import("pandas", "PowerLawFit.to_dataframe")
        row = self.as_dict()
        return pd.DataFrame([row], columns=list(row))

    def __repr__(self) -> str:
        ci = ("" if self.alpha_interval is None else
              f" [{fmt_number(self.alpha_interval[0], 4)}, {fmt_number(self.alpha_interval[1], 4)}]")
        return (f"PowerLawFit(alpha={fmt_number(self.alpha, 4)}{ci}, xmin={fmt_number(self.xmin, 4)}, "
                f"n_tail={self.n_tail} of {self.n}, ks={fmt_number(self.ks, 3)}, status={self.status})")


def _sizes(sizes: Any, discrete: bool) -> np.ndarray:
    x = reals("sizes", sizes, 0.0, math.inf, lo_open=True)
    if x.ndim != 1:
        raise ValueError(f"sizes must be a 1-D array of burst sizes, got shape {x.shape}")
    if discrete and np.any(x != np.round(x)):
        bad = float(x[np.flatnonzero(x != np.round(x))[0]])
        raise ValueError(f"sizes must be integers >= 1 with discrete=True, got {bad!r}")
    return np.sort(x)


def _fit_tail(x: np.ndarray, xmin: float, xmax: float, discrete: bool) -> tuple[float, float, int, int]:
    """``(alpha, ks, n_tail, evaluations)`` of the tail of the sorted data at a given xmin."""
    tail = x[(x >= xmin) & (x <= xmax)]
    if tail.size == 0 or tail[-1] == tail[0] == xmin:
        return math.inf, math.inf, int(tail.size), 0
    a, nev = alpha_mle(tail.size, float(np.sum(np.log(tail))), xmin, xmax, discrete)
    return a, ks_distance(tail, a, xmin, xmax, discrete), int(tail.size), nev


def _estimate(x: np.ndarray, xmin: float | None, xmax: float, discrete: bool, min_tail: int,
              max_candidates: int) -> tuple[float, float, float, int, int, int]:
    """``(xmin, alpha, ks, n_tail, candidates, evaluations)``: the whole procedure on the sorted data, or
    ValueError naming the tail that is too short."""
    if xmin is None:
        scan = ks_scan(x, min_tail=min_tail, max_candidates=max_candidates, xmax=xmax, discrete=discrete)
        if scan is None:
            raise ValueError(f"sizes: too few points for a power-law fit: no xmin leaves min_tail = {min_tail} "
                             f"sizes of more than one value in the tail ({x.size} sizes given)")
        return scan.xmin, scan.alpha, scan.ks, scan.n_tail, scan.candidates, scan.evaluations
    a, d, m, nev = _fit_tail(x, xmin, xmax, discrete)
    if m < min_tail:
        raise ValueError(f"xmin = {xmin!r} leaves {m} sizes in the tail, fewer than min_tail = {min_tail}: "
                         "lower xmin or min_tail")
    if not math.isfinite(a):
        raise ValueError(f"xmin = {xmin!r}: every size in the tail equals xmin, no power law can be fitted")
    return xmin, a, d, m, 0, nev


def sample_power_law(rng: np.random.Generator, n: int, alpha: float, xmin: float, xmax: float = math.inf
                     ) -> np.ndarray:
    """n continuous draws of the power law on ``[xmin, xmax]`` by inversion of its CDF."""
    u = rng.random(n)
    e = 1.0 - alpha
    if not math.isfinite(xmax):
        return xmin * (1.0 - u) ** (1.0 / e)
    if abs(e) < 1e-12:
        return xmin * (xmax / xmin) ** u
    return (xmin**e + u * (xmax**e - xmin**e)) ** (1.0 / e)


def reporter(progress: Any, label: str, total: int) -> Callable[[int], None]:
    """``tick(done)`` for a loop of ``total`` replicates: a :class:`peelapprox.io.ProgressLine` on stderr for
    ``progress=True``, ``progress(done, total)`` for a callable, nothing for False (ArgumentTypeError else)."""
    if progress is True and total:
        line = ProgressLine(label, total)
        return lambda done: line.update(done)
    if progress is False or progress is True:
        return lambda done: None
    fn = function("progress", progress)
    return lambda done: fn(done, total)


def _bootstrap(x, xmin_given, xmax, discrete, min_tail, max_candidates, n_boot, rng, deadline, tick):
    """Alphas and xmins of up to ``n_boot`` nonparametric replicates (resample, redo the whole procedure)."""
    alphas, xmins = [], []
    for k in range(n_boot):
        if time.perf_counter() > deadline:
            break
        tick(k + 1)
        xb = np.sort(rng.choice(x, x.size, replace=True))
        try:
            xm, a, *_ = _estimate(xb, xmin_given, xmax, discrete, min_tail, max_candidates)
        except ValueError:  # a replicate whose tail is too short: it has no fit, it is skipped
            continue
        alphas.append(a)
        xmins.append(xm)
    return np.asarray(alphas), np.asarray(xmins)


def _goodness(x, fit_xmin, alpha, ks, xmin_given, xmax, min_tail, max_candidates, n_gof, rng, deadline, tick):
    """CSN's semi-parametric bootstrap: ``(p, replicates done)``."""
    below = x[x < fit_xmin]
    n_tail = int(np.sum((x >= fit_xmin) & (x <= xmax)))
    worse = done = 0
    for k in range(n_gof):
        if time.perf_counter() > deadline:
            break
        tick(k + 1)
        k = rng.binomial(x.size, n_tail / x.size) if below.size else x.size
        synth = np.concatenate((sample_power_law(rng, k, alpha, fit_xmin, xmax),
                                rng.choice(below, x.size - k, replace=True) if below.size else np.empty(0)))
        try:
            _, _, d, *_ = _estimate(np.sort(synth), xmin_given, xmax, False, min_tail, max_candidates)
        except ValueError:
            continue
        done += 1
        worse += d >= ks
    return (worse / done if done else None), done


def _check_options(xmin, xmax, discrete, n_bootstrap, gof_bootstrap, seed, min_tail, max_candidates, max_wall
                   ) -> tuple:
    """:func:`fit_power_law`'s options checked (ValueError/TypeError naming the option): ``(xmin, hi,
    n_bootstrap, gof_bootstrap, seed, min_tail, max_candidates, max_wall)``, ``hi`` the law's upper end."""
    xmin = optional(positive, "xmin", xmin)
    hi = math.inf if xmax is None else positive("xmax", xmax)
    if xmin is not None and hi <= xmin:
        raise ValueError(f"xmax must be greater than xmin = {xmin!r}, got {xmax!r}")
    if discrete and xmin is not None and xmin != round(xmin):
        raise ValueError(f"xmin must be an integer >= 1 with discrete=True, got {xmin!r}")
    n_bootstrap = integer("n_bootstrap", n_bootstrap, lo=0, hi=100_000)
    gof_bootstrap = integer("gof_bootstrap", gof_bootstrap, lo=0, hi=100_000)
    if gof_bootstrap and discrete:
        raise ValueError("gof_bootstrap must be 0 with discrete=True (the goodness-of-fit test samples a "
                         "continuous law)")
    seed = integer("seed", seed, lo=0, hi=2**63 - 1)
    min_tail = integer("min_tail", min_tail, lo=5, hi=10**9)
    max_candidates = integer("max_candidates", max_candidates, lo=2, hi=MAX_XMIN_CANDIDATES)
    max_wall = in_range("max_wall", max_wall, 0.0, 1e6, lo_open=True)
    return xmin, hi, n_bootstrap, gof_bootstrap, seed, min_tail, max_candidates, max_wall


def _notes(x, discrete, n_tail, status, max_wall, n_done, n_bootstrap, n_gof, gof_bootstrap, min_tail, fxmin,
           alpha) -> list[str]:
    """The sentences of a :class:`PowerLawFit`'s ``message``."""
    notes = [f"{'discrete' if discrete else 'continuous'} maximum likelihood on {n_tail} of {x.size} sizes"]
    if status:
        notes.append(f"max_wall = {max_wall:g} s reached: {n_done} of {n_bootstrap} bootstrap and {n_gof} of "
                     f"{gof_bootstrap} goodness-of-fit replicates done")
    if not status and n_done < n_bootstrap:
        notes.append(f"{n_bootstrap - n_done} of {n_bootstrap} bootstrap replicates had no fit (no tail of "
                     f"min_tail = {min_tail} sizes) and are left out")
    if n_bootstrap and n_done < MIN_BOOTSTRAP:
        notes.append(f"no intervals: {n_done} bootstrap replicates, fewer than {MIN_BOOTSTRAP}")
    if not discrete and fxmin < 6 and np.all(x == np.round(x)):
        notes.append("the sizes are all integers and xmin < 6: the continuous law misfits counts there (CSN "
                     "Sec. 3.5); consider discrete=True")
    if any(abs(alpha - b) < 1e-6 for b in ALPHA_BOUNDS):
        notes.append(f"alpha on the search bound {ALPHA_BOUNDS}: the tail is not a power law in that range")
    return notes


def fit_power_law(sizes: Any, *, xmin: float | None = None, xmax: float | None = None, discrete: bool = False,
                  n_bootstrap: int = 100, gof_bootstrap: int = 0, seed: int = 0, min_tail: int = 50,
                  max_candidates: int = 100, max_wall: float = 60.0,
                  progress: bool | Callable[[int, int], None] = False) -> PowerLawFit:
    """Fit a power law ``p(x) ∝ x^-alpha`` on ``[xmin, xmax]`` to burst sizes (Clauset, Shalizi & Newman 2009).

    Parameters
    ----------
    sizes : array_like
        The sizes (energies, peaks, durations, force drops): a 1-D array of finite values > 0.
    xmin : float, optional
        The start of the tail; None: chosen by the KS scan (least Kolmogorov-Smirnov distance over at most
        ``2 max_candidates`` candidates, each leaving at least ``min_tail`` sizes).
    xmax : float, optional
        A known upper end: the law is normalised on ``[xmin, xmax]`` and sizes above it are left out.
    discrete : bool
        Integer sizes, fitted by the exact discrete likelihood (never the approximation of CSN eq. 3.7).
    n_bootstrap : int
        Nonparametric bootstrap replicates for the 95 % intervals of alpha and xmin (0 to 100000; 100).
    gof_bootstrap : int
        Synthetic catalogues for CSN's goodness-of-fit p-value (0, the default: none; continuous sizes only).
    seed : int
        Seed of the random generator (the same seed, the same intervals).
    min_tail : int
        The fewest sizes a tail may have (5 to 10**9; 50).
    max_candidates : int
        K, the candidate xmin per pass of the scan (2 to :data:`MAX_XMIN_CANDIDATES`; 100).
    max_wall : float
        Wall-time limit of the bootstrap loops [s] (the point fit and one scan, O(2 K n), always finish).
    progress : bool or callable
        Report the bootstrap loops: True, a line on stderr per ~5 % (:class:`peelapprox.io.ProgressLine`); a
        callable, ``progress(k, total)`` as replicate k (from 1) of each loop starts; False, nothing.

    Returns
    -------
    PowerLawFit

    Raises
    ------
    ValueError
        Empty sizes, a size that is NaN, infinite or <= 0, non-integers with ``discrete``, ``xmax <= xmin``,
        too few sizes in the tail, an option out of range.
    """
    t0 = time.perf_counter()
    discrete = flag("discrete", discrete)
    x = _sizes(sizes, discrete)
    xmin, hi, n_bootstrap, gof_bootstrap, seed, min_tail, max_candidates, max_wall = _check_options(
        xmin, xmax, discrete, n_bootstrap, gof_bootstrap, seed, min_tail, max_candidates, max_wall)
    reporter(progress, "", 0)  # checks progress before the work

    fxmin, alpha, ks, n_tail, cands, nev = _estimate(x, xmin, hi, discrete, min_tail, max_candidates)
    tail = x[(x >= fxmin) & (x <= hi)]
    loglik = float(np.sum(logpdf(tail, alpha, fxmin, hi, discrete)))
    rng = np.random.default_rng(seed)
    deadline = t0 + max_wall
    alphas, xmins = _bootstrap(x, xmin, hi, discrete, min_tail, max_candidates, n_bootstrap, rng, deadline,
                               reporter(progress, "power-law bootstrap", n_bootstrap))
    gof_p, n_gof = (None, 0)
    if gof_bootstrap:
        gof_p, n_gof = _goodness(x, fxmin, alpha, ks, xmin, hi, min_tail, max_candidates, gof_bootstrap, rng,
                                 deadline, reporter(progress, "goodness of fit", gof_bootstrap))
    cut = alphas.size < n_bootstrap or n_gof < gof_bootstrap
    status = 1 if time.perf_counter() > deadline and cut else 0
    notes = _notes(x, discrete, n_tail, status, max_wall, alphas.size, n_bootstrap, n_gof, gof_bootstrap, min_tail,
                   fxmin, alpha)
    enough = alphas.size >= MIN_BOOTSTRAP
    pct = (2.5, 97.5)
    return PowerLawFit(
        alpha=float(alpha), xmin=float(fxmin), xmax=None if xmax is None else hi, discrete=discrete, n=int(x.size),
        n_tail=int(n_tail), ks=float(ks), loglik=loglik, alpha_se=float(abs(alpha - 1.0) / math.sqrt(n_tail)),
        alpha_interval=tuple(float(v) for v in np.percentile(alphas, pct)) if enough else None,  # type: ignore
        xmin_interval=tuple(float(v) for v in np.percentile(xmins, pct)) if enough else None,  # type: ignore
        xmin_std=float(np.std(xmins)) if enough else None, gof_p=gof_p, n_bootstrap=int(alphas.size),
        n_gof=int(n_gof), xmin_method="given" if xmin is not None else f"KS scan over {cands} candidates",
        candidates=int(cands), evaluations=int(nev), status=status, message="; ".join(notes),
        wall_time=time.perf_counter() - t0, seed=seed, data=x)
