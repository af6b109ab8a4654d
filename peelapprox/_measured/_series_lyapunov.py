"""The largest Lyapunov exponent of a force trace, by delay embedding and the divergence of nearest neighbours.

:func:`series_lyapunov` (``ForceSeries.lyapunov``) follows Rosenstein, Collins and De Luca (1993) and Kantz
(1994): embed a scalar series ``x`` in ``m`` dimensions with delay ``τ`` (``X_i = (x_i, x_{i+τ}, …,
x_{i+(m-1)τ})``), pair each of a set of reference points with its nearest neighbours further than a Theiler
window ``w`` away in time, follow each pair ``k`` steps and average ``ln |X_{i+k} - X_{j+k}|`` over the pairs
(the mean over ``neighbours`` nearest of the distance first, Kantz's average; one neighbour is Rosenstein's).
The curve rises linearly, with slope λ per step, until the pairs' distances reach the attractor's size; the
slope is fitted over the linear part (``fit``) and divided by the time of a step.

**What is embedded** (``embed``):

``"returns"`` (the default)
    The force before each slip, ``F_n`` (:meth:`ForceSeries.slips`), one step per return, λ per return
    divided by the mean time between slips (the time average of the return times, so the flow's exponent).
    On the model's chaotic trace at V = 2.5 m/s, I = 1e-4 kg m² (50 s at 20 kHz, 6271 slips, 8.0 ms apart)
    the curve is a straight line over 4 nats from k = 0 to ~120 returns for any ``m`` from 2 to 7 (0.033
    nats per return), and the estimate is within 15 % of the exact solver's 5.28 bits/s.
``"trace"``
    The continuous trace F(t), uniformly resampled, one step per sample.  A slip lasts a few samples and two
    neighbours slip at slightly different times, so the curve jumps by ~1.5 nats within the first cycle and
    then bends: its slope falls from ~4.7 to ~3 nats/s over the first second, and the estimate depends on
    the fit range more than on anything else (docs/dynamics.md, "The Lyapunov exponent from a force trace").

**The surrogate test** (``surrogates``).  The null hypothesis is a *linear stochastic process*: a Gaussian
process with the series' power spectrum, seen through a static monotone function (its distribution).  Its
realisations are IAAFT surrogates (iterated amplitude-adjusted Fourier transform: the series' amplitudes and
values, new phases).  The statistic is the slope of each surrogate's divergence curve over the data's own fit
range; the test is one-sided (chaos makes neighbours diverge faster than the null does) and rank-based:
``p = (1 + #{λ_surrogate ≥ λ}) / (n + 1)``, rejected at ``p ≤ alpha`` (19 surrogates: p ≥ 0.05).

A periodic trace gives λ ≈ 0 *and the test does not reject*.  That does not say the trace is noise: the
surrogates of a periodic series are nearly periodic too (its spectrum is lines; new phases of the lines make
another periodic series, blurred only by the lines' leakage into their neighbours) and give λ ≥ 0 (0.01-0.5
bits/s on the model's period-3 orbit, about 0.05 on its period-1 orbit), so the data's λ ≈ 0 is no larger than
the null's.  The test asks for evidence of
sensitive dependence beyond a linear process, and a periodic trace has none.  The verdict "periodic" is read
off λ ≈ 0 and the return map's period (:meth:`ForceSeries.observables`), not off the test.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import textwrap
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from ..io import fmt_number, jsonable
from ..validate import choice, in_range, integer, positive
from ._divergence import MIN_FIT, _curve, _embed, _fit_range, _pairs, _slope

__all__ = ["EMBEDDINGS", "LyapunovOptions", "SeriesLyapunov", "SurrogateTest", "iaaft", "options_signature",
           "series_lyapunov"]

#: What :func:`series_lyapunov` can embed (module docstring).
EMBEDDINGS = ("returns", "trace")
#: The fewest reference points with a neighbour an estimate needs.
MIN_REFERENCES = 20


@dataclass(frozen=True, eq=False)
class SurrogateTest:
    """The surrogate-data test of a :class:`SeriesLyapunov` (module docstring).

    Attributes
    ----------
    kind : str
        ``"IAAFT"``.
    n : int
        Surrogates made (fewer than asked if ``max_wall`` ran out).
    lambdas : ndarray
        Their exponents over the data's fit range [bits/s].
    curves : ndarray
        Their divergence curves, ``(n, len(k))`` (mean ln distance).
    p_value : float
        One-sided rank p-value, ``(1 + #{λ_surrogate ≥ λ}) / (n + 1)``.
    z_score : float
        ``(λ - mean) / std`` of the surrogates' λ (0 when they do not scatter and equal λ).
    alpha : float
        The test's level.
    rejects_noise : bool
        ``p_value <= alpha``: the data's λ exceeds what a linear stochastic process with its spectrum and
        distribution gives.
    """

    kind: str
    n: int
    lambdas: np.ndarray
    curves: np.ndarray
    p_value: float
    z_score: float
    alpha: float
    rejects_noise: bool

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON data (the curves left out)."""
        return {"kind": self.kind, "n": self.n, "lambdas_bits_per_s": jsonable(self.lambdas),
                "p_value": self.p_value, "z_score": self.z_score, "alpha": self.alpha,
                "rejects_noise": self.rejects_noise}


@dataclass(frozen=True, eq=False)
class SeriesLyapunov:
    """The largest Lyapunov exponent of a force trace (:meth:`ForceSeries.lyapunov`).

    Attributes
    ----------
    lambda_bits_per_s : float
        The exponent [bits/s].
    stderr_bits_per_s : float
        The least-squares standard error of the fitted slope [bits/s] (the curve's points are correlated:
        a lower bound on the uncertainty; changing ``fit`` or ``dimension`` moves λ more).
    k : ndarray
        Steps followed (returns, or samples).
    ln_divergence : ndarray
        The mean ln distance of the pairs after ``k`` steps (distances in N).
    fit_range : tuple of int
        ``(k_start, k_end)``, the steps the slope is fitted over.
    intercept : float
        The fitted line's value at ``k = 0``.
    step : float
        Time of a step [s]: the mean time between slips (``"returns"``) or the sampling interval (``"trace"``).
    embedded : str
        ``"returns"`` or ``"trace"``.
    dimension, delay, theiler, neighbours, references : int
        The embedding's dimension and delay [steps], the Theiler window [steps], the neighbours averaged per
        reference point and the reference points used.
    surrogate : SurrogateTest or None
        The surrogate-data test (None with ``surrogates=0``).
    status : str
        ``"ok"``, or what ``max_wall`` cut short.
    method : str
        The method and its settings, in words.
    source : str
        The trace's ``source``.
    V : float or None
        The trace's pull speed [m/s].
    """

    lambda_bits_per_s: float
    stderr_bits_per_s: float
    k: np.ndarray
    ln_divergence: np.ndarray
    fit_range: tuple[int, int]
    intercept: float
    step: float
    embedded: str
    dimension: int
    delay: int
    theiler: int
    neighbours: int
    references: int
    surrogate: SurrogateTest | None
    status: str
    method: str
    source: str
    V: float | None

    def __repr__(self) -> str:
        test = ("" if self.surrogate is None else
                f", surrogates {'reject' if self.surrogate.rejects_noise else 'do not reject'} "
                f"(p = {fmt_number(self.surrogate.p_value, 2)})")
        return (f"SeriesLyapunov({fmt_number(self.lambda_bits_per_s, 3)} ± "
                f"{fmt_number(self.stderr_bits_per_s, 2)} bits/s from {self.embedded}, m = {self.dimension}, "
                f"fit k = {self.fit_range[0]}-{self.fit_range[1]}{test})")

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON data: every field, the curve as lists."""
        return {"lambda_bits_per_s": self.lambda_bits_per_s, "stderr_bits_per_s": self.stderr_bits_per_s,
                "k": jsonable(self.k), "ln_divergence": jsonable(self.ln_divergence),
                "fit_range": list(self.fit_range), "intercept": self.intercept, "step": self.step,
                "embedded": self.embedded, "dimension": self.dimension, "delay": self.delay,
                "theiler": self.theiler, "neighbours": self.neighbours, "references": self.references,
                "surrogate": None if self.surrogate is None else self.surrogate.as_dict(),
                "status": self.status, "method": self.method, "source": self.source, "V": self.V}

    def plot(self, ax: Any = None):
        """The divergence curve against the time followed, the fitted line over the fit range (shaded), and
        the surrogates' band (their smallest to largest mean ln distance).

        Parameters
        ----------
        ax : matplotlib axes, optional
            Draw there; None: new axes from :func:`peelapprox.plotting.pyplot`.

        Returns
        -------
        matplotlib axes
        """
        if ax is None:
            from ..plotting import pyplot

            _, ax = pyplot().subplots(figsize=(7, 4.5))
        tk = self.k * self.step
        if self.surrogate is not None and self.surrogate.n:
            c = self.surrogate.curves
            ax.fill_between(tk, c.min(axis=0), c.max(axis=0), color="0.8",
                            label=f"{self.surrogate.n} IAAFT surrogates")
        ax.plot(tk, self.ln_divergence, lw=1.2, color="C0", label="data")
        a, b = self.fit_range
        slope = self.lambda_bits_per_s * math.log(2.0) * self.step
        kk = np.array([a, b], float)
        ax.plot(kk * self.step, self.intercept + slope * kk, "--", color="C3",
                label=f"fit: {fmt_number(self.lambda_bits_per_s, 3)} ± {fmt_number(self.stderr_bits_per_s, 2)} bits/s")
        ax.axvspan(a * self.step, b * self.step, color="C3", alpha=0.08)
        unit = "returns" if self.embedded == "returns" else "samples"
        ax.set(xlabel=f"time followed, k × {fmt_number(self.step * 1e3, 3)} ms ({unit}) [s]",
               ylabel="mean ln distance [ln N]")
        V = "" if self.V is None else f"V = {fmt_number(self.V, 4)} m/s, "
        ax.set_title(textwrap.fill(f"{V}{self.embedded} embedded (m = {self.dimension}, delay {self.delay}); "
                                   f"{self.source}", 70), fontsize=8)
        ax.legend(loc="lower right", fontsize=8)
        return ax


def iaaft(x: np.ndarray, rng: np.random.Generator, iterations: int = 50) -> np.ndarray:
    """An IAAFT surrogate of ``x`` (Schreiber and Schmitz 1996): the amplitudes of its Fourier transform and its
    values, by alternating the two until the values' order repeats or ``iterations`` is reached."""
    amp = np.abs(np.fft.rfft(x))
    values = np.sort(x)
    s = rng.permutation(x)
    order = np.argsort(s, kind="stable")
    for _ in range(iterations):
        spec = np.fft.rfft(s)
        s = np.fft.irfft(amp * np.exp(1j * np.angle(spec)), n=x.size)
        new = np.argsort(s, kind="stable")
        s = np.empty_like(s)
        s[new] = values
        if np.array_equal(new, order):
            break
        order = new
    return s


@dataclass(frozen=True, kw_only=True)
class LyapunovOptions:
    """The options of :meth:`peelapprox.ForceSeries.lyapunov` (their meaning: its docstring), defined once: the
    method's signature is built from these fields (:func:`options_signature`), and :func:`series_lyapunov` checks
    them here.  The checks of ``dimension``, ``delay``, ``theiler``, ``horizon`` and ``fit_range`` need the series
    (their defaults and ranges depend on its slips) and are made by :func:`series_lyapunov`."""

    embed: str = "returns"
    dimension: int | None = None
    delay: int | None = None
    theiler: int | None = None
    horizon: int | None = None
    neighbours: int = 1
    references: int = 4000
    fit: tuple[float, float] = (0.1, 0.6)
    fit_range: tuple[int, int] | None = None
    surrogates: int = 19
    alpha: float = 0.05
    threshold: float | None = None
    seed: int | None = 0
    max_wall: float = 300.0
    progress: Callable[[int, int], Any] | None = None

    def __post_init__(self) -> None:
        put = functools.partial(object.__setattr__, self)
        put("embed", choice("embed", self.embed, EMBEDDINGS))
        put("neighbours", integer("neighbours", self.neighbours, lo=1, hi=50))
        put("references", integer("references", self.references, lo=MIN_REFERENCES, hi=10**6))
        put("surrogates", integer("surrogates", self.surrogates, lo=0, hi=1000))
        put("alpha", in_range("alpha", self.alpha, 0.0, 1.0, lo_open=True, hi_open=True))
        put("max_wall", positive("max_wall", self.max_wall))
        put("seed", None if self.seed is None else integer("seed", self.seed, lo=0, hi=2**63 - 1))
        fit = self.fit
        if len(fit) != 2 or not 0.0 <= float(fit[0]) < float(fit[1]) <= 1.0:
            raise ValueError(f"fit must be two fractions 0 <= lo < hi <= 1 of the curve's rise, got {fit!r}")


def options_signature(fn: Callable) -> Callable:
    """``fn(first, **options)`` with the signature ``fn(first, *, <the fields of LyapunovOptions>)`` (for
    ``help``, Sphinx and IDEs: the options are written once, as :class:`LyapunovOptions`' fields)."""
    first = next(iter(inspect.signature(fn).parameters.values()))
    kw = [inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=f.default, annotation=f.type)
          for f in dataclasses.fields(LyapunovOptions)]
    fn.__signature__ = inspect.Signature([first, *kw], return_annotation="SeriesLyapunov")  # type: ignore[attr-defined]
    return fn


