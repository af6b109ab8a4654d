"""The statistics :func:`exact.infer` fits: a force trace's, measured or the model's, read the same way.

* **Statistics** (:data:`STATISTICS`): the slip interval, force drop, stick and slip times of
  :meth:`ForceSeries.observables`, the mean slope of the sticks (``k (V - v)``: mostly k), the mean force at
  a slip's start (set by the law and the α oscillation: mostly I; the trace's linear trend removed, so a
  machine's slow drift does not read as force) and the cycle frequency (left out where no line stands out of the
  periodogram below half the slip frequency, :data:`LINE_RATIO`: a period-1 trace holds only drift and noise
  there).  The model's are read off an exact run
  (``t_transient`` seconds, then the series' duration at its sampling times) with white noise of the series'
  level added (σ of :meth:`ForceSeries.noise`, a fixed seed), by the same detector with the same threshold, so
  the detector's remaining biases under noise cancel.
* **The attractor set** (:func:`set_statistics`).  A trial point may hold several attractors; the model's
  statistics there are those of the attractor closest to the data among the ones reached from the first starts
  of :func:`exact.attractor_set`'s design, each run sampled and read as above, so the data's attractor counts
  even where its basin is a needle the solver's start misses.
* **Residuals.**  ``(model - data) / σ``, σ the detector's repeatability under noise
  (:data:`REPEATABILITY`, relative, measured) and, for an aperiodic trace, the standard error of the mean in
  quadrature; a periodic trace's means are over whole cycles.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from peelapprox import ForceSeries, PeelParams
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded
from peelapprox.io import fmt_number

from .._simulate import simulate
from ._attractor_set_runs import default_starts

__all__ = ["CLOSE", "LINE_RATIO", "NOISE_REPLICATES", "NOISE_SEED", "PERIOD_MARGIN", "STATISTICS", "REPEATABILITY",
           "SAME_ATTRACTOR", "SeriesData", "SetReading", "Spread", "data_period", "data_statistics", "model_period",
           "model_statistics", "noise_spread", "period_disagreements", "period_tolerance", "replicate_mean",
           "replicate_spread", "same_attractor", "set_statistics", "trace_statistics"]

#: The statistics fitted, in this order (module docstring).
STATISTICS = ("slip_interval", "force_drop", "stick_time", "slip_time", "rise", "F_start", "f_cycle")
#: The σ of each statistic, relative: not the detector's repeatability under noise (a 20 s, 10 kHz model trace
#: read with 0.5 N of white noise and without differs by 2e-6 in the slip interval, 0.2 % in the drop, 4.5 % in
#: the slip time) but the model's own roughness: from one periodic window to the next (I varied by 5 % steps
#: at V = 1 m/s, I = 1e-2) the means jump by 0.3 to 4 %, so a σ below that makes χ² a comb whose teeth no search
#: can resolve.  The cycle frequency (the strongest spectral line below half the slip frequency: the return
#: map's cycle, 1/(n · slip interval), which follows the α oscillation, ∝ I^-1/2 at high inertia) gets 3 %.
REPEATABILITY = {"slip_interval": 0.02, "force_drop": 0.02, "stick_time": 0.02, "slip_time": 0.05, "rise": 0.02,
                 "F_start": 0.005, "f_cycle": 0.03}
#: The height over the periodogram's median (in the band below half the slip frequency) from which its strongest
#: peak is a line of the stick-slip, the cycle frequency fitted: white noise's largest of N bins is about
#: ln N / ln 2 times their median (17 for 1e5 bins; measured 10-12 on 20 s at 10 kHz with 0.5 N of noise), a
#: period-3 orbit's line 4e6 times (V = 1 m/s, I = 1e-5, the same noise).
LINE_RATIO = 100.0
#: A start's trace fits the data well enough that the further starts of the set need not run when every fitted
#: residual is within this many σ (a start far from the data's attractor is off by tens of σ).
CLOSE = 3.0
#: Two readings are of one attractor where their slip interval, force drop and slip-start force agree within this
#: fraction (:func:`same_attractor`): replicates of one chaotic window (5-20 s) scatter by 1-3 % in these
#: (V = 0.6854 m/s, I = 2.46e-5 and V = 2.249 m/s, I = 3.2e-4, 4 starts each), while the other tori the starts reach
#: at the quasi-periodic points of ``comparisons.benchmark.infer_targets`` (seeds 2 and 4) differ by 21-70 %.
SAME_ATTRACTOR = 0.1
#: The noise draws of :func:`noise_spread` (the detector's spread under noise at an aperiodic fit's best grid point).
NOISE_REPLICATES = 4
#: The seed of the noise added to every model trace (the same at every parameter point: the statistics move with
#: the parameters, not with a new draw).
NOISE_SEED = 20041
#: The fitted attractor's period differs clearly from the data's (:func:`period_disagreements`) where its trace,
#: read at this many times the data's period tolerance (:func:`period_tolerance`), still repeats neither after the
#: data's period nor after a divisor of it.  The tolerance is set so that the noise alone stays below it (the
#: largest |F_{k+n} - F_k| of a noisy period-n trace), so a mismatch above twice it is a modulation above the
#: tolerance itself, which any noise draw shows: a sawtooth at 0.5 N of noise whose forces before a slip carry a
#: period-4 modulation of 0.6 N peak to peak reads period 2 at the tolerance (0.95 N) and period 1 at twice it.
PERIOD_MARGIN = 2.0


def trace_statistics(series: ForceSeries, threshold: float | None
                     ) -> tuple[np.ndarray | None, Any, bool, float]:
    """The statistics of :data:`STATISTICS` of a series (None if it does not stick-slip), its observables,
    whether its periodogram holds a cycle line (:func:`_cycle_frequency`) and the detector's threshold."""
    slips = series.slips(threshold, method="knee")  # the detector the statistics were calibrated with
    o = series.observables(slips=slips)  # read off these slips, not detected a second time
    if o.status != "stick-slip" or len(slips) < 2:
        return None, o, False, slips.threshold
    assert o.slip_interval is not None  # stick-slip with two slips or more
    f_cycle, line = _cycle_frequency(series, 1.0 / o.slip_interval)
    vals = [getattr(o, n) for n in STATISTICS[:4]] + [float(np.mean(slips.rise)), _start_force(slips), f_cycle]
    return np.asarray(vals, dtype=float), o, line, slips.threshold


