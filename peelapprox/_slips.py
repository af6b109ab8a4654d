"""Slips found in a sampled pull force: the detector :func:`detect_slips` and its table :class:`Slips`.

A slip is a fall of the force, fast against the stick's rise, by more than a threshold; it starts where the fall
begins and ends where the next rise begins (where the exact solution's AB→CD and CD→AB jumps are: ``Ḟ = k(V -
v)`` changes sign when v crosses V, which happens in the jumps).

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
3. *Corners.*  A slip starts at the knee where the stick's slow rise turns into the fall, and ends at the corner
   where the fall turns into the next rise.  On the raw force from the middle of the stick before (at most
   ``fit`` samples) to the middle of the stick after, a continuous three-piece line (the stick, the fall, the
   next stick) is fitted by least squares, its two knots searched coarse to fine to 1/8 sample between the
   confirmed extrema (± ``smooth // 2 + 1`` samples): the fit finds the fall's samples from all the data at
   once, where a knee read off a noisy gradient came late on short noisy cycles (the mean drop 9-11 % low at
   25-28 samples a cycle, drop/noise 10; 8 % at 40-sample sticks).  Then, for a fall of two or more samples,
   each corner is where the stick's own line (leaving out the 2 samples next to the fall) meets the line of the
   fall's nearest third: a curved fall's tangent there, not its chord (the partition redone from the corners
   once); F before and after are the sticks' lines at the corners.  A fall with no sample inside is a jump
   between two samples: both lines are read at their middle time (the jump's expected time).  A fall with one
   sample inside leaves the knots free along a line through it: they are averaged over a uniform prior on
   where the fall begins.  The knee is not the force maximum: where ``v_max > V`` (V = 1 m/s in the paper's
   law) F peaks on AB, a little before the jump, and falls slowly until it.  Noise averages out in the line
   fits where a raw extremum would be biased by it (the largest of n noisy samples), and the crossing is not
   tied to the sampling grid.  The mean drop's bias over sampling rates, noise levels and fall lengths:
   ``python -m comparisons.benchmark.detector_bias`` (docs/your-data.md: within 1.4 % from 25 samples a cycle
   and drop/noise 10).

A first slip whose start is the trace's first sample, and a last one without its end, are dropped (their
extrema are the trace's ends, not the stick-slip's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._slips_knee import slip_sticks
from .io import fmt_number, write_rows

__all__ = ["Slips", "detect_slips", "noise_level", "THRESHOLD_SIGMAS"]

#: The default threshold in units of the averaged force's noise, σ/√smooth (module docstring, step 2).
THRESHOLD_SIGMAS = 12.0
#: Samples next to a fall that the sticks' lines leave out when the corners are placed (:func:`_corners`).
_GAP = 2


def noise_level(F: np.ndarray) -> float:
    """The noise's standard deviation σ of a sampled force: 1.4826 · MAD(second differences) / √6 [N]
    (module docstring, step 1); 0 for a noiseless smooth trace.  Also the noise estimate of ``PeelForce.smoothed``
    (its penalty search, ``peelapprox/law/_spline.py``): the package's one."""
    d2 = F[2:] - 2.0 * F[1:-1] + F[:-2]
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return 1.4826 * mad / math.sqrt(6.0)


@dataclass(frozen=True, eq=False)
class Slips:
    """The slips of a force trace, one entry per slip in time order (:meth:`ForceSeries.slips`).

    Attributes
    ----------
    t_start, t_end : ndarray
        Times of the slip's start (where the stick's line meets the fall) and end (where the fall meets the next
        stick's line) [s]; for a fall shorter than a sample, the samples around it (module docstring, step 3).
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

    def period_tolerance(self) -> float:
        """The return map's default period tolerance for these slips (:meth:`peelapprox.ForceSeries.observables`),
        relative to the largest F before a slip: the detector's repeatability, the largest of 6 fit errors
        (``6 · 2σ/√40``, σ = :attr:`noise`), 2 % of the range of F before the slips and 3e-4 of the largest (on
        noiseless model traces sampled at 10 kHz the corners repeat to ~0.03 N of 300 N, 1e-4).  Needs a slip."""
        top = float(np.max(np.abs(self.F_before)))
        return max(6.0 * 2.0 * float(self.noise) / math.sqrt(40.0), 0.02 * float(np.ptp(self.F_before)),
                   3e-4 * top) / top

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

    def to_dataframe(self) -> Any:
        """:meth:`as_rows` as a :class:`pandas.DataFrame` (one row per slip; ``stick_before`` NaN for the first;
        ``df.attrs["units"]``, ``threshold``, ``noise``, ``method``).

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        from .io import optional_import

        pd = optional_import("pandas", "Slips.to_dataframe")
        cols = ["t_start", "t_end", "F_before", "F_after", "drop", "slip_time", "rise", "stick_before"]
        df = pd.DataFrame(self.as_rows(), columns=cols).astype(float)
        units = {"t_start": "s", "t_end": "s", "F_before": "N", "F_after": "N", "drop": "N", "slip_time": "s",
                 "rise": "N/s", "stick_before": "s"}
        df.attrs.update(units=units, threshold=self.threshold, noise=self.noise, method=self.method)
        return df

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