class _Embedding(NamedTuple):
    """The embedded scalar series ``x``, the time of one step [s], the steps per slip interval, the dimension
    ``m``, the delay ``tau`` and the Theiler window ``w``."""

    x: np.ndarray
    step: float
    per: float
    m: int
    tau: int
    w: int


@options_signature
def series_lyapunov(series: Any, **options: Any) -> SeriesLyapunov:
    """The largest Lyapunov exponent of ``series`` (:meth:`ForceSeries.lyapunov`, whose docstring documents the
    options, :class:`LyapunovOptions`; the module docstring)."""
    names = [f.name for f in dataclasses.fields(LyapunovOptions)]
    unknown = sorted(set(options) - set(names))
    if unknown:
        raise TypeError(f"lyapunov() got an unknown option {unknown[0]!r}; the options are {', '.join(names)}")
    o = LyapunovOptions(**options)
    deadline = time.perf_counter() + o.max_wall
    slips = series.slips(o.threshold)
    if len(slips) < 3:
        raise ValueError(f"the series has {len(slips)} slips (threshold {fmt_number(slips.threshold, 3)} N): "
                         "too few slips for a Lyapunov exponent (a trace without stick-slip has none)")
    interval = float(slips.t_start[-1] - slips.t_start[0]) / (len(slips) - 1)
    e = _embedding(series, slips, interval, o)
    x, m, tau = e.x, e.m, e.tau
    n_emb = x.size - (m - 1) * tau
    kmax, ks = _horizon(o, e, len(slips), n_emb)
    rng = np.random.default_rng(o.seed)
    floor = 1e-12 * (float(np.std(x)) or 1.0)

    def estimate(xs: np.ndarray) -> tuple[np.ndarray, int]:
        return _estimate(xs, e, n_emb, kmax, ks, floor, o, deadline)

    y, n_ref = estimate(x)
    X = _embed(x, m, tau)
    i, j = rng.integers(0, n_emb, 20000), rng.integers(0, n_emb, 20000)
    y_sat = float(np.mean(np.log(np.maximum(np.linalg.norm(X[i] - X[j], axis=1), floor))))
    a, b = _fit_indices(y, y_sat, ks, o)
    sl = slice(a, b + 1)
    slope, se, icept = _slope(ks[sl].astype(float), y[sl])
    to_bits = 1.0 / (e.step * math.log(2.0))
    lam = slope * to_bits
    test, status = _surrogate_test(x, rng, estimate, ks, sl, to_bits, lam, o, deadline)
    what = ("the force before each slip, one step per return, λ per return / the mean time between slips "
            f"({fmt_number(interval * 1e3, 4)} ms)" if o.embed == "returns" else
            f"the trace resampled uniformly, one step per sample ({fmt_number(e.step * 1e3, 4)} ms)")
    fit_how = (f"fit over k = {int(ks[a])}-{int(ks[b])}" + (" (given)" if o.fit_range is not None else
               f" (the curve's rise from {o.fit[0]:g} to {o.fit[1]:g} of the way to the attractor's size)"))
    method = (f"{'Rosenstein' if o.neighbours == 1 else f'Kantz ({o.neighbours} neighbours)'} divergence on "
              f"scipy.spatial.cKDTree: {what}; m = {m}, delay {tau}, Theiler window {e.w}, {n_ref} reference "
              f"points followed {kmax} steps; {fit_how}; " + slips.method)
    return SeriesLyapunov(lambda_bits_per_s=float(lam), stderr_bits_per_s=float(se * to_bits), k=ks,
                          ln_divergence=y, fit_range=(int(ks[a]), int(ks[b])), intercept=float(icept), step=e.step,
                          embedded=o.embed, dimension=m, delay=tau, theiler=e.w, neighbours=o.neighbours,
                          references=n_ref, surrogate=test, status=status, method=method,
                          source=str(series.source), V=series.V)


