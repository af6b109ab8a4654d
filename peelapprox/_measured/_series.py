"""A pull-force trace F(t), measured or simulated, and the model's statistics read off it.

:class:`ForceSeries` holds one trace (times [s], forces [N], optionally the pull speed V) and offers the
statistics the library computes for simulated runs: the slips (:meth:`ForceSeries.slips`, a per-slip table),
the attractor observables (:meth:`ForceSeries.observables`, the :class:`peelapprox.StickSlipObservables` of
the exact side, read off the detected slips by the same :func:`peelapprox._observables.jump_statistics`), the
return map of the force at the slips with its period, and the power spectrum.

The slips are found by :func:`peelapprox._slips.detect_slips` (its module docstring: the detector).
"""

from __future__ import annotations

import math
from collections.abc import Sized
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._checks import shown
from .._observables import StickSlipObservables, jump_statistics
from .._ranges import TIME_MAX
from .._slips import Slips, detect_slips, noise_level
from ..io import fmt_number, jsonable
from ..validate import integer, optional, positive, reals
from ._series_lyapunov import options_signature, series_lyapunov

if TYPE_CHECKING:
    from ._series_lyapunov import SeriesLyapunov

__all__ = ["ForceSeries", "Spectrum", "MAX_FORCE", "MAX_SAMPLES", "MIN_SAMPLES", "MIN_STEP"]

#: The fewest samples a trace may have.
MIN_SAMPLES = 16
#: The largest trace file read [bytes]: 50 s at 20 kHz is ~25 MB of text; 256 MiB is ten million rows.
MAX_TRACE_BYTES = 256 * 1024 * 1024
#: The most samples a trace may have: ten million (the rows a file of :data:`MAX_TRACE_BYTES` holds at ~25 bytes a
#: row).  Memory is linear in the samples: a trace is 16 bytes a sample, :meth:`ForceSeries.observables` adds
#: ~40 (measured, tests/test_bounded.py), ``exact.infer`` took ~110 in all (a probe: 11 GB on 1e8 samples), so a
#: call on a trace at the limit stays near 1 GB (docs/your-data.md).
MAX_SAMPLES = 10_000_000
#: The largest |F| of a trace [N]: five decades beyond the pull forces the solvers are built for
#: (``STATE_RANGES["F"]`` up to 1e7 N), so that a trace's squares and sums (its power spectrum, variance) stay
#: far from the float range (|F| = 1e200 overflowed the spectrum); a trace beyond is not in newtons.
MAX_FORCE = 1e12
#: A trace whose detrended fluctuations are below this fraction of its largest |F| is flat: no spectral peak
#: (rounding of a float64 force is ~1e-16 of it; a measured trace's noise is > 1e-6).
FLAT_RTOL = 1e-9
#: The shortest time step between two samples [s]: a picosecond, a sampling rate of 1 THz; below it (a trace whose
#: times were written in the wrong unit, ``1e-300 * arange(n)``) the statistics' fits are singular.
MIN_STEP = 1e-12
#: The longest trace [s]: :data:`peelapprox._ranges.TIME_MAX`, the longest run the model simulates.
MAX_DURATION = TIME_MAX


@dataclass(frozen=True, eq=False)
class Spectrum:
    """The power spectral density of a force trace (:meth:`ForceSeries.spectrum`, Welch's method).

    Attributes
    ----------
    frequency : ndarray
        [Hz], from 0 to the Nyquist frequency.
    power : ndarray
        [N² / Hz], one-sided.
    peak : float or None
        The frequency of the largest power above the lowest non-zero bin [Hz]; None when the trace is flat
        (its power above the lowest bin, integrated, is that of fluctuations below :data:`FLAT_RTOL` times its
        largest ``|F|``: rounding, not a signal, whose largest bin falls at an arbitrary frequency).
    """

    frequency: np.ndarray
    power: np.ndarray
    peak: float | None

    def as_rows(self) -> list[dict[str, float]]:
        """One row per frequency: ``frequency, power``."""
        return [{"frequency": float(f), "power": float(p)} for f, p in zip(self.frequency, self.power)]


