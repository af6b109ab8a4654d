"""The peel-force law as data: the one calling convention (ABI) by which a compiled driver evaluates ``f(v)``.

A driver compiled for the law type :data:`LAW_TYPE` takes the law as a first-class function argument
``law`` and its coefficients as a float vector ``coef``, and evaluates the peel force (fvV for the paper's law)
as ``law(x, coef, form)``; it is compiled once for that type, so a new law or new coefficients recompile
nothing (docs/design-peel-force-laws.md, issue 15).  The V-dependence of a law is evaluated in Python when a
run is packed (V is constant during a run): ``coef`` of the paper's law is ``(b, A) = peel_force_coefficients(V)``.

The three forms (``form``, an int64):

=============  ===========  ==================================================================================
form           ``x``        returns
=============  ===========  ==================================================================================
``LAW_LNV``    ``u = ln v``  ``(v, f, v f'(v))``: the hybrid solver's field works in u and ``dt/ds = v f'``
``LAW_FP``     ``v``         ``(f, f'(v), NaN)``: the pull force of CONSTR, Newton on v
``LAW_FPP``    ``v``         ``(f, f', f'')``: the saltation tangent and the fold finders
=============  ===========  ==================================================================================

A law is any function compiled by :func:`peelapprox._jit.kernel` with ``signature=LAW_SIG`` (cached on disk: a
compiled law costs one compilation per machine).  Registered here (:data:`LAWS`, keyed by the law's kind):

* ``"paper"`` -- :func:`paper_law`, fvV of De, Maybhate & Ananthakrishna (2004) through exactly the generated
  code the drivers inline (:mod:`peelapprox._generated`: ``peel_force_lnv``, ``peel_force_fp``,
  ``peel_force_fpp``), so a driver taking it as an argument gives bitwise the numbers of the inlined law;
* ``"cubic_v"`` -- :func:`cubic_v_law`, ``f = a + b v - c v² + d v³`` with ``coef = (a, b, c, d)``: the second
  law of the ABI, whose folds are closed forms (:func:`cubic_v_structure`); it shows that a second law costs no
  driver compilation and is the tests' independent physics check.  The literature families (power-law
  branches, the Hong-Yue N shape in ln v, tabulated curves) and the general fold finder ``law.folds(V)`` are
  the ``PeelForce`` object's (issue 15, the ``law`` branch).
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from scipy.optimize import brentq

from ._jit import kernel
from ._peelforce import (
    BREAKDOWN_LEVEL,
    BranchStructure,
    peel_force_coefficients,
    peel_force_fp_jit,
    peel_force_fpp_jit,
    peel_force_lnv_jit,
)

__all__ = ["LAW_SIG", "LAW_TYPE", "LAW_LNV", "LAW_FP", "LAW_FPP", "LAWS", "paper_law", "cubic_v_law",
           "paper_coefficients", "cubic_v_structure"]

#: ``law(x, coef, form) -> (float, float, float)`` (module docstring).
LAW_SIG = types.UniTuple(types.float64, 3)(types.float64, types.float64[::1], types.int64)
#: The type of a driver's law argument.
LAW_TYPE = types.FunctionType(LAW_SIG)
#: The forms of a law call (module docstring).
LAW_LNV, LAW_FP, LAW_FPP = 0, 1, 2


@kernel(signature=LAW_SIG)
def paper_law(x, coef, form):
    """fvV at ``x`` in the form ``form`` with ``coef = (b, A) = peel_force_coefficients(V)``: the generated
    ``peel_force_lnv`` / ``peel_force_fp`` / ``peel_force_fpp`` unchanged (the inlined law's arithmetic)."""
    if form == LAW_LNV:
        return peel_force_lnv_jit(x, coef[0], coef[1])
    if form == LAW_FP:
        f, fp = peel_force_fp_jit(x, coef[0], coef[1])
        return f, fp, np.nan
    return peel_force_fpp_jit(x, coef[0], coef[1])


@kernel(signature=LAW_SIG)
def cubic_v_law(x, coef, form):
    """``f = a + b v - c v² + d v³`` at ``x`` in the form ``form``, ``coef = (a, b, c, d)``."""
    a, b, c, d = coef[0], coef[1], coef[2], coef[3]
    v = np.exp(x) if form == LAW_LNV else x
    f = a + v * (b + v * (d * v - c))
    fp = b + v * (3.0 * d * v - 2.0 * c)
    if form == LAW_LNV:
        return v, f, v * fp
    if form == LAW_FP:
        return f, fp, np.nan
    return f, fp, 6.0 * d * v - 2.0 * c


#: The compiled laws by kind (module docstring).
LAWS = {"paper": paper_law, "cubic_v": cubic_v_law}


def paper_coefficients(V: float) -> np.ndarray:
    """``coef`` of :func:`paper_law` for the pull speed V: ``[b, A] = peel_force_coefficients(V)``."""
    b, A = peel_force_coefficients(V)
    return np.array([b, A], dtype=float)


def cubic_v_structure(coef, V: float) -> BranchStructure:
    """Folds and landing velocities of :func:`cubic_v_law` (closed forms; the law does not depend on V).

    ``f' = b - 2 c v + 3 d v²`` has the roots ``v_max < v_min`` (the folds); ``f - f_max`` has the double root
    ``v_max`` and, as the roots of a monic cubic sum to ``c/d``, the third root ``c/d - 2 v_max`` (where an
    AB→CD jump lands); likewise ``c/d - 2 v_min`` for CD→AB.  ``f(0+) = a``; the breakdown velocity solves
    ``f - a = BREAKDOWN_LEVEL max(|a|, 1)`` in ln v as for the paper's law.

    Parameters
    ----------
    coef : sequence of 4 floats
        ``(a, b, c, d)``, each > 0, with ``c² > 3 b d`` (two folds) and ``f_min > a`` (CD→AB jumps land).
    V : float
        Pull speed [m/s] (recorded in the result).

    Returns
    -------
    BranchStructure

    Raises
    ------
    ValueError
        Naming ``coef`` and the condition it breaks.
    """
    a, b, c, d = (float(x) for x in np.asarray(coef, dtype=float).reshape(4))
    if not (a > 0 and b > 0 and c > 0 and d > 0 and c * c > 3.0 * b * d):
        raise ValueError(f"coef=(a, b, c, d)={(a, b, c, d)} must be positive with c**2 > 3 b d (two folds)")
    r = math.sqrt(c * c - 3.0 * b * d)
    v_max, v_min = (c - r) / (3.0 * d), (c + r) / (3.0 * d)

    def f(v: float) -> float:
        return a + v * (b + v * (d * v - c))

    f_max, f_min = f(v_max), f(v_min)
    if not f_min > a:
        raise ValueError(f"coef={(a, b, c, d)} gives f_min={f_min} <= f(0+)={a}: CD->AB jumps cannot land")
    margin = BREAKDOWN_LEVEL * max(abs(a), 1.0)
    v_br = math.exp(brentq(lambda w: f(math.exp(w)) - a - margin, -690.0, math.log(v_max), xtol=1e-12,
                           rtol=4 * np.finfo(float).eps))
    return BranchStructure(V=float(V), has_folds=True, v_max=v_max, f_max=f_max, v_min=v_min, f_min=f_min,
                           v_inflection=c / (3.0 * d), f_zero=a, v_land_cd=c / d - 2.0 * v_max,
                           v_land_ab=c / d - 2.0 * v_min, v_breakdown=v_br)
