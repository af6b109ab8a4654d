"""The peel force f(v, V) (Eq. fvV), its derivatives, folds and branch inverses.

This is the one module that evaluates the peel force.  The formulas themselves
are generated from the sympy source (:mod:`peelapprox._symbolic`) into
:mod:`peelapprox._generated`; here they are wrapped as

* vectorised numpy functions with argument checking (:func:`peel_force`,
  :func:`peel_force_derivative`),
* numba-compiled scalar kernels (:data:`peel_force_fp_jit`,
  :data:`peel_force_fpp_jit`) for the solvers,
* the branch structure of ``f(·, V)``: the folds ``(v_max, f_max)`` (local
  maximum, end of the slow stable branch AB) and ``(v_min, f_min)`` (local
  minimum, start of the fast stable branch CD), found once per V and cached
  (:func:`branch_structure`),
* the inverse of f on each stable branch (:func:`branch_inverse`), accurate
  for ``v << 1`` because it solves in ``ln v``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from scipy.optimize import brentq

from . import _generated as _g
from ._jit import kernel
from ._params import PARAM_RANGES, STATE_RANGES
from .validate import choice, in_range, reals

__all__ = [
    "peel_force",
    "peel_force_derivative",
    "peel_force_coefficients",
    "peel_force_fp_jit",
    "peel_force_fpp_jit",
    "peel_force_lnv_jit",
    "BranchStructure",
    "branch_structure",
    "branch_inverse",
    "FixedPoint",
    "fixed_point",
    "BRANCHES",
]

#: Names of the stable branches, indexed by the integer codes used in arrays.
BRANCHES = ("AB", "CD")

peel_force_coefficients = _g.peel_force_coefficients

#: numba-compiled scalar ``(f, f')`` at ``v`` given ``(b, A) = peel_force_coefficients(V)``.
peel_force_fp_jit = kernel(inline="always")(_g.peel_force_fp)
#: numba-compiled scalar ``(f, f', f'')``.
peel_force_fpp_jit = kernel(_g.peel_force_fpp)
#: numba-compiled scalar ``(v, f, v f')`` at ``ln v`` (the hybrid solver's state variable; no log needed).
peel_force_lnv_jit = kernel(inline="always")(_g.peel_force_lnv)

# Bracket used to search for folds and roots: f' -> +inf as v -> 0 and the
# exponential term dominates for large v, so every sign change lies inside.
_V_LO = 1e-12
_V_HI = 300.0  # exp(300/11) ~ 7e11: f is astronomically large there


def _check_V(V) -> float:
    """The pull speed V in :data:`peelapprox.PARAM_RANGES` (the law's valid range, one bound for all)."""
    return in_range("V", V, *PARAM_RANGES["V"])


def _check_v(v) -> np.ndarray:
    """Peel velocities in ``STATE_RANGES["v"]`` = (1e-150, 1e3] m/s (f has a v^0.15 branch point at 0)."""
    return reals("v", v, *STATE_RANGES["v"], lo_open=True)


def peel_force(v, V):
    """Peel force f(v, V) of Eq. (fvV) [N].

    ``f = 400 v^0.35 + 110 v^0.15 + 130 e^(v/11) - 2 V^1.5
    - (415 - 45 V^0.4 - 0.35 V^2.15) v^0.5``

    Parameters
    ----------
    v : array_like
        Peel (rupture) velocity [m/s], ``v > 0``.
    V : float
        Pull speed [m/s], ``V > 0``.

    Returns
    -------
    ndarray or float
        Same shape as ``v``.
    """
    b, A = peel_force_coefficients(_check_V(V))
    f, _ = _g.peel_force_fp(_check_v(v), b, A)
    return f[()] if np.ndim(f) == 0 else f


def peel_force_derivative(v, V, order: int = 1):
    """``∂ᵏf/∂vᵏ (v, V)`` for ``order`` k in {0, 1, 2} [N s^k/m^k]."""
    order = choice("order", order, (0, 1, 2))
    b, A = peel_force_coefficients(_check_V(V))
    out = _g.peel_force_fpp(_check_v(v), b, A)[order]
    return out[()] if np.ndim(out) == 0 else out


def _fp(v, b, A):
    return _g.peel_force_fp(v, b, A)[1]


def _fpp(v, b, A):
    return _g.peel_force_fpp(v, b, A)[2]


@dataclass(frozen=True)
class BranchStructure:
    """Stable branches and folds of ``f(·, V)`` for one pull speed.

    Attributes
    ----------
    V : float
        Pull speed [m/s].
    has_folds : bool
        True inside the stick-slip window (f has a local max and min).  When
        False, f is increasing in v, there is one stable branch (called AB,
        spanning ``v in (0, inf)``) and no jumps are possible.
    v_max, f_max : float or None
        Fold at the end of AB (local maximum of f).
    v_min, f_min : float or None
        Fold at the start of CD (local minimum of f).
    v_inflection : float
        The minimiser of f' (``f'' = 0``), between the folds when they exist.
    f_zero : float
        ``f(0+, V) = 130 - 2 V^1.5``: below this pull level AB has no root.
    v_land_cd : float or None
        Where an AB→CD jump lands: the CD root of ``f = f_max``.
    v_land_ab : float or None
        Where a CD→AB jump lands: the AB root of ``f = f_min``; None if
        ``f_min <= f_zero`` (the orbit would have nowhere to land).
    v_breakdown : float
        The AB velocity where ``f(v, V) - f(0+, V) = BREAKDOWN_LEVEL``
        (``1e-10 max(|f(0+)|, 1 N)``): a level this close to ``f(0+)`` is
        f(0+) to within the rounding of the solvers' arithmetic, so CONSTR
        has no resolvable root above it (the model's breakdown criterion,
        used by ``exact.simulate``).  Since ``f - f(0+) ≈ 110 v^0.15`` at
        small v, it is ~1e-67 m/s for every V: far below any physical
        speed, reached only where the level really falls to f(0+).
    """

    V: float
    has_folds: bool
    v_max: float | None
    f_max: float | None
    v_min: float | None
    f_min: float | None
    v_inflection: float
    f_zero: float
    v_land_cd: float | None
    v_land_ab: float | None
    v_breakdown: float = 0.0
    # The fold fields (v_max, f_max, v_min, f_min, v_land_cd) are floats exactly when has_folds
    # (_folds_and_landings sets them together; v_land_ab may stay None): below, the casts in
    # ``... if has_folds else ...`` and the asserts after a has_folds guard state that for the type checker.

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


def branch_structure(V: float) -> BranchStructure:
    """Folds, inflection and landing velocities of ``f(·, V)``; cached per V.

    The folds are the two roots of ``f'(v, V) = 0`` on either side of the
    unique minimiser of ``f'`` (root of ``f''``), each located by Brent's
    method to ``xtol = 4 ulp``.  Robust near the cusp where the folds merge
    (``V ≈ 5.2``): no grid is used for the folds themselves.

    Parameters
    ----------
    V : float
        Pull speed [m/s] (> 0).

    Returns
    -------
    BranchStructure

    Raises
    ------
    ValueError
        If V is outside ``PARAM_RANGES["V"]`` (TypeError if not a number).
    """
    return _branch_structure(_check_V(V))


#: Relative distance of the level ``F(1 - cos θ)`` above ``f(0+, V)`` (times ``max(|f(0+)|, 1 N)``) at which the
#: model breaks down (BranchStructure.v_breakdown).
BREAKDOWN_LEVEL = 1e-10


@functools.lru_cache(maxsize=512)
def _branch_structure(V: float) -> BranchStructure:
    bs = _folds_and_landings(V)
    b, A = peel_force_coefficients(V)
    margin = BREAKDOWN_LEVEL * max(abs(bs.f_zero), 1.0)
    w_hi = math.log(cast(float, bs.v_max)) if bs.has_folds else math.log(_V_HI)
    g = lambda w: _g.peel_force_fp(math.exp(w), b, A)[0] - bs.f_zero - margin  # noqa: E731
    v_br = math.exp(brentq(g, -690.0, w_hi, xtol=1e-12, rtol=4 * np.finfo(float).eps))
    return dataclasses.replace(bs, v_breakdown=v_br)


def _folds_and_landings(V: float) -> BranchStructure:
    b, A = peel_force_coefficients(V)
    # f'' < 0 for small v (the -v^-1.85 term) and > 0 for large v (exp term):
    # locate its sign changes on a log grid and require exactly one.
    grid = np.logspace(math.log10(_V_LO), math.log10(_V_HI), 4001)
    s = np.sign(_g.peel_force_fpp(grid, b, A)[2])
    idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
    if len(idx) != 1:
        raise RuntimeError(f"f''(v, V={V}) has {len(idx)} sign changes on ({_V_LO}, {_V_HI}); expected one")
    i = idx[0]
    v_inf = brentq(_fpp, grid[i], grid[i + 1], args=(b, A), xtol=1e-300, rtol=4 * np.finfo(float).eps)
    f_zero = float(130.0 + b)
    if _fp(v_inf, b, A) >= 0:
        return BranchStructure(V, False, None, None, None, None, v_inf, f_zero, None, None)
    kw = dict(args=(b, A), xtol=1e-300, rtol=4 * np.finfo(float).eps)
    v_max = brentq(_fp, _V_LO, v_inf, **kw)
    v_min = brentq(_fp, v_inf, _V_HI, **kw)
    f_max = float(_g.peel_force_fp(v_max, b, A)[0])
    f_min = float(_g.peel_force_fp(v_min, b, A)[0])
    tmp = BranchStructure(V, True, v_max, f_max, v_min, f_min, v_inf, f_zero, None, None)
    v_land_cd = _invert(f_max, tmp, "CD", b, A)
    v_land_ab = _invert(f_min, tmp, "AB", b, A) if f_min > f_zero else None
    return BranchStructure(V, True, v_max, f_max, v_min, f_min, v_inf, f_zero, v_land_cd, v_land_ab)


def _invert(G: float, bs: BranchStructure, branch: str, b: float, A: float) -> float:
    """Velocity v on ``branch`` with ``f(v, V) = G`` for one level, the branch structure already at hand.

    The scalar core of :func:`branch_inverse` (offered to the other packages as
    :func:`peelapprox.kernels.branch_inverse_at`), for callers that invert many levels at one pull speed:
    no argument is checked or converted here beyond the level's range.

    Parameters
    ----------
    G : float
        Level of the pull side of CONSTR, ``G = F(1 - cos θ)`` [N].
    bs : BranchStructure
        ``branch_structure(V)`` of the pull speed V.
    branch : {"AB", "CD"}
        The slow branch ``(0, v_max]`` or the fast branch ``[v_min, inf)``; must be one of the two.
    b, A : float
        ``peel_force_coefficients(V)`` of the same V.

    Returns
    -------
    float
        v [m/s] to ~4 ulp (Brent's method; on AB in ``w = ln v``, so small v keep full relative precision);
        exactly ``v_max`` at ``G = f_max`` on AB and ``v_min`` at ``G = f_min`` on CD.

    Raises
    ------
    ValueError
        If ``G`` is outside the branch's level range (AB: ``(f(0+), f_max]``, CD: ``[f_min, inf)``),
        naming the range, or if ``G`` is within rounding of ``f(0+, V)`` on AB (v would underflow).
    """
    if not bs.has_root(G, branch):
        lo, hi = bs.level_range(branch)
        raise ValueError(
            f"level G={G!r} has no root on branch {branch} for V={bs.V}: valid range is "
            f"{'(' if branch == 'AB' else '['}{lo}, {hi}{']' if branch == 'AB' else ')'}"
        )
    if branch == "AB":
        if bs.has_folds and G == bs.f_max:
            assert bs.v_max is not None
            return bs.v_max
        # solve in w = ln v: f is monotone and smooth in w down to v ~ 1e-300
        w_hi = math.log(cast(float, bs.v_max)) if bs.has_folds else math.log(_V_HI)
        w_lo = -690.0
        g = lambda w: _g.peel_force_fp(math.exp(w), b, A)[0] - G  # noqa: E731
        if g(w_lo) >= 0:
            raise ValueError(f"level G={G!r} is within rounding of f(0+, V)={bs.f_zero}: v on AB underflows")
        return math.exp(brentq(g, w_lo, w_hi, xtol=1e-15, rtol=4 * np.finfo(float).eps))
    assert bs.v_min is not None  # CD: has_root above raised unless the folds exist
    if G == bs.f_min:
        return bs.v_min
    g = lambda x: _g.peel_force_fp(x, b, A)[0] - G  # noqa: E731
    hi_v = 2.0 * bs.v_min
    while g(hi_v) < 0:
        hi_v *= 2.0
    return brentq(g, bs.v_min, hi_v, xtol=1e-300, rtol=4 * np.finfo(float).eps)


def branch_inverse(G, V: float, branch: str):
    """Velocity v on a stable branch with ``f(v, V) = G``.

    Parameters
    ----------
    G : float or array_like
        Level(s) of the pull side of CONSTR, ``G = F(1 - cos θ)`` [N].
    V : float
        Pull speed [m/s].
    branch : {"AB", "CD"}
        The slow branch ``(0, v_max]`` or the fast branch ``[v_min, inf)``.

    Returns
    -------
    float or ndarray
        v [m/s], relative accuracy ~4 ulp (AB is solved in ``ln v``, so
        ``v ≈ 2e-3`` and below keep full relative precision).

    Raises
    ------
    ValueError
        If ``G`` is outside the branch's level range
        (AB: ``(f(0+), f_max]``, CD: ``[f_min, inf)``), naming the range.
    """
    bs = branch_structure(V)
    bs.branch_range(choice("branch", branch, BRANCHES))
    b, A = peel_force_coefficients(bs.V)
    Ga = reals("G", G)
    out = np.array([_invert(float(x), bs, branch, b, A) for x in Ga.ravel()]).reshape(Ga.shape)
    return float(out) if out.ndim == 0 else out


@dataclass(frozen=True)
class FixedPoint:
    """The steady state ``α = 0, ω = V/R, v = V, F = f(V, V)`` (Sec. II).

    ``stable`` is ``f'(V, V) > 0``: the paper's Hopf criterion.
    """

    alpha: float
    omega: float
    F: float
    v: float
    fprime: float
    stable: bool


def fixed_point(V: float, R: float = 0.1) -> FixedPoint:
    """Fixed point of FLOW1–flow3 with CONSTR and its stability (``f'(V,V) > 0``).

    ``V`` and ``R`` must lie in :data:`peelapprox.PARAM_RANGES`.
    """
    V = _check_V(V)
    R = in_range("R", R, *PARAM_RANGES["R"])
    f, fp = _g.peel_force_fp(V, *peel_force_coefficients(V))
    return FixedPoint(0.0, V / R, float(f), V, float(fp), bool(fp > 0))