class ForceSeries:
    """A pull-force trace F(t) [N] at times t [s], measured or sampled from a run, and its statistics.

    ``ForceSeries(t, F, *, V=None, source="measured")``: t increasing and finite, F finite with ``|F|`` at most
    :data:`MAX_FORCE` (1e12 N), one length, at least :data:`MIN_SAMPLES` samples; V the pull speed [m/s] if known
    (it labels the observables).

    Raises
    ------
    ValueError
        Naming the argument and the first offending sample: NaN or inf, ``|F|`` beyond MAX_FORCE, non-increasing
        time, different lengths, too few samples, V not positive.
    """

    def __init__(self, t: ArrayLike, F: ArrayLike, *, V: float | None = None, source: str = "measured"):
        t_arr, F_arr = _samples("t", t), _samples("F", F)
        if t_arr.size != F_arr.size:
            raise ValueError(f"t and F must have one length, got {t_arr.size} and {F_arr.size} samples")
        if t_arr.size < MIN_SAMPLES:
            raise ValueError(f"a force series needs at least {MIN_SAMPLES} samples, got {t_arr.size}")
        big = np.flatnonzero(np.abs(F_arr) > MAX_FORCE)
        if big.size:
            i = int(big[0])
            raise _SampleError(i, f"F[{i}] = {float(F_arr[i]):.6g} N: |F| must be at most MAX_FORCE = {MAX_FORCE:g} N "
                                  "(is the force in newtons?)")
        dt = np.diff(t_arr)
        bad = np.flatnonzero(dt <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise _SampleError(i, f"t must increase: t[{i}] = {fmt_number(float(t_arr[i]), 6)} s does not exceed "
                                  f"t[{i - 1}] = {fmt_number(float(t_arr[i - 1]), 6)} s")
        short = np.flatnonzero(dt < MIN_STEP)
        if short.size:
            i = int(short[0]) + 1
            raise _SampleError(i, f"t must step by at least {MIN_STEP:g} s (a sampling rate of at most 1 THz; are "
                                  f"the times in seconds?): t[{i}] - t[{i - 1}] = {float(dt[i - 1]):.3g} s")
        if t_arr[-1] - t_arr[0] > MAX_DURATION:
            raise ValueError(f"t must span at most {MAX_DURATION:g} s (are the times in seconds?), got "
                             f"{float(t_arr[-1] - t_arr[0]):.6g} s")
        self.t: np.ndarray = t_arr
        self.F: np.ndarray = F_arr
        self.V: float | None = optional(positive, "V", V)
        self.source = str(source)
        self.t.setflags(write=False)
        self.F.setflags(write=False)
        self._slips: dict[tuple, Slips] = {}  # slips() by its arguments: the trace is read-only

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
        from .._csvread import read_columns

        if not (isinstance(columns, tuple) and len(columns) == 2 and all(isinstance(c, str) for c in columns)):
            raise TypeError(f"columns must be a pair of column names (time, force), got {columns!r}")
        where = f"ForceSeries.from_csv({shown(str(path))})"
        tc, fc = columns
        data = read_columns(str(path), {tc: "s", fc: "N"}, where=where, delimiter=delimiter,
                            max_bytes=MAX_TRACE_BYTES, stated=units, max_rows=MAX_SAMPLES)
        try:
            return cls(data[tc], data[fc], V=V, source=f"measured: {path}")
        except _SampleError as exc:  # the sample the trace's check names, as a line of the file
            raise ValueError(f"{where}: {exc} (file line {int(data['line'][exc.index])})") from None
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None

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

    def slips(self, threshold: float | None = None, *, smooth: int = 5, fit: int = 40,
              method: str = "lines") -> Slips:
        """The slips, one table row each (:func:`detect_slips`; its parameters: ``method="lines"``, the
        three-piece line fit, or ``"knee"``, the earlier method that :func:`exact.infer` reads traces with)."""
        threshold = optional(positive, "threshold", threshold)
        smooth = integer("smooth", smooth, lo=1, hi=101)
        if smooth % 2 == 0:
            raise ValueError(f"smooth must be odd (a centred average), got {smooth}")
        fit = integer("fit", fit, lo=3, hi=10**5)
        if method not in ("lines", "knee"):
            raise ValueError(f"method must be 'lines' or 'knee', got {method!r}")
        key = (threshold, smooth, fit, method)
        if key not in self._slips:  # found once per trace and arguments (observables, spectrum, lyapunov all read them)
            found = detect_slips(self.t, self.F, threshold=threshold, smooth=smooth, fit=fit, method=method)
            for value in vars(found).values():
                if isinstance(value, np.ndarray):
                    value.setflags(write=False)  # shared by every caller: read-only, as the trace is
            self._slips[key] = found
        return self._slips[key]

    def observables(self, threshold: float | None = None, *, period_rtol: float | None = None,
                    max_period: int = 32, slips: Slips | None = None) -> StickSlipObservables:
        """The attractor observables of the trace, read off its slips by the exact side's definitions.

        Parameters
        ----------
        threshold : float, optional
            Of :meth:`slips`.
        period_rtol : float, optional
            The return map's period tolerance (:func:`peelapprox.periodicity`), relative to the largest F
            before a slip; None: :meth:`Slips.period_tolerance` (the detector's repeatability).
        max_period : int
            Largest period tried (1 to 64; 32).
        slips : Slips, optional
            This trace's :meth:`slips` when already found (``threshold`` is then theirs): not detected again.

        Returns
        -------
        StickSlipObservables
            ``status`` "stick-slip" with at least two slips, "too few slips" with one, "steady" with none;
            ``method`` names the detector and its threshold; ``I`` None (a trace does not know it).
        """
        if slips is not None and not isinstance(slips, Slips):
            raise TypeError(f"slips must be this trace's Slips (ForceSeries.slips()), got {type(slips).__name__}")
        s = self.slips(threshold) if slips is None else slips
        max_period = integer("max_period", max_period, lo=1, hi=64)
        common: dict[str, Any] = dict(V=self.V, I=None, t_start=float(self.t[0]), t_end=float(self.t[-1]))
        if len(s) == 0:
            return StickSlipObservables._no_slip(
                status="steady", method=s.method, **common,
                reason=f"no fall of the force by more than {fmt_number(s.threshold, 3)} N in the trace")
        tj, Fj, bj = s.jumps()
        rtol = s.period_tolerance() if period_rtol is None else positive("period_rtol", period_rtol)
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
        # a trace flat to rounding (fluctuations below FLAT_RTOL of its size after detrending) has no peak: the
        # largest of its rounding noise is at an arbitrary frequency
        scale = float(np.max(np.abs(Fu)))
        flat = f.size < 2 or float(np.sum(p[1:])) * float(f[1] - f[0]) <= (FLAT_RTOL * scale) ** 2
        peak = None if flat else float(f[1 + int(np.argmax(p[1:]))])
        return Spectrum(frequency=f, power=p, peak=peak)

    @options_signature
    def lyapunov(self, **options: Any) -> SeriesLyapunov:
        """The largest Lyapunov exponent from the trace, by delay embedding and the divergence of nearest
        neighbours (Rosenstein et al. 1993, Kantz 1994), with a surrogate-data test
        (:mod:`peelapprox._measured._series_lyapunov`).  The options are keyword-only; the signature is built from their
        one
        definition, the fields of ``LyapunovOptions`` (``peelapprox/_measured/_series_lyapunov.py``), and an unknown
        option
        is a ``TypeError`` naming it.

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
        return series_lyapunov(self, **options)

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
            from ..plotting import pyplot

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
            from ..plotting import pyplot

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

    def to_csv(self, path: str) -> None:
        """Write the trace as CSV, the header ``t [s],F [N]`` then one sample a row (17 significant digits: it
        reads back bitwise with :meth:`from_csv`)."""
        import os

        with open(os.fspath(path), "w", encoding="utf-8", newline="") as fh:
            fh.write("t [s],F [N]\n")
            np.savetxt(fh, np.column_stack([self.t, self.F]), fmt="%.17g", delimiter=",")

    def to_dataframe(self) -> Any:
        """The trace as a :class:`pandas.DataFrame`, columns ``t`` [s] and ``F`` [N] (``df.attrs["units"]``,
        ``df.attrs["V"]``, ``df.attrs["source"]``).

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        from ..io import optional_import

        pd = optional_import("pandas", "ForceSeries.to_dataframe")
        df = pd.DataFrame({"t": np.array(self.t), "F": np.array(self.F)})
        df.attrs.update(units={"t": "s", "F": "N"}, V=self.V, source=self.source)
        return df


class _SampleError(ValueError):
    """A bad sample of a trace, with its index (so a file reader can name its line)."""

    def __init__(self, index: int, message: str) -> None:
        super().__init__(message)
        self.index = index


def _samples(name: str, x: ArrayLike) -> np.ndarray:
    """``x`` as a 1-D float array of finite samples: the first sample that is not finite is named with its index
    (:class:`_SampleError`); anything else :func:`peelapprox.validate.reals` refuses."""
    size = x.size if isinstance(x, np.ndarray) else len(x) if isinstance(x, Sized) else 0
    if size > MAX_SAMPLES:
        raise ValueError(f"{name} has {size} samples, more than the {MAX_SAMPLES} a force series may have (its "
                         "statistics take ~60 bytes a sample; decimate or cut the trace)")
    try:
        raw = np.asarray(x, dtype=float)
    except (TypeError, ValueError):  # text, ragged nesting: reals names it below
        raw = None
    if raw is not None and raw.ndim == 1:
        bad = np.flatnonzero(~np.isfinite(raw))
        if bad.size:
            i = int(bad[0])
            raise _SampleError(i, f"{name}[{i}] = {float(raw[i])!r} is not finite (sample {i} of {raw.size})")
    a = reals(name, x)
    if a.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {a.shape}")
    return np.array(a, dtype=float)
