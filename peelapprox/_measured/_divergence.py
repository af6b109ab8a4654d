"""The divergence curve of a delay embedding: the numerical core of
:func:`peelapprox._measured._series_lyapunov.series_lyapunov` (the method: that module's docstring).  The delay
vectors, each reference point's nearest neighbours beyond the Theiler window, the mean log distance after k steps,
its least-squares slope and the range it is fitted over."""

from __future__ import annotations

import math
import time

import numpy as np

#: The fewest points a fit range may hold.
MIN_FIT = 5
#: The least rise [nats] from the curve's start to the attractor's size an automatic fit range needs.
MIN_RISE = 1.0
#: Reference points are paired with their neighbours this many at a time (bounds the query's memory).
BLOCK = 256


def _embed(x: np.ndarray, m: int, tau: int) -> np.ndarray:
    """The delay vectors ``(x_i, x_{i+τ}, …)`` as rows (a view)."""
    return np.lib.stride_tricks.sliding_window_view(x, (m - 1) * tau + 1)[:, ::tau]


def _pairs(X: np.ndarray, usable: int, refs: np.ndarray, w: int, nn: int, deadline: float) -> tuple[np.ndarray,
                                                                                                    np.ndarray]:
    """``(references, neighbours)``: each reference's ``nn`` nearest points among ``X[:usable]`` further than
    ``w`` steps away in time (references without that many dropped), queried ``BLOCK`` at a time."""
    from scipy.spatial import cKDTree

    tree = cKDTree(X[:usable])
    kq = min(2 * w + 1 + nn, usable)
    keep_r, keep_n = [], []
    for b in range(0, refs.size, BLOCK):
        if time.perf_counter() > deadline:
            raise TimeoutError("max_wall ran out pairing the reference points with their neighbours")
        r = refs[b:b + BLOCK]
        _, idx = tree.query(X[r], k=kq)
        idx = idx.reshape(r.size, -1)
        far = (np.abs(idx - r[:, None]) > w) & (idx < usable)
        sel = far & (np.cumsum(far, axis=1) <= nn)
        ok = sel.sum(axis=1) == nn
        keep_r.append(r[ok])
        keep_n.append(idx[ok][sel[ok]].reshape(-1, nn))
    return np.concatenate(keep_r), np.concatenate(keep_n)


def _curve(X: np.ndarray, refs: np.ndarray, nbrs: np.ndarray, ks: np.ndarray, floor: float) -> np.ndarray:
    """Mean over the references of ln (mean distance to their neighbours after k steps), for each k."""
    out = np.empty(ks.size)
    for a, k in enumerate(ks):
        d = np.linalg.norm(X[nbrs + k] - X[refs + k][:, None, :], axis=2).mean(axis=1)
        out[a] = float(np.mean(np.log(np.maximum(d, floor))))
    return out


def _slope(k: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """``(slope, stderr, intercept)`` of the least-squares line through ``(k, y)`` (at least 3 points)."""
    kc = k - k.mean()
    sxx = float(np.sum(kc * kc))
    slope = float(np.sum(kc * (y - y.mean()))) / sxx
    icept = float(y.mean()) - slope * float(k.mean())
    res = y - (icept + slope * k)
    se = math.sqrt(float(np.sum(res * res)) / max(k.size - 2, 1) / sxx)
    return slope, se, icept


def _fit_range(y: np.ndarray, y_sat: float, lo: float, hi: float) -> tuple[int, int]:
    """Indices ``(a, b)`` of the fit: from where the curve has risen ``lo`` of the way from its value after
    one step to the attractor's size ``y_sat`` to where it has risen ``hi`` of it; from step 1 (to the end)
    where it never does; at least :data:`MIN_FIT` points.  A curve starting less than :data:`MIN_RISE` below
    the attractor's size has no exponential range to resolve (noise as large as the attractor, or a periodic
    series whose returns differ by noise only): the whole curve from step 1.

    The curve starts at step 1, not 0: a neighbour is the nearest *with its noise*, so at k = 0 the distance
    is biased low by the selection and jumps to the noise level in one step whatever the dynamics.
    """
    y1 = float(y[1])
    rise = y_sat - y1
    if rise < MIN_RISE:
        return 1, y.size - 1
    above_hi = np.flatnonzero(y[1:] >= y1 + hi * rise)
    b = int(above_hi[0]) + 1 if above_hi.size else y.size - 1
    above_lo = np.flatnonzero(y[1:b + 1] >= y1 + lo * rise)
    a = int(above_lo[0]) + 1 if above_lo.size else 1
    if b - a + 1 < MIN_FIT:
        b = min(y.size - 1, a + MIN_FIT - 1)
        a = max(1, b - MIN_FIT + 1)
    return a, b
