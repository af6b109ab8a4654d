"""The choice of xmin: the Kolmogorov-Smirnov scan of Clauset, Shalizi & Newman (2009, Sec. 3.3), bounded.

For each candidate xmin the exponent is the tail's maximum-likelihood one and the candidate's score the KS
distance between the tail and that law; xmin is the candidate of least distance.  The candidates are the data's
distinct values (integers for discrete data) that leave at least ``min_tail`` points in the tail, so that a
tail of a handful of points, whose KS distance is small by chance, is never chosen (the failure powerlaw's issue
#61 shows: xmin = 6 with 14 points, α = 3.81, where the whole catalogue follows α ≈ 2.6).

Bounded in time and memory: at most ``max_candidates`` (K) candidates in a first, coarse pass, spaced evenly in
ln x over the distinct values; then at most K more, every distinct value between the coarse neighbours of the best
one (all of them where there are at most K).  Cost O(2 K n) operations, memory O(n) (one tail at a time).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ._laws import alpha_mle, ks_distance


class Scan(NamedTuple):
    """The scan's result: the chosen xmin, its tail's exponent and KS distance, the tail's size, the number of
    candidates scored and of likelihood evaluations."""

    xmin: float
    alpha: float
    ks: float
    n_tail: int
    candidates: int
    evaluations: int


def _candidate_indices(x: np.ndarray, min_tail: int, xmax: float) -> np.ndarray:
    """Indices into the sorted data of the first occurrence of each distinct value whose tail (up to xmax) has at
    least ``min_tail`` points."""
    first = np.flatnonzero(np.r_[True, x[1:] != x[:-1]])
    n_in = np.searchsorted(x, xmax, side="right") if math.isfinite(xmax) else x.size
    return first[(n_in - first) >= min_tail]


def _subsample(idx: np.ndarray, x: np.ndarray, k: int) -> np.ndarray:
    """At most k of the candidate indices, spaced evenly in ln x (the ends kept)."""
    if idx.size <= k:
        return idx
    lx = np.log(x[idx])
    targets = np.linspace(lx[0], lx[-1], k)
    pick = np.unique(np.clip(np.searchsorted(lx, targets), 0, idx.size - 1))
    return idx[pick]


def score(x: np.ndarray, lx: np.ndarray, logx_tailsum: np.ndarray, ramp: np.ndarray, i: int, xmax: float,
          discrete: bool) -> tuple[float, float, int]:
    """``(alpha, ks, evaluations)`` of the candidate xmin = x[i] (x sorted, cut at xmax; ``lx = ln x``;
    ``logx_tailsum[i]`` = Σ_{j >= i} ln x_j; ``ramp = arange(n)``)."""
    m = x.size - i
    xmin = float(x[i])
    if float(logx_tailsum[i]) - m * float(lx[i]) <= 0.0:  # every size of the tail equals xmin: no law to fit
        return math.inf, math.inf, 0
    alpha, nev = alpha_mle(m, float(logx_tailsum[i]), xmin, xmax, discrete)
    if discrete or math.isfinite(xmax):
        return alpha, ks_distance(x[i:], alpha, xmin, xmax, discrete), nev
    # the continuous law without xmax, in logs (the scan's hot loop): F = 1 - (x/xmin)^(1-alpha)
    F = -np.expm1((1.0 - alpha) * (lx[i:] - lx[i]))
    r = ramp[:m]
    d = max(float(np.max((r + 1.0) / m - F)), float(np.max(F - r / m)))
    return alpha, d, nev


def ks_scan(x: np.ndarray, *, min_tail: int, max_candidates: int, xmax: float, discrete: bool) -> Scan | None:
    """The KS scan over the sorted data ``x`` (module docstring); None when no candidate leaves ``min_tail``
    points."""
    if math.isfinite(xmax):
        x = x[: np.searchsorted(x, xmax, side="right")]
    idx = _candidate_indices(x, min_tail, math.inf)
    if idx.size == 0:
        return None
    lx = np.log(x)
    tailsum = np.cumsum(lx[::-1])[::-1]
    ramp = np.arange(x.size, dtype=float)
    scored: dict[int, tuple[float, float]] = {}
    nev = 0

    def run(indices: np.ndarray) -> None:
        nonlocal nev
        for i in indices:
            i = int(i)
            if i not in scored:
                a, d, e = score(x, lx, tailsum, ramp, i, xmax, discrete)
                scored[i] = (a, d)
                nev += e

    coarse = _subsample(idx, x, max_candidates)
    run(coarse)
    best = min(scored, key=lambda i: (scored[i][1], i))
    pos = int(np.searchsorted(coarse, best))
    lo = int(coarse[max(pos - 1, 0)])
    hi = int(coarse[min(pos + 1, coarse.size - 1)])
    fine = idx[(idx >= lo) & (idx <= hi)]
    run(_subsample(fine, x, max_candidates))
    best = min(scored, key=lambda i: (scored[i][1], i))
    a, d = scored[best]
    if not math.isfinite(d):
        return None
    return Scan(float(x[best]), a, d, int(x.size - best), len(scored), nev)
