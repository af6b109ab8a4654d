"""Split an exact trajectory at its jumps into branch segments (AB or CD).

A *segment* is one stay on a stable branch, from the landing of one jump to
the fold of the next.  Its entry and exit states come from the jump records,
which the hybrid solver locates to rounding, so Δt and ΔF are exact to the
solver tolerance.  The local periods of the α oscillation inside a segment are
the intervals between successive upward zero crossings of α, located by cubic
Hermite interpolation of the stored ``(α, α̇ = ω - v/R)`` pairs (4th order in
the step size, so the DOP853 step output suffices; no dense output needed).
Where a stay holds less than one full α cycle (the high-inertia AB stays of
Case II), the interior extrema of α (roots of the same interpolant's
derivative) give the half periods instead.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import trapezoid

from peelapprox.validate import integer

__all__ = ["Segment", "segments"]


@dataclass(frozen=True)
class Segment:
    """One stay on a branch of an exact trajectory.

    Attributes
    ----------
    index : int
        Position in the trajectory's list of complete segments.
    branch : {"AB", "CD"}
    t_in, alpha_in, alphadot_in, omega_in, F_in, v_in : float
        Entry state, just after the jump onto the branch (``v_in`` is the
        landing velocity; ``α̇ = ω - v/R``, FLOW1).
    t_out, alpha_out, alphadot_out, omega_out, F_out, v_out : float
        Exit state at the fold (``v_out`` = the fold velocity).
    dt, dF : float
        ``t_out - t_in`` [s] and ``F_out - F_in`` [N].
    crossings : ndarray
        Times of the upward zero crossings of α inside the segment [s].
    periods : ndarray
        Differences of successive ``crossings`` (local α periods) [s]; empty
        when fewer than two crossings (or when the trajectory stored no points).
    F_at_periods : ndarray
        Mean pull force over each period [N] (for comparison with
        ``2π sqrt(I/(F R))``).
    extrema : ndarray
        Times of the interior extrema of α (α̇ = 0) inside the segment [s].
    """

    index: int
    branch: str
    t_in: float
    alpha_in: float
    alphadot_in: float
    omega_in: float
    F_in: float
    v_in: float
    t_out: float
    alpha_out: float
    alphadot_out: float
    omega_out: float
    F_out: float
    v_out: float
    crossings: np.ndarray = field(repr=False)
    periods: np.ndarray = field(repr=False)
    F_at_periods: np.ndarray = field(repr=False)
    extrema: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))

    @property
    def dt(self) -> float:
        return self.t_out - self.t_in

    @property
    def dF(self) -> float:
        return self.F_out - self.F_in

    def local_period(self) -> float | None:
        """The α period inside this stay [s], or None if it cannot be measured.

        The median of :attr:`periods` (successive upward zero crossings) when
        there are any; otherwise twice the median spacing of successive α
        extrema (a max→min half cycle), which needs at least two extrema.
        """
        return local_period(self.crossings, self.extrema)

    def entry(self) -> dict:
        """Keyword arguments seeding :func:`peelapprox.reduced_segment` from this segment's entry."""
        return dict(F_in=self.F_in, alpha_in=self.alpha_in, alphadot_in=self.alphadot_in, v_in=self.v_in,
                    v_f=self.v_out)


def _hermite_coefficients(h, a0, a1, d0, d1):
    """``a(s) = c0 + c1 s + c2 s^2 + c3 s^3`` on s in [0, 1] with end values a and slopes d (per unit t)."""
    return a0, d0 * h, 3 * (a1 - a0) - (2 * d0 + d1) * h, 2 * (a0 - a1) + (d0 + d1) * h


def _hermite_roots(t0, t1, a0, a1, d0, d1):
    """Upward roots in (t0, t1] of the cubic Hermite interpolant with values a and slopes d."""
    h = t1 - t0
    c0, c1, c2, c3 = _hermite_coefficients(h, a0, a1, d0, d1)
    roots = np.roots([c3, c2, c1, c0]) if abs(c3) > 0 else np.roots([c2, c1, c0])
    out = []
    for r in roots:
        if abs(r.imag) < 1e-12 and 0.0 < r.real <= 1.0:
            s = r.real
            slope = c1 + 2 * c2 * s + 3 * c3 * s * s
            if slope > 0:
                out.append(t0 + s * h)
    return sorted(out)


