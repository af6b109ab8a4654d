"""A pull-force trace F(t), measured or simulated, and the model's statistics read off it.

:class:`ForceSeries` holds one trace (times [s], forces [N], optionally the pull speed V) and offers the
statistics the library computes for simulated runs: the slips (:meth:`ForceSeries.slips`, a per-slip table),
the attractor observables (:meth:`ForceSeries.observables`, the :class:`peelapprox.StickSlipObservables` of
the exact side, read off the detected slips by the same :func:`peelapprox._observables.jump_statistics`), the
return map of the force at the slips with its period, and the power spectrum.

**The slip detector** (:func:`detect_slips`).  A slip is a fall of the force, fast against the stick's rise,
by more than a threshold; its start is the force maximum before the fall and its end the minimum after it
(where the exact solution's AB→CD and CD→AB jumps are: ``Ḟ = k(V - v)`` changes sign when v crosses V, which
happens in the jumps).

1. *Noise.*  ``σ`` = 1.4826 · MAD of the second differences / √6: white noise of standard deviation σ gives
   second differences of standard deviation √6 σ, a smooth rise or a slow drift gives ~0, and the slips are
   too few samples to move a median.
2. *Extrema with hysteresis.*  On the force averaged over ``smooth`` samples, a maximum is confirmed when the
   force falls more than ``threshold`` below it, and the following minimum when the force rises more than
   ``threshold`` above it (a zigzag filter).  The default threshold is 12 times the averaged force's noise,
   ``12 σ / √smooth`` (5.4 σ for 5 samples; and at least 1e-9 of the force range): on a flat trace of a million
   samples the averaged noise's running maximum and a later minimum lie ~10 of its σ apart at the extremes, so
   12 confirms no false slip, while a stick that rises by 5.4 σ is seen (at 8 σ of the raw force, sticks rising
   less than 4 N at 0.5 N of noise were missed: 531 of 6271 at V = 2.5, I = 1e-4).  A trend slower than the
   threshold per stick (a drift) moves no extremum past it.
3. *Corners.*  A slip starts at the knee where the stick's slow rise turns into the fast fall, and ends at
   the corner where the fall turns into the next rise: each is the crossing of a straight line fitted to the
   stick (at most ``fit`` samples, from the middle of the stick to ``smooth // 2`` samples before the corner)
   with one fitted to the fall next to it, and F there is the stick line's value.  The knee is not the force
   maximum: where ``v_max > V`` (V = 1 m/s in the paper's law) F peaks on AB, a little before the jump, and
   falls slowly until it.  Noise averages out in the fits (standard error ~2σ/√n) where a raw extremum would
   be biased by it (the largest of n noisy samples), and the crossing is not tied to the sampling grid.

A first slip whose start is the trace's first sample, and a last one without its end, are dropped (their
extrema are the trace's ends, not the stick-slip's).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ._checks import shown
from ._observables import StickSlipObservables, jump_statistics
from .io import fmt_number, jsonable, write_rows
from .validate import integer, optional, positive, reals

if TYPE_CHECKING:
    from ._series_lyapunov import SeriesLyapunov

__all__ = ["ForceSeries", "Slips", "Spectrum", "detect_slips", "noise_level", "MIN_SAMPLES"]

#: The fewest samples a trace may have.
MIN_SAMPLES = 16
#: The largest trace file read [bytes]: 50 s at 20 kHz is ~25 MB of text; 256 MiB is ten million rows.
MAX_TRACE_BYTES = 256 * 1024 * 1024
#: The default threshold in units of the averaged force's noise, σ/√smooth (module docstring, step 2).
THRESHOLD_SIGMAS = 12.0


def noise_level(F: np.ndarray) -> float:
    """The noise's standard deviation σ of a sampled force: 1.4826 · MAD(second differences) / √6 [N]
    (module docstring, step 1); 0 for a noiseless smooth trace."""
    d2 = F[2:] - 2.0 * F[1:-1] + F[:-2]
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return 1.4826 * mad / math.sqrt(6.0)


@dataclass(frozen=True, eq=False)
class Slips:
    """The slips of a force trace, one entry per slip in time order (:meth:`ForceSeries.slips`).

    Attributes
    ----------
    t_start, t_end : ndarray
        Times of the force maximum before the slip and of the minimum after it [s].
    F_before, F_after : ndarray
        The force there [N], from straight-line fits of the sticks on either side (module docstring).
    rise : ndarray
        The slope of the line fitted to the stick before each slip [N/s] (``k(V - v)`` in the model).
    drop : ndarray
        ``F_before - F_after`` [N].
    slip_time : ndarray
        ``t_end - t_start`` [s].
    stick_time : ndarray
        The stick before each slip but the first, ``t_start[k+1] - t_end[k]`` [s] (one fewer entry).
    threshold, noise : float
        The detector's threshold and the noise level σ it was set from [N].
    method : str
        The detector and its settings, in words.
    """

    t_start: np.ndarray
    t_end: np.ndarray
    F_before: np.ndarray
    F_after: np.ndarray
    rise: np.ndarray
    threshold: float
    noise: float
    method: str
    drop: np.ndarray = field(init=False)
    slip_time: np.ndarray = field(init=False)
    stick_time: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "drop", self.F_before - self.F_after)
        object.__setattr__(self, "slip_time", self.t_end - self.t_start)
        object.__setattr__(self, "stick_time", self.t_start[1:] - self.t_end[:-1])

    def __len__(self) -> int:
        return int(self.t_start.size)

    def __repr__(self) -> str:
        mean = (f", mean drop {fmt_number(float(self.drop.mean()), 4)} N" if len(self) else "")
        return (f"Slips({len(self)} slips{mean}, threshold {fmt_number(self.threshold, 3)} N, "
                f"noise {fmt_number(self.noise, 3)} N)")

    def as_rows(self) -> list[dict[str, Any]]:
        """One row per slip: ``t_start, t_end, F_before, F_after, drop, slip_time, stick_before`` (None for the
        first slip's stick)."""
        return [{"t_start": float(self.t_start[k]), "t_end": float(self.t_end[k]),
                 "F_before": float(self.F_before[k]), "F_after": float(self.F_after[k]),
                 "drop": float(self.drop[k]), "slip_time": float(self.slip_time[k]), "rise": float(self.rise[k]),
                 "stick_before": None if k == 0 else float(self.stick_time[k - 1])} for k in range(len(self))]

    def write(self, path: str) -> None:
        """Write :meth:`as_rows` as CSV or JSON by the file's extension (:func:`peelapprox.io.write_rows`)."""
        write_rows(path, self.as_rows())

    def jumps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The slips as a jump record: times, forces and branches left (0 at a slip's start, the AB→CD jump; 1
        at its end), alternating, as :func:`peelapprox._observables.jump_statistics` reads it."""
        n = len(self)
        t = np.empty(2 * n)
        F = np.empty(2 * n)
        t[0::2], t[1::2] = self.t_start, self.t_end
        F[0::2], F[1::2] = self.F_before, self.F_after
        return t, F, np.tile(np.array([0, 1]), n)


@dataclass(frozen=True, eq=False)
class Spectrum:
    """The power spectral density of a force trace (:meth:`ForceSeries.spectrum`, Welch's method).

    Attributes
    ----------
    frequency : ndarray
        [Hz], from 0 to the Nyquist frequency.
    power : ndarray
        [N² / Hz], one-sided.
    peak : float
        The frequency of the largest power above the lowest non-zero bin [Hz].
    """

    frequency: np.ndarray
    power: np.ndarray
    peak: float

    def as_rows(self) -> list[dict[str, float]]:
        """One row per frequency: ``frequency, power``."""
        return [{"frequency": float(f), "power": float(p)} for f, p in zip(self.frequency, self.power)]


def _zigzag(F: np.ndarray, h: float) -> tuple[list[int], list[int]]:
    """Indices of the confirmed maxima and of the minima after them (module docstring, step 2), alternating,
    a maximum first; a trailing maximum without its minimum is left out."""
    peaks: list[int] = []
    valleys: list[int] = []
    up = True
    ext = 0
    x = F.tolist()  # a Python loop over floats: ~0.3 s per million samples
    for i in range(1, len(x)):
        xi = x[i]
        if up:
            if xi > x[ext]:
                ext = i
            elif x[ext] - xi > h:
                peaks.append(ext)
                up, ext = False, i
        elif xi < x[ext]:
            ext = i
        elif xi - x[ext] > h:
            valleys.append(ext)
            up, ext = True, i
    return peaks[:len(valleys)], valleys


def _line(t: np.ndarray, F: np.ndarray, lo: int, hi: int, min_n: int) -> tuple[float, float, float] | None:
    """``(slope, value at t0, t0)`` of the straight line fitted to ``F[lo:hi]`` (t0 the segment's first time),
    or None for fewer than ``min_n`` samples."""
    if hi - lo < min_n:
        return None
    t0 = float(t[lo])
    slope, icept = np.polyfit(t[lo:hi] - t0, F[lo:hi], 1)
    return float(slope), float(icept), t0


def _corner(t: np.ndarray, F: np.ndarray, stick: tuple[int, int], fall: tuple[int, int], near: int,
            window: tuple[int, int]) -> tuple[float, float, float]:
    """Where the line fitted to the stick meets the line fitted to the slip's fall: ``(time, F of the stick
    line there, the stick line's slope)``, the time kept within ``t[window]``; at ``t[near]`` (slope 0) where
    the stick has too few samples for a line."""
    s = _line(t, F, *stick, min_n=3)
    f = _line(t, F, *fall, min_n=2)
    lo_t, hi_t = float(t[window[0]]), float(t[window[1]])
    if s is None:
        return float(t[near]), float(F[near]), 0.0
    tc = float(t[near])
    if f is not None and f[0] != s[0]:
        # s0 (t - ts) + s1 = f0 (t - tf) + f1
        tc = (f[1] - s[1] - f[0] * f[2] + s[0] * s[2]) / (s[0] - f[0])
        tc = min(max(tc, lo_t), hi_t)
    return tc, s[1] + s[0] * (tc - s[2]), s[0]


def detect_slips(t: np.ndarray, F: np.ndarray, *, threshold: float | None = None, smooth: int = 5,
                 fit: int = 40) -> Slips:
    """The slips of a sampled force (module docstring: noise, extrema with hysteresis, values).

    Parameters
    ----------
    t, F : ndarray
        Times [s] (increasing) and forces [N], checked by :class:`ForceSeries`.
    threshold : float, optional
        The fall [N] that confirms a slip (and the rise that ends it); None: ``12 σ / √smooth``
        (:data:`THRESHOLD_SIGMAS`).
    smooth : int
        Samples of the moving average the extrema are searched on (odd, 1 to 101; 5).
    fit : int
        At most this many samples of each stick in the line fits (3 to 10**5; 40).

    Returns
    -------
    Slips
    """
    sigma = noise_level(F)
    span = float(F.max() - F.min())
    h = max(THRESHOLD_SIGMAS * sigma / math.sqrt(smooth), 1e-9 * span) if threshold is None else threshold
    Fs = F if smooth == 1 else np.convolve(F, np.ones(smooth) / smooth, mode="same")
    half = smooth // 2
    if half:  # the ends of a 'same' convolution are averages over fewer samples: keep the raw force there
        Fs[:half], Fs[-half:] = F[:half], F[-half:]
    peaks, valleys = _zigzag(Fs, h)
    if peaks and peaks[0] == 0:
        peaks, valleys = peaks[1:], valleys[1:]
    n = len(peaks)
    ts, te, fb, fa, rise = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    last = len(F) - 1
    for k in range(n):
        p, v = peaks[k], valleys[k]
        before = valleys[k - 1] if k else 0  # the stick before runs from the previous slip's end
        after = peaks[k + 1] if k + 1 < n else last  # the stick after runs to the next slip's start
        # the knee: walking back from the steepest fall, the first sample at least half as steep as the slip's
        # mean fall (from the maximum forwards, noise on a flat stick could pass for it)
        mean_fall = (Fs[v] - Fs[p]) / (t[v] - t[p])
        g = np.gradient(Fs[p:v + 1], t[p:v + 1]) if v > p else np.zeros(1)
        steep = int(np.argmin(g))
        flat = np.flatnonzero(g[:steep] >= 0.5 * mean_fall)
        knee = p + (int(flat[-1]) + 1 if flat.size else 0)
        L = max(2, min(fit, (v - knee) // 3))
        lo = max(before + (knee - before) // 2, knee - half - fit)
        ts[k], fb[k], rise[k] = _corner(t, F, (lo, knee - half), (knee + half, min(knee + half + L, v - half)), knee,
                               (max(p - half - 1, 0), min(knee + half + 1, last)))
        hi = min(v + (after - v) // 2, v + half + 1 + fit)
        te[k], fa[k], _ = _corner(t, F, (v + half + 1, hi), (max(knee + half, v - half - L), v - half), v,
                               (max(v - half - 1, 0), min(v + half + 1, last)))
    method = (f"slips: falls of the {smooth}-sample moving average by more than {fmt_number(h, 3)} N "
              + (f"(12 sigma/sqrt({smooth}), sigma = {fmt_number(sigma, 3)} N from the second differences)"
                 if threshold is None
                 else "(given)")
              + f", F before and after from line fits of up to {fit} stick samples")
    return Slips(t_start=ts, t_end=te, F_before=fb, F_after=fa, rise=rise, threshold=float(h), noise=sigma,
                 method=method)


class ForceSeries:
    """A pull-force trace F(t) [N] at times t [s], measured or sampled from a run, and its statistics.

    ``ForceSeries(t, F, *, V=None, source="measured")``: t increasing and finite, F finite, one length, at
    least :data:`MIN_SAMPLES` samples; V the pull speed [m/s] if known (it labels the observables).

    Raises
    ------
    ValueError
        Naming the argument and the first offending sample: NaN or inf, non-increasing time, different
        lengths, too few samples, V not positive.
    """

    def __init__(self, t: ArrayLike, F: ArrayLike, *, V: float | None = None, source: str = "measured"):
        t_arr, F_arr = _samples("t", t), _samples("F", F)
        if t_arr.size != F_arr.size:
            raise ValueError(f"t and F must have one length, got {t_arr.size} and {F_arr.size} samples")
        if t_arr.size < MIN_SAMPLES:
            raise ValueError(f"a force series needs at least {MIN_SAMPLES} samples, got {t_arr.size}")
        dt = np.diff(t_arr)
        bad = np.flatnonzero(dt <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise ValueError(f"t must increase: t[{i}] = {fmt_number(float(t_arr[i]), 6)} s does not exceed "
                             f"t[{i - 1}] = {fmt_number(float(t_arr[i - 1]), 6)} s")
        self.t: np.ndarray = t_arr
        self.F: np.ndarray = F_arr
        self.V: float | None = optional(positive, "V", V)
        self.source = str(source)
        self.t.setflags(write=False)
        self.F.setflags(write=False)

    def __len__(self) -> int:
        return int(self.t.size)

    def __repr__(self) -> str:
        V = "" if self.V is None else f", V = {fmt_number(self.V, 4)} m/s"
        return (f"ForceSeries({len(self)} samples over {fmt_number(self.duration, 4)} s at "
                f"{fmt_number(self.rate, 4)} Hz{V}, {self.source})")

    @classmethod
    def from_csv(cls, path: str, *, columns: tuple[str, str] = ("t", "F"), V: float | None = None,
                 delimiter: str | None = None, units: dict[str, str] | None = None) -> ForceSeries:
        """A trace read from a CSV file: a header naming the time and force columns (``columns``), then one
        sample per row; other columns are ignored.

        Units in the header (``t [ms], F [kN]``; :data:`peelapprox._csvread.UNITS`: s, ms, us, min; N, mN, cN,
        kN) are converted to s and N, or stated with ``units={"t": "ms"}`` where the header gives none (none:
        s and N).  The file is read by the package's one CSV reader (a regular UTF-8 file of at most 256 MiB,
        ``#`` comments), which never executes anything.

        Raises
        ------
        ValueError
            Naming the file and, for a cell, its line and column (a missing column, an unknown unit, a cell
            that is not a number); or the trace's own checks with the file line of the offending sample.
        """
        from ._csvread import read_columns

        if not (isinstance(columns, tuple) and len(columns) == 2 and all(isinstance(c, str) for c in columns)):
            raise TypeError(f"columns must be a pair of column names (time, force), got {columns!r}")
        where = f"ForceSeries.from_csv({shown(str(path))})"
        tc, fc = columns
        data = read_columns(str(path), {tc: "s", fc: "N"}, where=where, delimiter=delimiter,
                            max_bytes=MAX_TRACE_BYTES, stated=units)
        try:
            return cls(data[tc], data[fc], V=V, source=f"measured: {path}")
        except ValueError as exc:
            import re

            m = re.search(r"\[(\d+)\]", str(exc))  # the sample the trace's check names
            i = int(m.group(1)) if m else -1
            line = f" (file line {int(data['line'][i])})" if 0 <= i < data["line"].size else ""
            raise ValueError(f"{where}: {exc}{line}") from None

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]`` [s]."""
        return float(self.t[-1] - self.t[0])

    @property
    def rate(self) -> float:
        """The sampling rate, 1 / the median time step [Hz]."""
        return 1.0 / float(np.median(np.diff(self.t)))

    @property
    def noise(self) -> float:
        """The noise level σ [N] (:func:`noise_level`)."""
        return noise_level(self.F)

    def slips(self, threshold: float | None = None, *, smooth: int = 5, fit: int = 40) -> Slips:
        """The slips, one table row each (:func:`detect_slips`; its parameters)."""
        threshold = optional(positive, "threshold", threshold)
        smooth = integer("smooth", smooth, lo=1, hi=101)
        if smooth % 2 == 0:
            raise ValueError(f"smooth must be odd (a centred average), got {smooth}")
        fit = integer("fit", fit, lo=3, hi=10**5)
        return detect_slips(self.t, self.F, threshold=threshold, smooth=smooth, fit=fit)

    def observables(self, threshold: float | None = None, *, period_rtol: float | None = None,
                    max_period: int = 32) -> StickSlipObservables:
        """The attractor observables of the trace, read off its slips by the exact side's definitions.

        Parameters
        ----------
        threshold : float, optional
            Of :meth:`slips`.
        period_rtol : float, optional
            The return map's period tolerance (:func:`peelapprox.periodicity`), relative to the largest F
            before a slip; None: the detector's repeatability, the largest of 6 fit errors (``6 · 2σ/√fit``),
            2 % of the range of F before the slips and 3e-4 of the largest (on noiseless model traces sampled
            at 10 kHz the corners repeat to ~0.03 N of 300 N, 1e-4).
        max_period : int
            Largest period tried (1 to 64; 32).

        Returns
        -------
        StickSlipObservables
            ``status`` "stick-slip" with at least two slips, "too few slips" with one, "steady" with none;
            ``method`` names the detector and its threshold; ``I`` None (a trace does not know it).
        """
        s = self.slips(threshold)
        max_period = integer("max_period", max_period, lo=1, hi=64)
        common: dict[str, Any] = dict(V=self.V, I=None, t_start=float(self.t[0]), t_end=float(self.t[-1]))
        if len(s) == 0:
            return StickSlipObservables._no_slip(
                status="steady", method=s.method, **common,
                reason=f"no fall of the force by more than {fmt_number(s.threshold, 3)} N in the trace")
        tj, Fj, bj = s.jumps()
        top = float(np.max(np.abs(s.F_before)))
        spread = float(np.ptp(s.F_before))
        rtol = (max(6.0 * 2.0 * s.noise / math.sqrt(40.0), 0.02 * spread, 3e-4 * top) / top if period_rtol is None
                else positive("period_rtol", period_rtol))
        stats, cycles = jump_statistics(tj, Fj, bj, period_rtol=rtol, max_period=max_period)
        status = "stick-slip" if len(s) >= 2 else "too few slips"
        reason = (f"{len(s)} slips in the trace, return map {stats['period_label']} (period tolerance "
                  f"{fmt_number(rtol, 2)})" + (f"; means over the last {cycles} whole cycles" if cycles else ""))
        return StickSlipObservables(status=status, reason=reason, method=f"{self.source}: {s.method}", **stats,
                                    **common)

    def return_map(self, threshold: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(F_n, F_n+1)``: the force before each slip against the next one's [N] (the exact side's return map
        ``x_k``)."""
        fb = self.slips(threshold).F_before
        return fb[:-1], fb[1:]

    def spectrum(self, *, segment: float | None = None, detrend: str = "linear") -> Spectrum:
        """The power spectral density by Welch's method (:func:`scipy.signal.welch`) on the uniformly resampled
        trace.

        Parameters
        ----------
        segment : float, optional
            Length of Welch's segments [s]; None: an eighth of the trace.
        detrend : {"linear", "constant"}
            What each segment loses before its transform (a slow drift: "linear").
        """
        from scipy.signal import welch

        if detrend not in ("linear", "constant"):
            raise ValueError(f"detrend must be 'linear' or 'constant', got {detrend!r}")
        rate = self.rate
        seg = self.duration / 8.0 if segment is None else positive("segment", segment)
        n = len(self)
        tu = np.linspace(self.t[0], self.t[-1], n)
        Fu = np.interp(tu, self.t, self.F)
        nper = int(min(n, max(16, round(seg * rate))))
        f, p = welch(Fu, fs=(n - 1) / self.duration, nperseg=nper, detrend=detrend)
        peak = float(f[1 + int(np.argmax(p[1:]))]) if f.size > 1 else 0.0
        return Spectrum(frequency=f, power=p, peak=peak)

    def lyapunov(self, *, embed: str = "returns", dimension: int | None = None, delay: int | None = None,
                 theiler: int | None = None, horizon: int | None = None, neighbours: int = 1,
                 references: int = 4000, fit: tuple[float, float] = (0.1, 0.6),
                 fit_range: tuple[int, int] | None = None, surrogates: int = 19, alpha: float = 0.05,
                 threshold: float | None = None, seed: int | None = 0, max_wall: float = 300.0,
                 progress: Callable[[int, int], Any] | None = None) -> SeriesLyapunov:
        """The largest Lyapunov exponent from the trace, by delay embedding and the divergence of nearest
        neighbours (Rosenstein et al. 1993, Kantz 1994), with a surrogate-data test
        (:mod:`peelapprox._series_lyapunov`).

        Parameters
        ----------
        embed : {"returns", "trace"}
            What is embedded: the force before each slip, one step per return (default; the measured choice),
            or the uniformly resampled trace F(t), one step per sample.
        dimension, delay : int, optional
            Embedding dimension (1 to 20) and delay [steps].  None: 4 and 1 for returns; 5 and an eighth of
            the mean slip interval for the trace.
        theiler : int, optional
            Neighbours closer in time than this many steps are not paired.  None: ``dimension * delay``
            (returns), one mean slip interval (trace).
        horizon : int, optional
            Steps each pair is followed.  None: a quarter of the slips, at most 400 slip intervals.
        neighbours : int
            Nearest neighbours whose mean distance is followed per reference point (1: Rosenstein; more:
            Kantz's average; 1 to 50).
        references : int
            Reference points, evenly spread over the series (20 to 10**6; 4000).
        fit : (float, float)
            The fit range, as fractions of the curve's rise from its start to the attractor's size (the mean
            ln distance of random pairs); ``(0.1, 0.6)``.
        fit_range : (int, int), optional
            The fit range in steps, instead of ``fit``.
        surrogates : int
            IAAFT surrogates for the test (0: no test; 19 for a one-sided test at 5 %).
        alpha : float
            The test's level (0.05).
        threshold : float, optional
            Of :meth:`slips`.
        seed : int or None
            Of the surrogates' and the saturation level's random numbers (0).
        max_wall : float
            Wall-time budget [s] (300).  Surrogates not made by then are left out and ``status`` says so; a
            budget spent before the data's own curve raises ``TimeoutError``.
        progress : callable, optional
            Called as ``progress(done, total)`` after each surrogate.

        Returns
        -------
        SeriesLyapunov
            λ [bits/s] with its standard error, the divergence curve, the fit range, the embedding and the
            surrogate test.  A periodic trace gives λ ≈ 0 and a test that does not reject: its surrogates
            are nearly periodic too (a line spectrum with new phases), so the test finds nothing beyond a
            linear process; "periodic" is read off λ ≈ 0 and the return map's period, not off the test.
            Noise: the detector misses slips whose stick rises less than its threshold (5.4 σ by default),
            which scrambles the returns; give ``threshold`` below the smallest drop where sticks are that
            short (docs/dynamics.md).  A λ the surrogates do not reject is no evidence of chaos.

        Raises
        ------
        ValueError
            Naming the argument: fewer than 3 slips, a series too short for the horizon, embedding and
            Theiler window, parameters out of range.
        """
        from ._series_lyapunov import series_lyapunov

        return series_lyapunov(self, embed=embed, dimension=dimension, delay=delay, theiler=theiler,
                               horizon=horizon, neighbours=neighbours, references=references, fit=fit,
                               fit_range=fit_range, surrogates=surrogates, alpha=alpha, threshold=threshold,
                               seed=seed, max_wall=max_wall, progress=progress)

    def plot(self, ax: Any = None, *, window: tuple[float, float] | None = None, threshold: float | None = None):
        """The trace F(t) with its detected slips marked (start ▼, end ▲, at the fitted corners).

        Parameters
        ----------
        ax : matplotlib axes, optional
            Draw there; None: new axes from :func:`peelapprox.plotting.pyplot`.
        window : (float, float), optional
            The time span shown [s]; None: the whole trace.
        threshold : float, optional
            Of :meth:`slips`.

        Returns
        -------
        matplotlib axes
        """
        lo, hi = (self.t[0], self.t[-1]) if window is None else (float(window[0]), float(window[1]))
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ValueError(f"window must be (t_start, t_end) with t_start < t_end, got {window!r}")
        if ax is None:
            from .plotting import pyplot

            _, ax = pyplot().subplots(figsize=(9, 4))
        s = self.slips(threshold)
        m = (self.t >= lo) & (self.t <= hi)
        ax.plot(self.t[m], self.F[m], lw=0.7, color="C0", label="F(t)")
        a = (s.t_start >= lo) & (s.t_start <= hi)
        b = (s.t_end >= lo) & (s.t_end <= hi)
        ax.plot(s.t_start[a], s.F_before[a], "v", ms=4, color="C3", label=f"slip start ({len(s)} slips)")
        ax.plot(s.t_end[b], s.F_after[b], "^", ms=4, color="C2", label="slip end")
        ax.set(xlabel="t [s]", ylabel="F [N]", xlim=(lo, hi))
        ax.set_title(f"{self._label()}; threshold {fmt_number(s.threshold, 3)} N", fontsize=8)
        ax.legend(loc="best", fontsize=8)
        return ax

    def plot_return_map(self, ax: Any = None, *, threshold: float | None = None):
        """The return map of the force before the slips, F_n+1 against F_n, with the diagonal.

        Parameters
        ----------
        ax : matplotlib axes, optional
            Draw there; None: new axes from :func:`peelapprox.plotting.pyplot`.
        threshold : float, optional
            Of :meth:`slips`.

        Returns
        -------
        matplotlib axes
        """
        if ax is None:
            from .plotting import pyplot

            _, ax = pyplot().subplots(figsize=(5, 5))
        x, y = self.return_map(threshold)
        ax.plot(x, y, ".", ms=3, color="C0", label=f"{x.size} returns")
        if x.size:
            lo, hi = float(min(x.min(), y.min())), float(max(x.max(), y.max()))
            ax.plot([lo, hi], [lo, hi], lw=0.8, color="0.5", label="F_n+1 = F_n")
        ax.set(xlabel="$F_n$ before slip n [N]", ylabel="$F_{n+1}$ [N]")
        ax.set_title(f"return map: {self._label()}", fontsize=8)
        ax.legend(loc="best", fontsize=8)
        return ax

    def _label(self) -> str:
        """The pull speed and the source, for a title (wrapped at 70 characters)."""
        import textwrap

        return textwrap.fill(("" if self.V is None else f"V = {fmt_number(self.V, 4)} m/s, ") + self.source, 70)

    def as_rows(self) -> list[dict[str, float]]:
        """One row per sample: ``t, F``."""
        return [{"t": float(a), "F": float(b)} for a, b in zip(self.t, self.F)]

    def as_dict(self) -> dict[str, Any]:
        """The trace as plain JSON data."""
        return {"t": jsonable(self.t), "F": jsonable(self.F), "V": self.V, "source": self.source}


def _samples(name: str, x: ArrayLike) -> np.ndarray:
    """``x`` as a 1-D float array of finite samples (:func:`peelapprox.validate.reals` names the first that is
    not)."""
    a = reals(name, x)
    if a.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {a.shape}")
    return np.array(a, dtype=float)