def _start_force(slips: Any) -> float:
    """The mean force at a slip's start with the trace's linear trend removed, referred to its first slip: a
    machine's slow drift (tared at the start) does not read as a larger force.  A periodic model trace has no
    trend, so this is its plain mean there."""
    t, F = np.asarray(slips.t_start), np.asarray(slips.F_before)
    if t.size < 3 or t[-1] <= t[0]:
        return float(np.mean(F))
    slope = np.polyfit(t - t[0], F, 1)[0]
    return float(np.mean(F - slope * (t - t[0])))


def _cycle_frequency(series: ForceSeries, f_slip: float) -> tuple[float, bool]:
    """The cycle frequency [Hz] and whether it is a line of the periodogram.

    The strongest line of the trace's periodogram (Hann window, linear trend removed) between 3 / duration and
    half the slip frequency, refined by a parabola through its log power and its neighbours, if it stands out
    of the band's median by :data:`LINE_RATIO` and lies within two bins of ``f_slip / n`` for an integer
    n >= 2 (a period-n return map's cycle); else no line: ``(f_slip, False)``, the cycle of a period-1 map. A
    noiseless period-1 trace's strongest peak is an aliased harmonic of the slips (21.5 Hz = 85 f_slip - 10 kHz
    at V = 3.95 m/s), which moves wildly with the parameters."""
    from scipy.signal import periodogram

    f, p = periodogram(series.F, fs=(len(series) - 1) / series.duration, window="hann", detrend="linear")
    band = np.flatnonzero((f >= 3.0 / series.duration) & (f <= 0.5 * f_slip))
    if band.size < 3:
        return f_slip, False
    i = int(band[np.argmax(p[band])])
    floor = float(np.median(p[band]))
    if floor > 0 and p[i] < LINE_RATIO * floor:
        return f_slip, False
    line = float(f[i])
    if 0 < i < f.size - 1 and min(p[i - 1], p[i], p[i + 1]) > 0:
        a, b, c = np.log(p[i - 1]), np.log(p[i]), np.log(p[i + 1])
        shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c != 0 else 0.0
        line += max(-0.5, min(0.5, shift)) * float(f[1] - f[0])
    n = round(f_slip / line) if line > 0 else 0
    if n < 2 or abs(f_slip / n - line) > 2.0 * float(f[1] - f[0]):
        return f_slip, False
    return line, True