def _suffix_sums(s: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, ...]:
    """Sums of 1, s, s^2, y, s y from each sample to the end (one more entry: 0), and ``y @ y``."""
    c = np.cumsum(np.stack([np.ones_like(s), s, s * s, y, s * y])[:, ::-1], axis=1)[:, ::-1]
    out = np.concatenate([c, np.zeros((5, 1))], axis=1)
    return (*out, np.array(float(y @ y)))


def _hinge_sse(sums: tuple[np.ndarray, ...], s: np.ndarray, k1: np.ndarray,
               k2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(SSE, coefficients)`` of the least-squares linear spline ``c0 + c1 s + c2 (s - k1)+ + c3 (s - k2)+`` of
    ``y(s)`` for each knot pair ``(k1[i], k2[i])``, all at once: the normal equations from suffix sums of
    1, s, s^2, y, s y over the samples past each knot (O(pairs), not O(pairs x samples))."""
    S0, S1, S2, Y0, Y1, yy = sums
    i1 = np.searchsorted(s, k1, side="right")
    i2 = np.searchsorted(s, k2, side="right")
    a0, a1, a2, b0, b1 = S0[i1], S1[i1], S2[i1], S0[i2], S1[i2]
    b2 = S2[i2]
    G = np.empty((k1.size, 4, 4))
    G[:, 0, 0], G[:, 0, 1], G[:, 1, 1] = S0[0], S1[0], S2[0]
    G[:, 0, 2] = a1 - k1 * a0
    G[:, 1, 2] = a2 - k1 * a1
    G[:, 2, 2] = a2 - 2 * k1 * a1 + k1 * k1 * a0
    G[:, 0, 3] = b1 - k2 * b0
    G[:, 1, 3] = b2 - k2 * b1
    G[:, 2, 3] = b2 - (k1 + k2) * b1 + k1 * k2 * b0
    G[:, 3, 3] = b2 - 2 * k2 * b1 + k2 * k2 * b0
    for i, j in ((1, 0), (2, 0), (2, 1), (3, 0), (3, 1), (3, 2)):
        G[:, i, j] = G[:, j, i]
    r = np.stack([np.full(k1.size, Y0[0]), np.full(k1.size, Y1[0]), Y1[i1] - k1 * Y0[i1], Y1[i2] - k2 * Y0[i2]],
                 axis=1)
    G += 1e-12 * np.trace(G, axis1=1, axis2=2)[:, None, None] * np.eye(4)
    c = np.linalg.solve(G, r[:, :, None])[:, :, 0]
    return float(yy) - np.einsum("pi,pi->p", r, c), c


def _hinge(t: np.ndarray, F: np.ndarray, a: int, b: int, x_lo: float, x_hi: float
           ) -> tuple[float, float, float, float, float]:
    """One slip by a continuous three-piece line fit (module docstring, step 3) of ``F[a:b+1]``: the stick's line,
    the fall's, the next stick's, the two knots searched between the fractional sample indices ``x_lo`` and
    ``x_hi`` coarse to fine (to 1/8 sample).  ``(t_start, t_end, F_before, F_after, rise)``: the knots' times and
    the fit's values there, and the stick line's slope; an unresolved fall (no sample between the knots) is a
    jump between the two samples around it, both lines read at their middle time."""
    tt = t[a:b + 1]
    t0, scale = float(t[a]), float(t[b] - t[a]) / max(b - a, 1)
    s = (tt - t0) / scale
    y = F[a:b + 1] - float(F[a])
    n = b - a
    x_lo, x_hi = min(max(x_lo - a, 1.0), n - 2.0), min(max(x_hi - a, 2.0), n - 1.0)
    sums = _suffix_sums(s, y)
    h = max(0.5, (x_hi - x_lo) / 24.0)
    g1 = g2 = np.arange(x_lo, x_hi + 1e-9, h)
    best = (x_lo, x_hi)
    while True:
        i1, i2 = np.meshgrid(g1, g2, indexing="ij")
        keep = i2 > i1 + 1e-9
        k1, k2 = _frac_time(s, i1[keep]), _frac_time(s, i2[keep])
        if k1.size:
            sse, c = _hinge_sse(sums, s, k1, k2)
            j = int(np.argmin(sse))
            best, coef, kk = (float(i1[keep][j]), float(i2[keep][j])), c[j], (float(k1[j]), float(k2[j]))
        if h <= 0.125 or not k1.size:
            break
        h /= 3.0
        g1 = np.arange(max(x_lo, best[0] - 3 * h), min(x_hi, best[0] + 3 * h) + 1e-9, h)
        g2 = np.arange(max(x_lo, best[1] - 3 * h), min(x_hi, best[1] + 3 * h) + 1e-9, h)
    if not k1.size:  # too few samples for a search: the extremes' own values
        return float(t[a]), float(t[b]), float(F[a]), float(F[b]), 0.0
    c0, c1, c2, c3 = (float(x) for x in coef)
    k1f, k2f = kk
    inside = np.flatnonzero((s > k1f) & (s < k2f))
    after0, after1 = c0 - c2 * k1f - c3 * k2f, c1 + c2 + c3  # the next stick's line
    if inside.size == 0:  # a jump between two samples: each line read at their middle
        i = int(np.searchsorted(s, k1f, side="right")) - 1
        km = 0.5 * (s[i] + s[i + 1])
        fb, fa = c0 + c1 * km, after0 + after1 * km
        ts, te = float(tt[i]), float(tt[i + 1])
    elif inside.size == 1:  # one sample in the fall: the knots are free along a line through it (all fit alike)
        ts, te, fb, fa = _one_inside(s, int(inside[0]), (c0, c1), (after0, after1), c0 + c1 * k1f + c2 * (
            s[inside[0]] - k1f))
        ts, te = t0 + ts * scale, t0 + te * scale
    else:  # a resolved fall: each corner where a stick's own line meets the nearest third of the fall's samples
        ts, te, fb, fa, c1 = _corners(s, y, inside)
        ts, te = t0 + ts * scale, t0 + te * scale
    base = float(F[a])
    return ts, te, fb + base, fa + base, c1 / scale


def _one_inside(s: np.ndarray, m: int, before: tuple[float, float], after: tuple[float, float],
                ym: float) -> tuple[float, float, float, float]:
    """A fall with one sample ``m`` inside: every fall line through ``(s[m], ym)`` from the stick's line (knot
    k1 in ``(s[m-1], s[m])``) to the next stick's (knot k2 in ``(s[m], s[m+1])``) fits alike; the knots, F before
    and F after averaged over k1 uniform on the part of its interval whose k2 lies in its own (a uniform prior
    on where the fall begins).  ``(k1, k2, F_before, F_after)`` in the scaled time."""
    k1 = s[m - 1] + (np.arange(64) + 0.5) / 64 * (s[m] - s[m - 1])
    fb = before[0] + before[1] * k1
    slope = (ym - fb) / (s[m] - k1)
    with np.errstate(divide="ignore", invalid="ignore"):
        # the fall line fb + slope (k - k1) meets after[0] + after[1] k
        k2 = (fb - slope * k1 - after[0]) / (after[1] - slope)
    ok = np.isfinite(k2) & (k2 > s[m]) & (k2 <= s[m + 1])
    if not ok.any():
        km = float(s[m])
        return km, km, before[0] + before[1] * km, after[0] + after[1] * km
    k1, k2, fb = k1[ok], k2[ok], fb[ok]
    fa = after[0] + after[1] * k2
    return float(k1.mean()), float(k2.mean()), float(fb.mean()), float(fa.mean())


def _corners(s: np.ndarray, y: np.ndarray, inside: np.ndarray) -> tuple[float, float, float, float, float]:
    """The corners of a fall whose samples are ``inside`` (two or more; the hinge fit's partition): the line of
    the stick before meets the line of the fall's first third (at least two samples) at the start, the fall's
    last third meets the next stick's line at the end (a curved fall's tangent there, not its chord).  The
    sticks' lines leave out :data:`_GAP` samples next to the fall (the chord's partition may hand them a curved
    fall's first or last samples), each corner is kept within those samples of its bracket, and the partition is
    redone from the corners once.  ``(k1, k2, F_before, F_after, stick slope)`` in the scaled time."""
    n = s.size

    def line(lo: int, hi: int) -> tuple[float, float]:
        lo, hi = max(lo, 0), min(hi, n)
        if hi - lo < 2:
            j = min(max(lo, 0), n - 1)
            return 0.0, float(y[j])
        slope, icept = np.polyfit(s[lo:hi], y[lo:hi], 1)
        return float(slope), float(icept)

    def meet(a: tuple[float, float], b: tuple[float, float], lo: float, hi: float) -> float:
        if a[0] == b[0]:
            return 0.5 * (lo + hi)
        return min(max((b[1] - a[1]) / (a[0] - b[0]), lo), hi)

    i0, i1 = int(inside[0]), int(inside[-1])
    g = _GAP
    for _ in range(2):
        m = max(2, (i1 - i0 + 1) // 3)
        stick, after = line(0, max(i0 - g, 2)), line(min(i1 + 1 + g, n - 2), n)
        k1 = meet(stick, line(i0, i0 + m), float(s[max(i0 - 1 - g, 0)]), float(s[min(i0 + g, i1)]))
        k2 = meet(line(i1 + 1 - m, i1 + 1), after, float(s[max(i1 - g, i0)]), float(s[min(i1 + 1 + g, n - 1)]))
        j0 = int(np.searchsorted(s, k1, side="right"))
        j1 = int(np.searchsorted(s, k2, side="left")) - 1
        if j1 - j0 < 1 or (j0, j1) == (i0, i1):
            break
        i0, i1 = j0, j1
    return k1, k2, stick[1] + stick[0] * k1, after[1] + after[0] * k2, stick[0]


def _frac_time(s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The scaled time at the fractional sample indices ``x`` (linear between samples)."""
    return np.interp(x, np.arange(s.size, dtype=float), s)


