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


def _crossings(t, a, d):
    """Upward zero crossings of α from samples (t, α, α̇), Hermite-refined."""
    out = []
    idx = np.nonzero((a[:-1] < 0) & (a[1:] >= 0))[0]
    for i in idx:
        if t[i + 1] <= t[i]:
            continue
        out.extend(_hermite_roots(t[i], t[i + 1], a[i], a[i + 1], d[i], d[i + 1]))
    return np.array(sorted(set(out)))


def local_period(crossings, extrema) -> float | None:
    """Median spacing of upward zero crossings, else twice the median spacing of extrema, else None [s]."""
    if len(crossings) >= 2:
        return float(np.median(np.diff(crossings)))
    if len(extrema) >= 2:
        return 2.0 * float(np.median(np.diff(extrema)))
    return None


def _extrema(t, a, d):
    """Times where α̇ changes sign between samples, refined as the stationary point of the Hermite cubic."""
    out = []
    for i in np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]:
        h = t[i + 1] - t[i]
        if h <= 0:
            continue
        _, c1, c2, c3 = _hermite_coefficients(h, a[i], a[i + 1], d[i], d[i + 1])
        roots = np.roots([3 * c3, 2 * c2, c1]) if abs(c3) > 0 else np.roots([2 * c2, c1])
        inside = [r.real for r in roots if abs(r.imag) < 1e-12 and 0.0 <= r.real <= 1.0]
        # a sign change of d guarantees a root in [0, 1]; take the one nearest the linear estimate
        s_lin = d[i] / (d[i] - d[i + 1])
        out.append(t[i] + h * (min(inside, key=lambda r: abs(r - s_lin)) if inside else s_lin))
    return np.array(out)


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


def segments(trajectory) -> list[Segment]:
    """Complete branch segments of an exact trajectory, in time order.

    Parameters
    ----------
    trajectory : exact.Trajectory
        From :func:`exact.simulate`.  Entry/exit states and Δt, ΔF need only
        the jumps (``save="jumps"`` suffices); the α periods need stored points
        (``save="steps"`` or ``t_eval``), else they are empty.

    Returns
    -------
    list of Segment
        One per stay that begins and ends with a jump inside the stored window
        (the partial stays before the first and after the last jump are left
        out).
    """
    J = trajectory.jumps
    R = trajectory.params.R
    t = np.asarray(trajectory.t)
    al = np.asarray(trajectory.alpha)
    ad = np.asarray(trajectory.omega) - np.asarray(trajectory.v) / R
    F = np.asarray(trajectory.F)
    out: list[Segment] = []
    for i in range(len(J) - 1):
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
            index=len(out), branch=a.to_branch, t_in=a.t, alpha_in=a.alpha, alphadot_in=a.omega - a.v_after / R,
            omega_in=a.omega, F_in=a.F, v_in=a.v_after, t_out=b.t, alpha_out=b.alpha,
            alphadot_out=b.omega - b.v_before / R, omega_out=b.omega, F_out=b.F, v_out=b.v_before,
            crossings=cross, periods=per, F_at_periods=Fp, extrema=ext,
        ))
    return out