@dataclass(frozen=True)
class SeriesData:
    """One measured series' statistics as :func:`infer` fits them (:func:`data_statistics`).

    Attributes
    ----------
    values, sigma : ndarray
        The statistics of :data:`STATISTICS` and their σ (module docstring: residuals).
    threshold, noise : float
        The detector's threshold and the series' noise level, with which every model trace is read.
    used : ndarray of bool
        Which statistics the series carries (not the cycle frequency where no line stands out of its
        periodogram, nor where it is not stable across the model's replicates).
    """

    values: np.ndarray
    sigma: np.ndarray
    threshold: float
    noise: float
    used: np.ndarray

    def fitted(self, sel: np.ndarray) -> np.ndarray:
        """The indices into :data:`STATISTICS` fitted: those of ``sel`` (the ``statistics`` asked for) the
        series carries, in ``sel``'s order."""
        return sel[self.used[sel]]

    def target(self, sel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(values, σ, mask)`` of :func:`set_statistics`: the mask over :data:`STATISTICS` of the fitted
        statistics."""
        mask = np.zeros(len(STATISTICS), dtype=bool)
        mask[self.fitted(sel)] = True
        return self.values, self.sigma, mask

    def residuals(self, model: np.ndarray | None, sel: np.ndarray, penalty: float) -> np.ndarray:
        """``(model - data) / σ`` over the fitted statistics; ``penalty`` for each where the model does not
        stick-slip (``model`` None)."""
        if model is None:
            return np.full(int(np.count_nonzero(self.used[sel])), penalty)
        return ((model - self.values) / self.sigma)[self.fitted(sel)]


def data_statistics(series: ForceSeries) -> SeriesData:
    """The series' statistics, their σ (module docstring: residuals), the detector's threshold, the noise
    level and which statistics it carries: not the cycle frequency where no line stands out of the periodogram
    below half the slip frequency (a period-1 trace: only drift and noise there)."""
    if series.V is None:
        raise ValueError(f"{series!r} has no pull speed: give ForceSeries(..., V=...) (the model needs V)")
    vals, o, line, threshold = trace_statistics(series, None)
    if vals is None:
        raise ValueError(f"the series at V = {fmt_number(series.V, 4)} m/s does not stick-slip ({o.status}: "
                         f"{o.reason}): there is nothing to fit")
    sig = np.array([REPEATABILITY[n] * abs(v) for n, v in zip(STATISTICS, vals)])
    sig[-1] = max(sig[-1], 0.5 / series.duration)  # at least half a periodogram bin
    if o.period is None:  # an aperiodic trace: its means scatter
        for j, n in enumerate(STATISTICS[:4]):
            spread = getattr(o, f"{n}_spread") or 0.0
            sig[j] = math.hypot(sig[j], spread / math.sqrt(max(o.n_slips - 1, 1)))
    used = np.ones(len(STATISTICS), dtype=bool)
    used[STATISTICS.index("f_cycle")] = line
    return SeriesData(vals, sig, threshold, series.noise, used)


def model_statistics(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float,
                     rtol: float, max_wall: float, **start: Any) -> np.ndarray | None:
    """The statistics of the model's trace at ``p``, sampled at the series' times after ``t_transient`` with
    white noise of the series' level added (a fixed seed), read with the series' threshold; None where it does
    not stick-slip or breaks down.  ``start``: the initial state's keywords of :func:`exact.simulate` (the
    solver's start if none)."""
    return _reading(p, series, threshold, noise, t_transient, rtol, max_wall, start)[0]


def _reading(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float, rtol: float,
             max_wall: float, start: dict[str, Any]) -> tuple[np.ndarray | None, int | None, bool]:
    """:func:`model_statistics`, the return map's period of the model's trace (None: aperiodic or none) and
    whether its periodogram holds a cycle line."""
    return _readings(p, series, threshold, noise, t_transient, rtol, max_wall, start, (NOISE_SEED,))[0]


def _readings(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float, rtol: float,
              max_wall: float, start: dict[str, Any], seeds: tuple[int, ...]
              ) -> list[tuple[np.ndarray | None, int | None, bool]]:
    """:func:`_reading` of one model run with the noise of each of ``seeds`` (one run, read once per seed)."""
    traces = _model_series(p, series, noise, t_transient, rtol, max_wall, start, seeds)
    if traces is None:
        return [(None, None, False)] * len(seeds)
    out: list[tuple[np.ndarray | None, int | None, bool]] = []
    for model in traces:
        vals, o, line, _ = trace_statistics(model, threshold)
        out.append((vals, (o.period if vals is not None else None), line))
    return out


def _model_series(p: PeelParams, series: ForceSeries, noise: float, t_transient: float, rtol: float,
                  max_wall: float, start: dict[str, Any], seeds: tuple[int, ...]) -> list[ForceSeries] | None:
    """The model's trace at ``p`` from ``start``, sampled at the series' times after ``t_transient``, once per
    noise seed of ``seeds`` (one run); None where it breaks down, exceeds ``max_wall`` or the start lies outside
    the model's domain (ValueError)."""
    t_eval = t_transient + (series.t - series.t[0])
    try:
        tr = simulate(p, float(t_eval[-1]), t_eval=t_eval, rtol=rtol, max_wall=max_wall, **start)
    except (ModelBreakdown, SolverBudgetExceeded, ValueError):
        return None
    return [ForceSeries(tr.t, tr.F + np.random.default_rng(seed).normal(0.0, noise, tr.F.size) if noise > 0
                        else tr.F, V=p.V, source="model") for seed in seeds]


def noise_spread(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float,
                 rtol: float, max_wall: float, start: dict[str, Any], n: int = NOISE_REPLICATES
                 ) -> np.ndarray | None:
    """The detector's spread under noise at ``p``: the standard deviation of each statistic over one model run
    (from ``start``) read with ``n`` draws of the series' noise (seeds after :data:`NOISE_SEED`); None where a
    reading does not stick-slip.  The data's statistics and the model's each carry one such draw, so their
    difference has twice its variance.  It is the trace's own repeatability, where :data:`REPEATABILITY` is a
    fixed guess: at the quasi-periodic V = 3.923 m/s, I = 0.01045 (1.5 ms sticks) the mean stick slope moves by
    2.2 % (1.1 σ) from one draw to the next, at the other aperiodic points of ``infer_targets`` (seeds 2-4) by
    0.1-1.5 %."""
    reads = _readings(p, series, threshold, noise, t_transient, rtol, max_wall, start,
                      tuple(NOISE_SEED + 1 + j for j in range(n)))
    if n < 2 or any(r[0] is None for r in reads):
        return None
    return np.array([r[0] for r in reads]).std(axis=0, ddof=1)


@dataclass(frozen=True)
class SetReading:
    """The statistics of the attractor of a trial point's set closest to the data (:func:`set_statistics`)."""

    values: np.ndarray | None
    start: str
    period: int | None
    n_runs: int
    share: float | None = None

    @property
    def label(self) -> str:
        """``"period-n"``, ``"aperiodic"`` or ``"no stick-slip"``."""
        if self.values is None:
            return "no stick-slip"
        return f"period-{self.period}" if self.period else "aperiodic"


def set_statistics(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float,
                   rtol: float, max_wall: float, target: tuple[np.ndarray, np.ndarray, np.ndarray], n_starts: int,
                   *, share: bool = False) -> SetReading:
    """The statistics of the attractor closest to the data among those reached from the first ``n_starts``
    starts of :func:`exact.attractor_set`'s design (``default_starts``: the solver's start, the relaxation foot
    at rest, α0 = -0.3, -0.15, ...), each trace sampled, noised and read as :func:`model_statistics`.

    ``target`` is the data's ``(values, σ, used)``.  Closest: the smallest Σ ((model - data)/σ)² over the used
    statistics; the starts stop at the first whose residuals are all within :data:`CLOSE` σ.  With ``share``
    every start of the design runs, and the share is the fraction of them whose statistics lie within one σ of
    the chosen one's (the same attractor: a periodic orbit's means over the window agree far closer)."""
    vals, sig, used = target
    starts = default_starts(p)
    chosen = starts[: (len(starts) if share else max(1, n_starts))]
    readings: list[tuple[float, str, np.ndarray | None, int | None]] = []
    for st in chosen:
        m, period, _ = _reading(p, series, threshold, noise, t_transient, rtol, max_wall, st.kwargs())
        cost = math.inf if m is None else _chi2(m, (vals, sig, used))
        readings.append((cost, st.name, m, period))
        if not share and m is not None and np.all(np.abs(((m - vals) / sig)[used]) <= CLOSE):
            break
    best = min(readings, key=lambda r: r[0])
    frac = None
    if share:
        if best[2] is None:
            frac = sum(r[2] is None for r in readings) / len(readings)
        else:
            frac = sum(r[2] is not None and bool(np.all(np.abs(((r[2] - best[2]) / sig)[used]) <= 1.0))
                       for r in readings) / len(readings)
    return SetReading(best[2], best[1], best[3], len(readings), frac)


def replicate_spread(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float,
                     rtol: float, max_wall: float, n: int = 4,
                     target: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> Spread:
    """The model's replicate spread at ``p`` for an aperiodic trace (a synthetic likelihood's covariance, Wood
    2010, diagonal): the standard deviation of each statistic over the aperiodic traces reached from the first
    ``n`` starts of :func:`exact.attractor_set`'s design that lie on the data's attractor (each a replicate:
    another phase of the same chaotic or quasi-periodic attractor; :func:`same_attractor`), whether the cycle
    line is stable across them (present in every one, its spread within :data:`REPEATABILITY`) and how many
    replicates were kept (:class:`Spread`).  ``target`` (the data's ``(values, σ, used)``) picks the data's
    attractor: that of the replicate closest to the data (the first without it), whose start ``Spread.start``
    names.  ``sd`` None with fewer than two replicates on it."""
    reads = []
    for st in default_starts(p)[:n]:
        m, period, line = _reading(p, series, threshold, noise, t_transient, rtol, max_wall, st.kwargs())
        if m is not None and period is None:
            reads.append((m, line, st.kwargs()))
    if not reads:
        return Spread(None, False, 0, None)
    ref = reads[0] if target is None else min(
        reads, key=lambda r: _chi2(r[0], target))
    reads = [r for r in reads if same_attractor(r[0], ref[0])]
    if len(reads) < 2:
        return Spread(None, False, len(reads), ref[2])
    arr = np.array([r[0] for r in reads])
    sd = arr.std(axis=0, ddof=1)
    j = STATISTICS.index("f_cycle")
    stable = all(r[1] for r in reads) and sd[j] <= REPEATABILITY["f_cycle"] * abs(float(arr[:, j].mean()))
    return Spread(sd, bool(stable), len(reads), ref[2])


class Spread(NamedTuple):
    """What :func:`replicate_spread` found."""

    sd: np.ndarray | None           #: each statistic's standard deviation over the replicates (None: under two)
    stable: bool                    #: the cycle line in every replicate, its spread within its repeatability
    n: int                          #: the replicates kept (on the data's attractor)
    start: dict[str, Any] | None    #: the start of the replicate closest to the data (None: no aperiodic one)


def _chi2(m: np.ndarray, target: tuple[np.ndarray, np.ndarray, np.ndarray]) -> float:
    """χ² of model statistics ``m`` against ``target`` = the data's ``(values, σ, mask of the fitted ones)``: how
    close a reading is to the data, by which the closest attractor or replicate is picked."""
    values, sigma, used = target
    return float(np.sum((((m - values) / sigma)[used]) ** 2))


def same_attractor(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two readings of :data:`STATISTICS` are of one attractor: the slip interval, force drop and
    slip-start force within :data:`SAME_ATTRACTOR` of each other (relative).  Two starts of one parameter point
    may reach different aperiodic attractors; their spread is not a replicate spread.  At V = 3.149 m/s,
    I = 0.05665, k = 1173 (quasi-periodic) the start at rest reaches a torus whose slip interval is 70 % longer;
    counted as a replicate it multiplied every σ and left I free within a factor 4 (χ² 2.7e-5 on 4 dof)."""
    idx = [STATISTICS.index(n) for n in ("slip_interval", "force_drop", "F_start")]
    return bool(np.all(np.abs(a[idx] - b[idx]) <= SAME_ATTRACTOR * np.abs(b[idx])))


def replicate_mean(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float,
                   rtol: float, max_wall: float, target: tuple[np.ndarray, np.ndarray, np.ndarray], n: int
                   ) -> SetReading:
    """The model's statistics at ``p`` for an aperiodic series as a synthetic likelihood's mean (Wood 2010): the
    mean over the aperiodic traces reached from the first ``n`` starts of :func:`exact.attractor_set`'s design
    on the attractor of the one closest to the data (:func:`same_attractor`; each a replicate: another phase of a
    chaotic or quasi-periodic attractor), read as :func:`model_statistics`.
    A single chaotic window's means move erratically with the parameters (another phase at every point); their
    mean over replicates moves less.  Where no start reaches an aperiodic trace, the reading of those starts
    closest to the data (:func:`set_statistics`' rule); ``n_runs`` is ``n``."""
    vals, sig, used = target
    reads, periodic = [], []
    for st in default_starts(p)[: max(1, n)]:
        m, period, _ = _reading(p, series, threshold, noise, t_transient, rtol, max_wall, st.kwargs())
        if m is not None and period is None:
            reads.append(m)
        else:
            cost = math.inf if m is None else _chi2(m, (vals, sig, used))
            periodic.append((cost, st.name, m, period))
    if reads:  # those on the attractor of the replicate closest to the data (same_attractor)
        ref = min(reads, key=lambda m: _chi2(m, (vals, sig, used)))
        reads = [m for m in reads if same_attractor(m, ref)]
        return SetReading(np.mean(np.array(reads), axis=0), f"mean of {len(reads)} aperiodic replicates", None,
                          max(1, n))
    best = min(periodic, key=lambda r: r[0])
    return SetReading(best[2], best[1], best[3], max(1, n))


def period_tolerance(slips: Any) -> float:
    """The return map's period tolerance :meth:`peelapprox.ForceSeries.observables` uses by default, relative to
    the largest force before a slip (:meth:`peelapprox.Slips.period_tolerance`, its one definition)."""
    return float(slips.period_tolerance())


def data_period(series: ForceSeries) -> tuple[int | None, float]:
    """The series' return-map period as :meth:`peelapprox.ForceSeries.observables` reads it by default (its
    default detector, whose line fits place F before a slip closer than the knee's: at seed 8 trace 2 of
    ``comparisons.benchmark.infer_targets`` the knee's returns jump once by 4.2 N, the line fits' by at most
    0.54 N; None: aperiodic or too few slips) and its period tolerance (:func:`period_tolerance`)."""
    slips = series.slips(None)
    if len(slips) < 2:
        return None, math.nan
    return series.observables(slips=slips).period, period_tolerance(slips)


def model_period(p: PeelParams, series: ForceSeries, threshold: float, noise: float, t_transient: float,
                 rtol: float, max_wall: float, start: dict[str, Any], period_rtol: float
                 ) -> tuple[int | None, int | None]:
    """The return-map period of the model's trace at ``p`` from ``start`` (run, sampled and noised as
    :func:`model_statistics`: the same run and noise draw), read as :func:`data_period` reads the data (the
    default detector at the data's ``threshold``) at its own noise's tolerance, and at ``period_rtol``; None
    where it does not stick-slip, breaks down or is aperiodic at that tolerance."""
    traces = _model_series(p, series, noise, t_transient, rtol, max_wall, start, (NOISE_SEED,))
    if traces is None:
        return None, None
    model = traces[0]
    slips = model.slips(threshold)
    if len(slips) < 2:
        return None, None
    return model.observables(slips=slips).period, model.observables(slips=slips, period_rtol=period_rtol).period


def period_disagreements(data: Sequence[int | None], model: Sequence[int | None],
                         wide: Sequence[int | None | bool], Vs: Sequence[float]) -> tuple[str, ...]:
    """Per series where the data and the fitted attractor are both periodic of clearly different periods, the
    sentence saying so; ``()`` where none is.

    ``data``: the series' periods (:func:`data_period`); ``model``: the best point's attractor's, its trace noised
    like the data and read with the same rule (:func:`model_period`), None where not read; ``wide``: the model
    trace's period at :data:`PERIOD_MARGIN` times the data's tolerance (:func:`model_period`), or False where not
    measured
    (``max_wall`` spent: the disagreement is kept, and the sentence says the margin was not measured).  Clear: p
    and q periodic, q ≠ p, and the wide reading neither p nor a divisor of it.  An aperiodic side is not compared:
    a periodic trace of a long period, or one near the tolerance, can read aperiodic under noise (seed 6 trace 3
    of ``comparisons.benchmark.infer_targets``: data period 6, the fit's reading aperiodic, I within 0.1 %)."""
    if not len(data) == len(model) == len(wide) == len(Vs):
        raise ValueError(f"data, model, wide and Vs must have one entry per series, got {len(data)}, {len(model)}, "
                         f"{len(wide)} and {len(Vs)}")
    out = []
    for p, q, w, V in zip(data, model, wide, Vs):
        if p is None or q is None or p == q or (w is not False and w is not None and p % int(w) == 0):
            continue
        margin = ("its margin not measured (max_wall spent)" if w is False else
                  f"at {fmt_number(PERIOD_MARGIN, 2)} times the data's period tolerance it reads "
                  + (f"period {w}" if w is not None else "aperiodic"))
        out.append(f"at V = {fmt_number(float(V), 4)} m/s the fit's attractor is period {q} where the data's is period "
                   f"{p} ({margin})")
    return tuple(out)
