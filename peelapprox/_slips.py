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
3. *Corners.*  A slip starts at the knee where the stick's slow rise turns into the fast fall, and ends at
   the corner where the fall turns into the next rise: each is the crossing of a straight line fitted to the
   stick (at most ``fit`` samples, from the middle of the stick to ``smooth // 2`` samples before the corner)
   with one fitted to the fall next to it, and F there is the stick line's value.  The knee is not the force
   maximum: where ``v_max > V`` (V = 1 m/s in the paper's law) F peaks on AB, a little before the jump, and
   falls slowly until it.  The knee is first where the smoothed gradient, walked back from the steepest fall,
   is half as steep as the mean fall; then, where noise makes that test unreliable (:data:`KNEE_NOISE`), at
   most that late, the sample that splits the stick and the fall
   into two straight lines of least total squared residual (segmented regression): under noise a single
   noisy sample of the fall passes the gradient test, and the knee alone came 3.5 samples late and the drop 8 %
   low where sticks and slips are 40 samples long (V = 3.95 m/s, I = 1.43e-5, 0.5 N of noise; 0.3 % with the
   split).  Noise averages out in the fits (standard error ~2σ/√n) where a raw extremum would
   be biased by it (the largest of n noisy samples), and the crossing is not tied to the sampling grid.

A first slip whose start is the trace's first sample, and a last one without its end, are dropped (their
extrema are the trace's ends, not the stick-slip's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .io import fmt_number, write_rows

__all__ = ["KNEE_NOISE", "Slips", "detect_slips", "noise_level", "THRESHOLD_SIGMAS"]

#: The default threshold in units of the averaged force's noise, σ/√smooth (module docstring, step 2).
THRESHOLD_SIGMAS = 12.0
#: The averaged noise σ/√smooth, as a fraction of a slip's mean fall per sample, above which its knee is found
#: by segmented regression instead of the gradient alone (module docstring, step 3).  At V = 3.95 m/s,
#: I = 1.43e-5 (the ratio 0.61 with 0.5 N of noise) the gradient's knee put the drop 7.2 % low and the split's
#: 0.24 %; at ratios up to 0.37 the gradient's drop is within 0.33 % and the split's, which moves with the
#: sampling grid's phase and scatters 1.5x more, within 0.3 % the other way: the split only where it is needed.
KNEE_NOISE = 0.3


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


def _split(t: np.ndarray, F: np.ndarray, lo: int, hi: int, first: int, last: int) -> int:
    """The index j in ``[first, last]`` that splits ``F[lo:hi]`` into the two straight lines ``[lo, j)`` and
    ``[j, hi)`` of least total squared residual (segmented regression; module docstring, step 3): the sample
    where the stick ends and the fall begins, found by the fits, not by a noisy gradient.  Every candidate at
    once from cumulative sums."""
    first, last = max(first, lo + 3), min(last, hi - 2)
    if last < first:
        return min(max((first + last) // 2, lo), hi)
    x = t[lo:hi] - t[lo]
    y = F[lo:hi] - F[lo]
    zero = np.zeros(1)
    c = [np.concatenate((zero, np.cumsum(a))) for a in (np.ones_like(x), x, y, x * x, x * y, y * y)]
    j = np.arange(first - lo, last - lo + 1)

    def sse(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        n, sx, sy, sxx, sxy, syy = (ci[b] - ci[a] for ci in c)
        vxx = sxx - sx * sx / n
        vxy = sxy - sx * sy / n
        vyy = syy - sy * sy / n
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(vxx > 0, vyy - vxy * vxy / np.where(vxx > 0, vxx, 1.0), vyy)

    total = sse(np.zeros_like(j), j) + sse(j, np.full_like(j, hi - lo))
    return lo + int(j[int(np.argmin(total))])


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
    knee_noise = sigma / math.sqrt(smooth) / KNEE_NOISE  # the smallest fall per sample the gradient is trusted on
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
        if knee_noise > abs(mean_fall) * (t[v] - t[p]) / max(v - p, 1):
            # a noisy sample of the fall passes for half as steep, so the gradient's knee is late: the split
            # of least squares between the stick's line and the fall's, searched from the maximum on
            knee = _split(t, F, lo, min(knee + half + L, v - half), p - half, knee)
            L = max(2, min(fit, (v - knee) // 3))
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