def _embedding(series: Any, slips: Any, interval: float, o: LyapunovOptions) -> _Embedding:
    """What is embedded (``o.embed``: the returns, or the uniformly resampled trace) and how, the defaults of
    ``dimension``, ``delay`` and ``theiler`` filled and every one checked."""
    if o.embed == "returns":
        x = np.asarray(slips.F_before, float)
        m = integer("dimension", 4 if o.dimension is None else o.dimension, lo=1, hi=20)
        tau = integer("delay", 1 if o.delay is None else o.delay, lo=1, hi=1000)
        w = integer("theiler", m * tau if o.theiler is None else o.theiler, lo=0, hi=10**6)
        return _Embedding(x, interval, 1.0, m, tau, w)
    n = len(series)
    tu = np.linspace(series.t[0], series.t[-1], n)
    x = np.interp(tu, series.t, series.F)
    step = float(tu[1] - tu[0])
    per = interval / step  # samples per slip interval
    m = integer("dimension", 5 if o.dimension is None else o.dimension, lo=1, hi=20)
    tau = integer("delay", max(1, round(per / 8)) if o.delay is None else o.delay, lo=1, hi=10**6)
    w = integer("theiler", max(1, round(per)) if o.theiler is None else o.theiler, lo=0, hi=10**5)
    return _Embedding(x, step, per, m, tau, w)


