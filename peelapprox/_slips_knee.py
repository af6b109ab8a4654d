"""The slip detector's knee method (``ForceSeries.slips(method="knee")``): a slip's knee where the smoothed
gradient first flattens (or, under noise, by segmented regression), its corners where lines fitted to the stick
and to the nearest third of the fall cross.

This was the detector's only method until the three-piece line fit (:mod:`peelapprox._slips`, step 3) replaced
it as the default: it reads the mean drop 4-11 % low on short noisy cycles (25-100 samples a cycle, drop/noise 10;
``python -m comparisons.benchmark.detector_bias``).  It is kept for :func:`exact.infer` (its numbers as they were:
the line fits in closed form instead of ``np.polyfit``, the slips of 8 noisy and noiseless model traces within
1e-10 relative of the polyfit version, 2.5x cheaper; the gradient bitwise ``np.gradient``'s), whose
statistics (read off the data and the model the same way, so that the detector's biases cancel) and their
repeatability (``REPEATABILITY`` in ``exact/dynamics/_infer_stats.py``) were measured with it: with the line fit,
the high-inertia fit of ``tests/test_infer.py`` (I and k free) ended 17 % off in I instead of 0.4 %, a
recalibration not yet done.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["KNEE_NOISE", "knee_slips", "slip_sticks"]

#: The averaged noise σ/√smooth, as a fraction of a slip's mean fall per sample, above which its knee is found
#: by segmented regression instead of the gradient alone.  At V = 3.95 m/s, I = 1.43e-5 (the ratio 0.61 with
#: 0.5 N of noise) the gradient's knee put the drop 7.2 % low and the split's 0.24 %; at ratios up to 0.37 the
#: gradient's drop is within 0.33 % and the split's, which moves with the sampling grid's phase and scatters 1.5x
#: more, within 0.3 % the other way: the split only where it is needed.
KNEE_NOISE = 0.3


def _line(t: np.ndarray, F: np.ndarray, lo: int, hi: int, min_n: int) -> tuple[float, float, float] | None:
    """``(slope, value at t0, t0)`` of the straight line fitted to ``F[lo:hi]`` (t0 the segment's first time),
    or None for fewer than ``min_n`` samples."""
    if hi - lo < min_n:
        return None
    t0 = float(t[lo])
    # least squares in closed form about the segment's means (np.polyfit's SVD costs ~10x more and agrees to
    # rounding: the slips of 8 noisy and noiseless model traces within 1e-10 relative)
    x = t[lo:hi] - t0
    y = F[lo:hi]
    n = hi - lo
    xm, ym = float(x.sum()) / n, float(y.sum()) / n
    dx = x - xm
    slope = float(dx @ (y - ym)) / float(dx @ dx)
    return slope, ym - slope * xm, t0


def _gradient(f: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``np.gradient(f, x)`` of a 1-D ``f`` (two samples or more), its operations repeated without its N-d
    bookkeeping (bitwise the same; 5-10x cheaper on a slip's few samples): second-order central differences
    inside (numpy's non-uniform formula unless the spacing is exactly uniform), first-order at the ends."""
    d = np.diff(x)
    out = np.empty_like(f)
    if (d == d[0]).all():
        h = d[0]
        out[1:-1] = (f[2:] - f[:-2]) / (2. * h)
        out[0] = (f[1] - f[0]) / h
        out[-1] = (f[-1] - f[-2]) / h
        return out
    dx1, dx2 = d[:-1], d[1:]
    a = -(dx2) / (dx1 * (dx1 + dx2))
    b = (dx2 - dx1) / (dx1 * dx2)
    c = dx1 / (dx2 * (dx1 + dx2))
    out[1:-1] = a * f[:-2] + b * f[1:-1] + c * f[2:]
    out[0] = (f[1] - f[0]) / d[0]
    out[-1] = (f[-1] - f[-2]) / d[-1]
    return out


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
    c = np.zeros((6, x.size + 1))
    np.cumsum(np.stack((np.ones_like(x), x, y, x * x, x * y, y * y)), axis=1, out=c[:, 1:])
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


def slip_sticks(peaks: list[int], valleys: list[int], last: int) -> list[tuple[int, int, int, int]]:
    """Each slip's ``(peak, valley, before, after)``: the stick before it runs from the previous slip's end (or the
    trace's start), the stick after it to the next slip's start (or the trace's last sample ``last``).  A slip at
    the first sample is dropped: its stick before is not in the trace."""
    if peaks and peaks[0] == 0:
        peaks, valleys = peaks[1:], valleys[1:]
    n = len(peaks)
    return [(peaks[k], valleys[k], valleys[k - 1] if k else 0, peaks[k + 1] if k + 1 < n else last) for k in range(n)]


def knee_slips(t: np.ndarray, F: np.ndarray, Fs: np.ndarray, peaks: list[int], valleys: list[int],
               sigma: float, smooth: int, fit: int) -> tuple[np.ndarray, ...]:
    """``(t_start, t_end, F_before, F_after, rise)`` of the confirmed extrema by the knee method (module
    docstring)."""
    half = smooth // 2
    knee_noise = sigma / math.sqrt(smooth) / KNEE_NOISE  # the smallest fall per sample the gradient is trusted on
    last = len(F) - 1
    spans = slip_sticks(peaks, valleys, last)
    n = len(spans)
    ts, te, fb, fa, rise = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for k, (p, v, before, after) in enumerate(spans):
        # the knee: walking back from the steepest fall, the first sample at least half as steep as the slip's
        # mean fall (from the maximum forwards, noise on a flat stick could pass for it)
        mean_fall = (Fs[v] - Fs[p]) / (t[v] - t[p])
        g = _gradient(Fs[p:v + 1], t[p:v + 1]) if v > p else np.zeros(1)
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
    return ts, te, fb, fa, rise
