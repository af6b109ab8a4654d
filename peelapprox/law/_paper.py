"""The paper's law fvV (Eq. fvV): its evaluation, branch structure and branch inverses, bitwise the 0.2 numbers.

The formulas are generated from the sympy source (:mod:`peelapprox._compiled._symbolic`) into
:mod:`peelapprox._compiled._generated`; here they are wrapped as vectorised numpy functions with argument checks
(:func:`peel_force`, :func:`peel_force_derivative`), numba kernels for the solvers (``peel_force_*_jit``),
the branch structure of ``f(·, V)`` (:func:`paper_structure`: folds by Brent's method either side of the
minimiser of f', cached per V) and the inverse of f on each stable branch (:func:`branch_inverse`, in
``ln v`` so that ``v << 1`` keeps its relative precision).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any, cast

import numpy as np

from .._brentq import brentq
from .._checks import choice, in_range, reals
from .._compiled import _generated as _g
from .._compiled._jit import kernel
from .._ranges import PARAM_RANGES, STATE_RANGES
from ._folds import BRANCHES, BREAKDOWN_LEVEL, BranchStructure

__all__ = [
    "peel_force",
    "peel_force_derivative",
    "peel_force_coefficients",
    "peel_force_fp_jit",
    "peel_force_fpp_jit",
    "peel_force_lnv_jit",
    "paper_structure",
    "paper_value_slope",
    "branch_inverse",
    "check_V",
]

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


def check_V(V: Any) -> float:
    """The pull speed V in :data:`peelapprox.PARAM_RANGES` (the law's valid range, one bound for all)."""
    return in_range("V", V, *PARAM_RANGES["V"])


def _check_v(v) -> np.ndarray:
    """Peel velocities in ``STATE_RANGES["v"]`` = (1e-150, 1e3] m/s (f has a v^0.15 branch point at 0)."""
    return reals("v", v, *STATE_RANGES["v"], lo_open=True)


def peel_force(v: Any, V: float) -> Any:
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
    b, A = peel_force_coefficients(check_V(V))
    f, _ = _g.peel_force_fp(_check_v(v), b, A)
    return f[()] if np.ndim(f) == 0 else f


def peel_force_derivative(v: Any, V: float, order: int = 1) -> Any:
    """``∂ᵏf/∂vᵏ (v, V)`` for ``order`` k in {0, 1, 2} [N s^k/m^k]."""
    order = choice("order", order, (0, 1, 2))
    b, A = peel_force_coefficients(check_V(V))
    out = _g.peel_force_fpp(_check_v(v), b, A)[order]
    return out[()] if np.ndim(out) == 0 else out


def paper_fp(v: float, V: float) -> float:
    """``f'(v, V)`` at a velocity and pull speed already checked: :func:`peel_force_derivative`'s arithmetic (the
    generated kernel on a 0-d float array) without its argument checks (bitwise its value), for callers that
    check once and evaluate per segment plan."""
    b, A = _g.peel_force_coefficients(float(V))
    return float(_g.peel_force_fpp(np.asarray(float(v)), b, A)[1])


def _fp(v, b, A):
    return _g.peel_force_fp(v, b, A)[1]


def _fpp(v, b, A):
    return _g.peel_force_fpp(v, b, A)[2]


def paper_structure(V: float) -> BranchStructure:
    """The :class:`BranchStructure` of fvV at V (every field; V checked); cached per V.

    The folds are the two roots of ``f'(v, V) = 0`` either side of the unique minimiser of ``f'`` (root of
    ``f''``), each by Brent's method to ``xtol = 4 ulp``: robust near the cusp (``V ≈ 5.2``), no grid for the
    folds themselves.  :func:`peelapprox.branch_structure` is the public face.
    """
    return _branch_structure(check_V(V))


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
        return BranchStructure(V, False, v_inflection=v_inf, f_zero=f_zero)
    kw: dict[str, Any] = dict(args=(b, A), xtol=1e-300, rtol=4 * np.finfo(float).eps)
    v_max = brentq(_fp, _V_LO, v_inf, **kw)
    v_min = brentq(_fp, v_inf, _V_HI, **kw)
    f_max = float(_g.peel_force_fp(v_max, b, A)[0])
    f_min = float(_g.peel_force_fp(v_min, b, A)[0])
    tmp = BranchStructure(V, True, v_max, f_max, v_min, f_min, v_inflection=v_inf, f_zero=f_zero)
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
        ``paper_structure(V)`` of the pull speed V.
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


def branch_inverse(G: Any, V: float, branch: str) -> Any:
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
    bs = paper_structure(V)
    bs.branch_range(choice("branch", branch, BRANCHES))
    b, A = peel_force_coefficients(bs.V)
    Ga = reals("G", G)
    out = np.array([_invert(float(x), bs, branch, b, A) for x in Ga.ravel()]).reshape(Ga.shape)
    return float(out) if out.ndim == 0 else out


def paper_value_slope(V: float) -> tuple[float, float]:
    """``(f, f')`` of fvV at the steady sliding ``v = V`` (the fixed point of :func:`peelapprox.fixed_point`)."""
    f, fp = _g.peel_force_fp(V, *peel_force_coefficients(V))
    return float(f), float(fp)
