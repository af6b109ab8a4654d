"""Analysis of the return map of an exact trajectory: periodicity, force drops, settle time.

Everything here reads the *jump sequence* of an exact (hybrid, ε → 0) trajectory, the natural Poincaré
section of stick-slip: the pull force at the AB→CD jumps, ``x_k = F(t_k)``, is the return map whose
periods the paper reports ("period 4 at V = 2, I = 1e-5", "period 8 at V = 1, I = 1e-2", ...).  A model
variant's trajectory (a tape mass, a constant load: ``method="smooth"`` or ``"regularized"``) is read the same
way: its jumps are the crossings of the inflection velocity of f, F there (docs/tape-mass-dynamics.md).

* :func:`return_map` — ``x_k``, the F values at AB→CD jumps.
* :func:`periodicity` — period-n (n <= 32) of ``x_k`` to a stated tolerance, or aperiodic.
* :func:`classify` — :func:`periodicity` of a trajectory's window, "no stick-slip" below 2 returns.
* :func:`force_drops` — ``ΔF_k = F(AB→CD jump k) − F(next CD→AB jump)``, the slip's force drop (Fig. 6).
* :func:`settle_time` — when a periodic orbit is reached (the transient's end).

Pure analysis of a given trajectory (anything with ``jumps.t``, ``jumps.F``, ``jumps.from_branch``: the
protocol :class:`HasJumps`, which :class:`exact.Trajectory` satisfies, so this module need not import
``exact``): no solver runs here.  The functions that run the exact solver (windowed runs, attractors, the
Lyapunov family) live in :mod:`exact`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Protocol, cast, overload

import numpy as np
from numpy.typing import ArrayLike

from ._checks import MAX_COUNT
from .law import BRANCHES
from .validate import ArgumentTypeError, integer, positive, reals

__all__ = ["return_map", "Periodicity", "periodicity", "classify", "force_drops", "settle_time", "HasJumps",
           "JumpRecord"]

_AB = BRANCHES.index("AB")


class JumpRecord(Protocol):
    """The jump sequence this module reads (as :class:`exact.Jumps`): one entry per jump, in time order."""

    @property
    def t(self) -> ArrayLike:
        """Jump times [s]."""

    @property
    def F(self) -> ArrayLike:
        """Pull force at each jump [N]."""

    @property
    def from_branch(self) -> ArrayLike:
        """Branch left by each jump, as an index into :data:`peelapprox.BRANCHES`."""


class HasJumps(Protocol):
    """A trajectory with its jump sequence (as :class:`exact.Trajectory`): what the functions here analyse."""

    @property
    def jumps(self) -> JumpRecord:
        """The jumps in the stored window."""


def _trajectory(name: str, x: object) -> HasJumps:
    """x if it looks like an :class:`exact.Trajectory` (has ``jumps`` with ``t``, ``F``, ``from_branch``)."""
    J = getattr(x, "jumps", None)
    if not all(hasattr(J, a) for a in ("t", "F", "from_branch")):
        raise ArgumentTypeError(f"{name} must be an exact.Trajectory (with jumps), got {type(x).__name__}")
    return cast(HasJumps, x)


@overload
def return_map(trajectory: HasJumps, *, with_times: Literal[False] = ...) -> np.ndarray: ...


@overload
def return_map(trajectory: HasJumps, *, with_times: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...


def return_map(trajectory: HasJumps, *, with_times: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """``x_k``: the pull force [N] at the AB→CD jumps of an exact trajectory (its stored window).

    Parameters
    ----------
    trajectory : HasJumps
        An :class:`exact.Trajectory`, or anything with ``jumps.t``, ``jumps.F`` and ``jumps.from_branch``.
    with_times : bool
        Also return the jump times.

    Returns
    -------
    ndarray, or (ndarray, ndarray) with ``with_times=True``
        ``x_k`` [N], or the pair ``(t_k, x_k)`` of jump times [s] and forces.
    """
    J = _trajectory("trajectory", trajectory).jumps
    m = np.asarray(J.from_branch) == _AB
    x = np.asarray(J.F)[m]
    return (np.asarray(J.t)[m], x) if with_times else x


@dataclass(frozen=True)
class Periodicity:
    """Period of the return map ``x_k`` (see :func:`periodicity`).

    ``kind`` is ``"periodic"`` (``period`` = the smallest n that repeats), ``"aperiodic"`` (no n <=
    ``max_period`` repeats; ``period`` None) or ``"too short"`` (fewer than
    ``(min_repeats + 1) · max_period`` returns were given — 96 with the defaults — so not every n could be
    tried, *and* no shorter period repeated).  ``mismatch`` = ``max_k |x_{k+n} − x_k| / max|x|`` for
    the period found, or the smallest over all n tried (``inf`` when too few returns to try any n; NaN only
    for "no stick-slip" from :func:`classify`); ``n_returns`` = ``len(x)``.
    """

    kind: str
    period: int | None
    mismatch: float
    n_returns: int
    rtol: float

    @property
    def label(self) -> str:
        return f"period-{self.period}" if self.kind == "periodic" else self.kind


def periodicity(
    x: ArrayLike | HasJumps, *, rtol: float = 1e-6, max_period: int = 32, min_repeats: int = 2
) -> Periodicity:
    """Classify the return map as period-n or aperiodic.

    Parameters
    ----------
    x : array_like or exact.Trajectory
        The F values at AB→CD jumps (or a trajectory, through :func:`return_map`), after the transient.
    rtol : float
        Tolerance: period n is accepted when ``max_k |x_{k+n} − x_k| <= rtol · max|x|`` over every k.  The
        hybrid solver at rtol 1e-10 reproduces a periodic orbit's jump forces to ~1e-12, so 1e-6 separates
        periodic orbits from chaotic ones, whose returns do not come within 1e-6 for n <= 32.
    max_period : int
        Largest n tried.
    min_repeats : int
        A period n needs at least ``min_repeats · n`` pairs ``(x_k, x_{k+n})``.

    Returns
    -------
    Periodicity
    """
    if (type(x) is np.ndarray and x.dtype == np.float64 and x.ndim == 1 and x.size >= 2 and type(rtol) is float
            and 0.0 < rtol < math.inf and type(max_period) is int and type(min_repeats) is int
            and 1 <= max_period <= MAX_COUNT and 1 <= min_repeats <= MAX_COUNT and bool(np.isfinite(x).all())):
        return _periodicity(x, rtol, max_period, min_repeats)  # what the checks below pass, without their cost
    if hasattr(x, "jumps"):
        x = return_map(cast(HasJumps, x))
    x = reals("x", x)
    rtol = positive("rtol", rtol)
    max_period, min_repeats = integer("max_period", max_period), integer("min_repeats", min_repeats)
    if x.ndim != 1 or x.size < 2:
        raise ValueError(f"x must be a 1-D finite sequence of at least 2 returns, got shape {x.shape}")
    return _periodicity(x, rtol, int(max_period), int(min_repeats))


def _periodicity(x: np.ndarray, rtol: float, max_period: int, min_repeats: int = 2) -> Periodicity:
    """:func:`periodicity` of arguments it has checked: ``x`` a 1-D finite float array of at least 2 returns,
    ``rtol`` a finite positive float, ``max_period`` and ``min_repeats`` positive ints (the observables of a reduced
    map read a period for every orbit it finds, and these checks cost more than the search)."""
    xs = _scaled(x)
    best = math.inf
    for n in range(1, int(max_period) + 1):
        if x.size - n < int(min_repeats) * n:
            break
        mis = _mismatch(xs, n)
        if mis <= rtol:
            return Periodicity("periodic", n, mis, x.size, rtol)
        best = min(best, mis)
    enough = x.size - int(max_period) >= int(min_repeats) * int(max_period)
    return Periodicity("aperiodic" if enough else "too short", None, best, x.size, rtol)


def settled_period(x: np.ndarray, n: int, rtol: float, min_repeats: int = 2) -> int:
    """The period of returns ``x`` that :func:`periodicity` reads as period ``n`` over the whole sample, once the
    sample's decaying transient is set aside: the smallest divisor ``d < n`` of n whose repeat holds to ``rtol``
    (relative to the whole sample's ``max|x|``, as in :func:`periodicity`) over the sample's last half (at least
    ``min_repeats · d`` pairs there), n where none does.

    A period-d orbit approached along a multiplier μ of ``P^d`` near -1 (a flip mode still decaying, the deviation's
    sign turned every d returns) repeats after 2d to ``|1 - μ²|`` of its deviation but after d only to ``|1 - μ|``,
    about twice it: a sample whose deviation has not yet fallen below ``rtol/2`` repeats after 2d and not after d,
    and reads as period 2d, though the orbit it settles on has period d (measured on the exact runs of the atlas's
    grid: at V = 3.646 m/s, I = 4.92e-4 the orbit is period 9 with μ = -0.988 (:func:`exact.periodic_orbit`), the
    window [30, 50] s repeats after 18 to 6.5e-8 and after 9 to 5.5e-6, its last half after 9 to below 1e-6;
    docs/theory.md, "Period labels").  Near any p-th root of unity likewise after pd (at V = 1.677 m/s, I = 8.4e-5
    from α0 = 0.15 a period-1 orbit's complex pair, |μ| = 0.994, turns 69.8° per return: the window read period 5).
    An orbit of period 2d modulates its returns by a fixed amount that does not
    decay: where that modulation is above ``rtol`` its repeat after d fails over the last half as over the whole,
    and n stays.  The means of :func:`peelapprox._observables.jump_statistics` are still taken over whole cycles of
    n (whole cycles of d too)."""
    hs = _scaled(x)[x.size // 2:]
    for d in range(1, n):
        if n % d == 0 and hs.size - d >= min_repeats * d and _mismatch(hs, d) <= rtol:
            return d
    return n


def _scaled(x: np.ndarray) -> np.ndarray:
    """``x / max|x|`` (in [-1, 1]): no overflow for |x| near the float maximum; all-zero returns (scale 0) are the
    constant sequence, mismatch 0."""
    scale = float(np.max(np.abs(x)))
    return x / scale if scale > 0 else x


def _mismatch(xs: np.ndarray, n: int) -> float:
    """How far scaled returns ``xs`` are from repeating after ``n``: ``max |xs[k + n] - xs[k]|``."""
    return float(np.max(np.abs(xs[n:] - xs[:-n])))


def force_drops(trajectory: HasJumps) -> np.ndarray:
    """Force drop of each slip [N]: ``F`` at an AB→CD jump minus ``F`` at the next CD→AB jump.

    One value per completed slip in the stored window.
    The paper's Fig. 6 plots their mean against V.

    Parameters
    ----------
    trajectory : HasJumps
        As for :func:`return_map`; its jumps must alternate AB→CD→AB (else ValueError).

    Returns
    -------
    ndarray
        ``ΔF_k`` [N], one per AB→CD jump followed by a CD→AB jump in the window.
    """
    J = _trajectory("trajectory", trajectory).jumps
    fb = np.asarray(J.from_branch)
    F = np.asarray(J.F)
    idx = np.flatnonzero(fb[:-1] == _AB)  # AB→CD followed by CD→AB (jumps alternate)
    if np.any(fb[idx + 1] == _AB):
        raise ValueError("force_drops: the jumps do not alternate AB→CD→AB (not an exact trajectory's jumps)")
    return F[idx] - F[idx + 1]


def settle_time(trajectory: HasJumps, *, rtol: float = 1e-6, max_period: int = 32) -> float | None:
    """The time from which the return map is periodic to the end of the stored window, or None.

    The orbit's period n is found on the last half of the returns (:func:`periodicity`); the settle time is
    that of the earliest AB→CD jump from which ``|x_{k+n} − x_k| <= rtol·max|x|`` holds for every later k.
    None means no period was found in the last half (aperiodic, or still in the transient).

    Parameters
    ----------
    trajectory : HasJumps
        As for :func:`return_map`.
    rtol, max_period
        As for :func:`periodicity`.

    Returns
    -------
    float or None
        The settle time [s], or None (fewer than 4 returns, or no period in the last half).
    """
    rtol = positive("rtol", rtol)
    max_period = integer("max_period", max_period)
    t, x = return_map(trajectory, with_times=True)
    if x.size < 4:
        return None
    per = periodicity(x[x.size // 2:], rtol=rtol, max_period=max_period)
    if per.kind != "periodic":
        return None
    n = per.period
    assert n is not None  # kind "periodic" comes with its period
    bad = np.abs(x[n:] - x[:-n]) > rtol * float(np.max(np.abs(x)))
    k = int(np.flatnonzero(bad)[-1]) + 1 if bad.any() else 0
    return float(t[k])


def classify(trajectory: HasJumps, *, period_rtol: float = 1e-6, max_period: int = 32) -> Periodicity:
    """:func:`periodicity` of a window's return map, with ``kind = "no stick-slip"`` below 2 returns.

    Parameters
    ----------
    trajectory : HasJumps
        As for :func:`return_map`, after its transient.
    period_rtol, max_period
        ``rtol`` and ``max_period`` of :func:`periodicity`.

    Returns
    -------
    Periodicity
    """
    x = return_map(trajectory)
    if x.size < 2:
        return Periodicity("no stick-slip", None, math.nan, int(x.size), period_rtol)
    return periodicity(x, rtol=period_rtol, max_period=max_period)