def detect_slips(t: np.ndarray, F: np.ndarray, *, threshold: float | None = None, smooth: int = 5,
                 fit: int = 40, method: str = "lines") -> Slips:
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
    method : {"lines", "knee"}
        How each slip is read: ``"lines"`` (default) the three-piece line fit (module docstring, step 3);
        ``"knee"`` the earlier knee method (:mod:`peelapprox._slips_knee`: biased low on short noisy cycles,
        kept for :func:`exact.infer`, whose statistics were calibrated with it).

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
    if method == "knee":
        from ._slips_knee import knee_slips

        ts, te, fb, fa, rise = knee_slips(t, F, Fs, peaks, valleys, sigma, smooth, fit)
        return Slips(t_start=ts, t_end=te, F_before=fb, F_after=fa, rise=rise, threshold=float(h), noise=sigma,
                     method=_describe(smooth, h, sigma, threshold, fit, "knee"))
    if method != "lines":
        raise ValueError(f"method must be 'lines' or 'knee', got {method!r}")
    last = len(F) - 1
    spans = slip_sticks(peaks, valleys, last)
    n = len(spans)
    ts, te, fb, fa, rise = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for k, (p, v, before, after) in enumerate(spans):
        a = max(before + (p - before) // 2, p - half - fit, 0)
        b = min(v + (after - v) // 2, v + half + fit, last)
        ts[k], te[k], fb[k], fa[k], rise[k] = _hinge(t, F, a, b, p - half - 1.0, v + half + 1.0)
    return Slips(t_start=ts, t_end=te, F_before=fb, F_after=fa, rise=rise, threshold=float(h), noise=sigma,
                 method=_describe(smooth, h, sigma, threshold, fit, "lines"))


def _describe(smooth: int, h: float, sigma: float, threshold: float | None, fit: int, method: str) -> str:
    """The detector and its settings, in words (:attr:`Slips.method`)."""
    how = ("a three-piece line fit (stick, fall, stick)" if method == "lines"
           else "the knee method (line fits at the knee; biased low on short noisy cycles)")
    return (f"slips: falls of the {smooth}-sample moving average by more than {fmt_number(h, 3)} N "
            + (f"(12 sigma/sqrt({smooth}), sigma = {fmt_number(sigma, 3)} N from the second differences)"
               if threshold is None
               else "(given)")
            + f", F before and after by {how} with up to {fit} stick samples")
