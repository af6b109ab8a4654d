"""The one fold record (:class:`BranchStructure`) and the search for the folds of any law but fvV.

:func:`find_folds` works on a vectorised evaluator ``fn(v, order)`` of f (order 0) and f' (order 1) at one
pull speed, so it serves every kind of :class:`peelapprox.PeelForce` but the built-in one (whose folds are
:func:`peelapprox.branch_structure`'s):

1. f' on a grid uniform in ``ln v`` over the fold window; its sign changes (zeros skipped) bracket the
   extrema of f: ``+ -> -`` a maximum, ``- -> +`` a minimum;
2. each refined by Brent's method in ``ln v`` (xtol 1e-15, rtol 4 ulp);
3. exactly one maximum followed by one minimum is stick-slip (the N shape): the folds; none with f' > 0 is
   no stick-slip at this V (``has_folds=False``); anything else is a ValueError listing the extrema;
4. the landings: Brent's method in ``ln v`` for ``f = f_max`` on ``[v_min, hi]`` (CD) and ``f = f_min`` on
   ``[lo, v_max]`` (AB) over the law's whole domain ``(lo, hi)``; None where f does not reach the level.

Two extrema closer than the grid spacing (0.5 % in v at the default density, e.g. right at the cusp
where the folds are born) fall in one cell and are not seen: the law is then reported without folds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

from .._brentq import brentq

__all__ = ["BRANCHES", "BREAKDOWN_LEVEL", "BranchStructure", "Folds", "find_folds"]

_RTOL = 4 * np.finfo(float).eps


#: Names of the stable branches, indexed by the integer codes used in arrays.
BRANCHES = ("AB", "CD")
#: Relative distance of the level ``F(1 - cos θ)`` above ``f(0+, V)`` (times ``max(|f(0+)|, 1 N)``) at which the
#: model breaks down (:attr:`BranchStructure.v_breakdown`).
BREAKDOWN_LEVEL = 1e-10


@dataclass(frozen=True)
class BranchStructure:
    """The stable branches of ``f(·, V)`` at one pull speed: its folds, where jumps land, and what the solvers read.

    One record for every law: :meth:`peelapprox.PeelForce.folds` fills the folds and landings (the law's own
    search), :func:`peelapprox.branch_structure` every field.  ``Folds`` is another name of this class.

    Attributes
    ----------
    V : float
        Pull speed [m/s].
    has_folds : bool
        True inside the stick-slip window (f has a local maximum followed by a local minimum in v).  When
        False, f increases in v, there is one stable branch (AB, ``v in (0, inf)``), no jumps, and every fold
        field is None.
    v_max, f_max : float or None
        The fold ending the slow branch AB (local maximum of f) [m/s, N].
    v_min, f_min : float or None
        The fold starting the fast branch CD (local minimum of f) [m/s, N].
    v_inflection : float
        The minimiser of f' (``f'' = 0``), between the folds when they exist.
    f_zero : float
        ``f(0+, V)`` (fvV: ``130 - 2 V^1.5``; a law whose domain starts above 0: f there): below this level AB
        has no root.
    v_land_cd : float or None
        Where an AB→CD jump lands: the CD velocity with ``f = f_max``; None if f stays below ``f_max`` up to
        the end of the law's domain.
    v_land_ab : float or None
        Where a CD→AB jump lands: the AB velocity with ``f = f_min``; None if f stays above ``f_min`` down to
        the start of the law's domain.
    v_breakdown : float
        The AB velocity where ``f - f(0+) = BREAKDOWN_LEVEL max(|f(0+)|, 1 N)``: a level this close to
        ``f(0+)`` is f(0+) to within the solvers' rounding, so CONSTR has no resolvable root above it (the
        model's breakdown criterion, used by ``exact.simulate``); ~1e-67 m/s for fvV at every V.

    ``v_inflection``, ``f_zero`` and ``v_breakdown`` are NaN (not computed) in the record of
    :meth:`PeelForce.folds`, which finds the folds by numpy alone.
    """

    V: float
    has_folds: bool
    v_max: float | None = None
    f_max: float | None = None
    v_min: float | None = None
    f_min: float | None = None
    v_inflection: float = math.nan
    f_zero: float = math.nan
    v_land_cd: float | None = None
    v_land_ab: float | None = None
    v_breakdown: float = math.nan

    def branch_range(self, branch: str) -> tuple[float, float]:
        """Range ``(v_lo, v_hi)`` of v on a stable branch."""
        if branch == "AB":
            return (0.0, cast(float, self.v_max) if self.has_folds else math.inf)
        if branch == "CD":
            if not self.has_folds:
                raise ValueError(f"branch 'CD' does not exist for V={self.V}: f(v, V) has no fold "
                                 "(no stick-slip window)")
            assert self.v_min is not None  # has_folds
            return (self.v_min, math.inf)
        raise ValueError(f"branch must be 'AB' or 'CD', got {branch!r}")

    def has_root(self, G: float, branch: str) -> bool:
        """True if ``f(v, V) = G`` has a root on the branch: AB ``(f(0+), f_max]``, CD ``[f_min, inf)``."""
        lo, hi = self.level_range(branch)
        return (lo < G <= hi) if branch == "AB" else (lo <= G < hi)

    def level_range(self, branch: str) -> tuple[float, float]:
        """Range of levels ``G = F(1 - cos θ)`` for which the branch has a root."""
        if branch == "AB":
            return (self.f_zero, cast(float, self.f_max) if self.has_folds else math.inf)
        self.branch_range(branch)  # raises unless branch is CD and the folds exist
        assert self.f_min is not None
        return (self.f_min, math.inf)


#: The folds of a law (:meth:`peelapprox.PeelForce.folds`): the same record.
Folds = BranchStructure


def find_folds(fn: Callable[[np.ndarray, int], np.ndarray], V: float, window: tuple[float, float],
               domain: tuple[float, float], label: str, density: int) -> BranchStructure:
    """The folds and landings (:class:`BranchStructure`) of the law ``fn`` at pull speed V (module docstring).

    Parameters
    ----------
    fn : callable
        ``fn(v, order)``: f (order 0) or f' (order 1) at the peel velocities v [m/s] (an array).
    V : float
        The pull speed [m/s], recorded in the result.
    window : (lo, hi)
        Where to look for the extrema [m/s].
    domain : (lo, hi)
        Where the law may be evaluated [m/s], the range of the landings (contains the window).
    label : str
        The law, for messages.
    density : int
        Grid points per unit of ln v (at least 2001 in all).
    """
    wlo, whi = math.log(window[0]), math.log(window[1])
    n = max(2001, int(density * (whi - wlo)) + 1)
    w = np.linspace(wlo, whi, n)
    vg = np.clip(np.exp(w), window[0], window[1])

    def at(x: float, order: int) -> float:
        v = min(max(math.exp(x), domain[0]), domain[1])
        return float(fn(np.array([v]), order)[0])

    d = fn(vg, 1)
    if not np.all(np.isfinite(d)):
        i = int(np.flatnonzero(~np.isfinite(d))[0])
        raise ValueError(f"the peel-force law {label} has f' = {d[i]} at v={vg[i]!r} m/s, V={V!r} m/s")
    # Brent's method in units of the law's own size: its inverse quadratic steps multiply three values of the
    # function, which underflow for a law scaled by 1e-100 (f' ~ 1e-108: products ~ 1e-324), and it then stalls
    # ("failed to converge").  Dividing by the power of two nearest the largest |f'| (or |f|) makes the search
    # scale-free, and bitwise the same as before for an ordinary law (a power of two scales without rounding).
    d_scale = _power_of_two(float(np.max(np.abs(d))))
    nz = np.flatnonzero(d != 0)
    if nz.size == 0:
        raise ValueError(f"the peel-force law {label} has f' = 0 throughout v in [{window[0]:g}, {window[1]:g}] m/s "
                         f"at V={V!r}: no branch structure")
    s = np.sign(d[nz])
    extrema = []
    for c in np.flatnonzero(s[:-1] != s[1:]):
        i, j = nz[c], nz[c + 1]
        x = _root(lambda x: at(x, 1) / d_scale, w[i], w[j], label, V)
        v = min(max(math.exp(x), domain[0]), domain[1])
        extrema.append(("max" if s[c] > 0 else "min", v, at(math.log(v), 0)))
    kinds = [k for k, _, _ in extrema]
    if not kinds:
        if s[0] > 0:
            return BranchStructure(V, False)
        raise ValueError(f"the peel-force law {label} decreases in v throughout [{window[0]:g}, {window[1]:g}] m/s "
                         f"at V={V!r}: no stable branch")
    if kinds != ["max", "min"]:
        found = ", ".join(f"a local {k} at v={v:.6g} m/s (f={fv:.6g} N)" for k, v, fv in extrema)
        raise ValueError(f"the peel-force law {label} must have exactly one local maximum followed by one local "
                         f"minimum in v at V={V!r} (stick-slip) or none (no stick-slip); found {found}")
    (_, v_max, f_max), (_, v_min, f_min) = extrema
    lo, hi = math.log(domain[0]), math.log(domain[1])
    f_scale = _power_of_two(max(abs(f_max), abs(f_min)))
    v_land_cd = None
    if at(hi, 0) > f_max:
        v_land_cd = math.exp(_root(lambda x: (at(x, 0) - f_max) / f_scale, math.log(v_min), hi, label, V))
    v_land_ab = None
    if at(lo, 0) < f_min:
        v_land_ab = math.exp(_root(lambda x: (at(x, 0) - f_min) / f_scale, lo, math.log(v_max), label, V))
    return BranchStructure(V, True, v_max, f_max, v_min, f_min, v_land_cd=v_land_cd, v_land_ab=v_land_ab)


def _power_of_two(x: float) -> float:
    """The power of two ``2^(e-1) <= x < 2^e`` (1.0 for 0 or a non-finite x; never overflows, even for the largest
    float)."""
    return math.ldexp(1.0, math.frexp(x)[1] - 1) if x > 0 and math.isfinite(x) else 1.0


def _root(g: Callable[[float], float], a: float, b: float, label: str, V: float) -> float:
    """Brent's method for ``g = 0`` on ``[a, b]`` (ln v; xtol 1e-15, rtol 4 ulp); a ValueError naming the law
    where it does not converge (a law too irregular to have well-defined folds), never scipy's RuntimeError."""
    try:
        return float(brentq(g, a, b, xtol=1e-15, rtol=_RTOL))
    except RuntimeError as exc:
        raise ValueError(f"the folds of the peel-force law {label} at V={V!r} m/s could not be located between "
                         f"v={math.exp(a):.6g} and {math.exp(b):.6g} m/s ({exc})") from None