def _companion_roots(p: np.ndarray) -> np.ndarray:
    """The roots of each row of ``p`` (polynomial coefficients, highest power first, the first and last of every
    row nonzero) as ``numpy.roots`` finds them, one row each: the eigenvalues of the same companion matrices, by
    one stacked ``numpy.linalg.eigvals`` call (LAPACK's geev on each matrix, as ``numpy.roots`` calls it: the
    same numbers bitwise) instead of a Python call per interval.  Complex, shape ``p.shape[0] x (degree)``."""
    n, k = p.shape
    A = np.zeros((n, k - 1, k - 1))
    A[:, np.arange(1, k - 1), np.arange(k - 2)] = 1.0
    A[:, 0, :] = -p[:, 1:] / p[:, :1]
    return np.linalg.eigvals(A).astype(complex, copy=False) if n else np.empty((0, k - 1), complex)


def _crossings(t, a, d):
    """Upward zero crossings of α from samples (t, α, α̇), Hermite-refined (:func:`_hermite_roots` on every
    interval where α turns from negative to non-negative; the cubics with a zero end coefficient, which
    ``numpy.roots`` reduces, one by one, the others in one stacked eigenvalue call)."""
    idx = np.nonzero((a[:-1] < 0) & (a[1:] >= 0))[0]
    idx = idx[t[idx + 1] > t[idx]]
    t0, t1 = t[idx], t[idx + 1]
    h = t1 - t0
    c0, c1, c2, c3 = _hermite_coefficients(h, a[idx], a[idx + 1], d[idx], d[idx + 1])
    plain = (np.abs(c3) > 0) & (c0 != 0)
    out = [] if plain.all() else [r for i in idx[~plain] for r in
                                  _hermite_roots(t[i], t[i + 1], a[i], a[i + 1], d[i], d[i + 1])]
    c0, c1, c2, c3, t0, h = (x[plain, None] for x in (c0, c1, c2, c3, t0, h))
    r = _companion_roots(np.hstack((c3, c2, c1, c0)))
    s = r.real
    ok = (np.abs(r.imag) < 1e-12) & (0.0 < s) & (s <= 1.0)
    ok &= c1 + 2 * c2 * s + 3 * c3 * s * s > 0
    out.extend((t0 + s * h)[ok].tolist())
    return np.array(sorted(set(out)))


def local_period(crossings, extrema) -> float | None:
    """Median spacing of upward zero crossings, else twice the median spacing of extrema, else None [s]."""
    if len(crossings) >= 2:
        return float(np.median(np.diff(crossings)))
    if len(extrema) >= 2:
        return 2.0 * float(np.median(np.diff(extrema)))
    return None


def _extremum(t0, h, a0, a1, d0, d1):
    """The stationary point of the Hermite cubic on one interval where α̇ changes sign (numpy.roots)."""
    _, c1, c2, c3 = _hermite_coefficients(h, a0, a1, d0, d1)
    roots = np.roots([3 * c3, 2 * c2, c1]) if abs(c3) > 0 else np.roots([2 * c2, c1])
    inside = [r.real for r in roots if abs(r.imag) < 1e-12 and 0.0 <= r.real <= 1.0]
    # a sign change of d guarantees a root in [0, 1]; take the one nearest the linear estimate
    s_lin = d0 / (d0 - d1)
    return t0 + h * (min(inside, key=lambda r: abs(r - s_lin)) if inside else s_lin)


def _extrema(t, a, d):
    """Times where α̇ changes sign between samples, refined as the stationary point of the Hermite cubic
    (:func:`_extremum`: the quadratics with a zero end coefficient one by one, the others in one stacked
    eigenvalue call; of two roots in [0, 1] the first nearest the linear estimate, as ``min`` picks)."""
    idx = np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]
    h = t[idx + 1] - t[idx]
    idx, h = idx[h > 0], h[h > 0]
    t0, d0, d1 = t[idx], d[idx], d[idx + 1]
    _, c1, c2, c3 = _hermite_coefficients(h, a[idx], a[idx + 1], d0, d1)
    p = np.stack((3 * c3, 2 * c2, c1), axis=1)
    plain = (np.abs(c3) > 0) & (c1 != 0)
    out = np.empty(len(idx))
    for j in np.flatnonzero(~plain):
        out[j] = _extremum(t0[j], h[j], a[idx[j]], a[idx[j] + 1], d0[j], d1[j])
    r = _companion_roots(p[plain])
    s_lin = (d0 / (d0 - d1))[plain, None]
    s = r.real
    inside = (np.abs(r.imag) < 1e-12) & (0.0 <= s) & (s <= 1.0)
    dist = np.where(inside, np.abs(s - s_lin), np.inf)
    best = np.argmin(dist, axis=1)
    rows = np.arange(len(best))
    s_best = np.where(inside.any(axis=1), s[rows, best], s_lin[:, 0])
    out[plain] = t0[plain] + h[plain] * s_best
    return out