def _horizon(o: LyapunovOptions, e: _Embedding, n_slips: int, n_emb: int) -> tuple[int, np.ndarray]:
    """The steps each pair is followed and those the curve is evaluated at; ValueError when the series is too short
    for them, or ``o.fit_range`` does not fit."""
    kmax_default = max(MIN_FIT, min(400, (n_slips - 1) // 4))
    kmax = integer("horizon", round(kmax_default * e.per) if o.horizon is None else o.horizon, lo=MIN_FIT, hi=10**7)
    if n_emb - kmax < 2 * e.w + o.neighbours + MIN_REFERENCES:
        what = f"{n_slips} slips" if o.embed == "returns" else f"{e.x.size} samples"
        raise ValueError(f"the series is too short for horizon = {kmax}, dimension = {e.m}, delay = {e.tau} and "
                         f"theiler = {e.w}: {what} give {n_emb} delay vectors, and following {MIN_REFERENCES} "
                         f"of them for {kmax} steps needs {kmax + 2 * e.w + o.neighbours + MIN_REFERENCES}")
    ks = np.arange(kmax + 1) if kmax <= 1000 else np.unique(np.round(np.linspace(0, kmax, 401)).astype(int))
    fit_range = o.fit_range
    if fit_range is not None:
        if (len(fit_range) != 2 or not 0 <= int(fit_range[0]) < int(fit_range[1]) <= kmax
                or int(fit_range[1]) - int(fit_range[0]) < 2):
            raise ValueError(f"fit_range must be (k_start, k_end) steps with 0 <= k_start < k_end - 1 < horizon "
                             f"= {kmax}, got {fit_range!r}")
    return kmax, ks


def _estimate(xs: np.ndarray, e: _Embedding, n_emb: int, kmax: int, ks: np.ndarray, floor: float,
              o: LyapunovOptions, deadline: float) -> tuple[np.ndarray, int]:
    """The divergence curve of ``xs`` (the data or a surrogate) at the steps ``ks`` and its reference points."""
    X = _embed(xs, e.m, e.tau)
    usable = n_emb - kmax
    refs = np.unique(np.linspace(0, usable - 1, min(o.references, usable)).astype(int))
    r, nb = _pairs(X, usable, refs, e.w, o.neighbours, deadline)
    if r.size < MIN_REFERENCES:
        raise ValueError(f"only {r.size} reference points have {o.neighbours} neighbours outside the Theiler "
                         f"window theiler = {e.w}: lower theiler or horizon")
    return _curve(X, r, nb, ks, floor), int(r.size)


def _fit_indices(y: np.ndarray, y_sat: float, ks: np.ndarray, o: LyapunovOptions) -> tuple[int, int]:
    """The first and last index into ``ks`` of the fit: ``o.fit_range``, else the rise fractions ``o.fit``."""
    if o.fit_range is None:
        return _fit_range(y, y_sat, float(o.fit[0]), float(o.fit[1]))
    a = int(np.searchsorted(ks, int(o.fit_range[0])))
    b = int(np.searchsorted(ks, int(o.fit_range[1]), side="right")) - 1
    if b - a + 1 < 3:
        raise ValueError(f"fit_range = {o.fit_range!r} holds {max(b - a + 1, 0)} of the curve's steps (they are "
                         f"{int(ks[1] - ks[0])} apart here): it needs at least 3")
    return a, b


def _surrogate_test(x: np.ndarray, rng: np.random.Generator, estimate: Callable, ks: np.ndarray, sl: slice,
                    to_bits: float, lam: float, o: LyapunovOptions,
                    deadline: float) -> tuple[SurrogateTest | None, str]:
    """The IAAFT surrogate test of ``lam`` (None without surrogates) and the status ("ok", or what the wall
    budget left out)."""
    if not o.surrogates:
        return None, "ok"
    status = "ok"
    lams, curves = [], []
    for q in range(o.surrogates):
        if time.perf_counter() > deadline:
            status = f"max_wall = {fmt_number(o.max_wall, 3)} s ran out after {q} of {o.surrogates} surrogates"
            break
        try:
            ys, _ = estimate(iaaft(x, rng))
        except TimeoutError:
            status = f"max_wall = {fmt_number(o.max_wall, 3)} s ran out after {q} of {o.surrogates} surrogates"
            break
        curves.append(ys)
        lams.append(_slope(ks[sl].astype(float), ys[sl])[0] * to_bits)
        if o.progress is not None:
            o.progress(q + 1, o.surrogates)
    la = np.array(lams, float)
    n_s = int(la.size)
    p = (1.0 + float(np.sum(la >= lam))) / (n_s + 1.0)
    sd = float(np.std(la, ddof=1)) if n_s > 1 else 0.0
    mean = float(np.mean(la)) if n_s else lam
    z = (lam - mean) / sd if sd > 0 else 0.0
    test = SurrogateTest(kind="IAAFT", n=n_s, lambdas=la, curves=np.array(curves, float).reshape(n_s, ks.size),
                         p_value=p, z_score=z, alpha=o.alpha, rejects_noise=bool(p <= o.alpha))
    return test, status