def time_mean(t: np.ndarray, x: np.ndarray, t0: float, t1: float) -> float:
    """Time average of the sampled x(t) over [t0, t1] (trapezoid on the stored points, the end values
    interpolated linearly), independent of how densely the solver happened to store points."""
    if not t1 > t0:
        raise ValueError(f"time_mean needs t1 > t0, got [{t0}, {t1}]")
    if t0 < t[0] or t1 > t[-1]:
        raise ValueError(f"time_mean: [{t0}, {t1}] must lie inside the sampled range [{t[0]}, {t[-1]}]")
    m = (t > t0) & (t < t1)
    tt = np.concatenate(([t0], t[m], [t1]))
    xx = np.concatenate(([np.interp(t0, t, x)], x[m], [np.interp(t1, t, x)]))
    return float(trapezoid(xx, tt) / (t1 - t0))


def segments(trajectory, *, last: int | None = None) -> list[Segment]:
    """Complete branch segments of an exact trajectory, in time order.

    Parameters
    ----------
    trajectory : exact.Trajectory
        From :func:`exact.simulate`.  Entry/exit states and Δt, ΔF need only
        the jumps (``save="jumps"`` suffices); the α periods need stored points
        (``save="steps"`` or ``t_eval``), else they are empty.
    last : int, optional
        Only the last ``last`` complete segments (each as in the whole list, its :attr:`Segment.index` too;
        the branches alternate, so the last ``2 n`` hold the last ``n`` of each branch): what a caller that
        compares the end of a window needs, without the α crossings of every earlier stay.  None: all.

    Returns
    -------
    list of Segment
        One per stay that begins and ends with a jump inside the stored window
        (the partial stays before the first and after the last jump are left
        out).
    """
    J = trajectory.jumps
    first = 0 if last is None else max(len(J) - 1 - integer("last", last, lo=0), 0)
    R = trajectory.params.R
    t = np.asarray(trajectory.t)
    al = np.asarray(trajectory.alpha)
    ad = np.asarray(trajectory.omega) - np.asarray(trajectory.v) / R
    F = np.asarray(trajectory.F)
    out: list[Segment] = []
    for i in range(first, len(J) - 1):
        a, b = J[i], J[i + 1]
        if a.to_branch != b.from_branch:  # pragma: no cover - the solver guarantees alternation
            raise ValueError(f"jumps {i} and {i + 1} do not share a branch: {a.to_branch} vs {b.from_branch}")
        cross = np.empty(0)
        per = np.empty(0)
        Fp = np.empty(0)
        ext = np.empty(0)
        if len(t):
            lo = np.searchsorted(t, a.t, side="right") - 1  # the stored landing point (second row at a.t)
            hi = np.searchsorted(t, b.t, side="left") + 1   # through the fold point at b.t
            lo = max(lo, 0)
            sl = slice(lo, hi)
            tt, aa, dd, FF = t[sl], al[sl], ad[sl], F[sl]
            keep = (tt >= a.t) & (tt <= b.t)
            tt, aa, dd, FF = tt[keep], aa[keep], dd[keep], FF[keep]
            if len(tt) >= 2:
                ext = _extrema(tt, aa, dd)
                ext = ext[(ext > a.t) & (ext < b.t)]
                cross = _crossings(tt, aa, dd)
                cross = cross[(cross > a.t) & (cross < b.t)]
                per = np.diff(cross)
                if len(per):
                    Fp = np.array([time_mean(tt, FF, c0, c1) for c0, c1 in zip(cross[:-1], cross[1:])])
        out.append(Segment(
            index=i, branch=a.to_branch, t_in=a.t, alpha_in=a.alpha, alphadot_in=a.omega - a.v_after / R,
            omega_in=a.omega, F_in=a.F, v_in=a.v_after, t_out=b.t, alpha_out=b.alpha,
            alphadot_out=b.omega - b.v_before / R, omega_out=b.omega, F_out=b.F, v_out=b.v_before,
            crossings=cross, periods=per, F_at_periods=Fp, extrema=ext,
        ))
    return out
