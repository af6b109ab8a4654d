"""The peel-force law as data: the one calling convention (ABI) by which a compiled driver evaluates ``f(v)``.

A driver compiled for the law type :data:`LAW_TYPE` takes the law as a first-class function argument
``law`` and its coefficients as a float vector ``coef``, and evaluates the peel force (fvV for the paper's law)
as ``law(x, coef, form)``; it is compiled once for that type, so a new law or new coefficients recompile
nothing (docs/design-peel-force-laws.md).  The V-dependence of a law is evaluated in Python when a
run is packed (V is constant during a run): ``coef`` of the paper's law is ``(b, A) = peel_force_coefficients(V)``.

The three forms (``form``, an int64):

=============  ===========  ==================================================================================
form           ``x``        returns
=============  ===========  ==================================================================================
``LAW_LNV``    ``u = ln v``  ``(v, f, v f'(v))``: the hybrid solver's field works in u and ``dt/ds = v f'``
``LAW_FP``     ``v``         ``(f, f'(v), NaN)``: the pull force of CONSTR, Newton on v
``LAW_FPP``    ``v``         ``(f, f', f'')``: the saltation tangent and the fold finders
=============  ===========  ==================================================================================

A law is any function compiled by :func:`peelapprox._compiled._jit.kernel` with ``signature=LAW_SIG`` (cached on disk: a
compiled law costs one compilation per machine).  :func:`paper_law` (:data:`LAWS`) is fvV of De, Maybhate &
Ananthakrishna (2004) through exactly the generated code the drivers inline (:mod:`peelapprox._compiled._generated`:
``peel_force_lnv``, ``peel_force_fp``, ``peel_force_fpp``), so a driver taking it as an argument gives bitwise
the numbers of the inlined law.  The other laws are generated from their sympy form
(:mod:`peelapprox.law._kernels`: the families from :mod:`peelapprox.law._generated`, an expression in the user
cache) or are the table kernel (:mod:`peelapprox.law._table_jit`); :func:`peelapprox.law._compiled.compiled_law`
picks the kernel of a :class:`peelapprox.PeelForce`.
"""

from __future__ import annotations

import numpy as np
from numba import types

from .._compiled._jit import kernel
from ._paper import (
    peel_force_coefficients,
    peel_force_fp_jit,
    peel_force_fpp_jit,
    peel_force_lnv_jit,
)

__all__ = ["LAW_SIG", "LAW_TYPE", "LAW_LNV", "LAW_FP", "LAW_FPP", "LAWS", "pack_inlined", "pack_law", "paper_law",
           "paper_coefficients", "unused_law"]

#: ``law(x, coef, form) -> (float, float, float)`` (module docstring).
LAW_SIG = types.UniTuple(types.float64, 3)(types.float64, types.float64[::1], types.int64)
#: The type of a driver's law argument.
LAW_TYPE = types.FunctionType(LAW_SIG)
#: The forms of a law call (module docstring).
LAW_LNV, LAW_FP, LAW_FPP = 0, 1, 2


@kernel(signature=LAW_SIG, lazy=True)  # compiled on first use: the default drivers inline fvV instead
def paper_law(x, coef, form):
    """fvV at ``x`` in the form ``form`` with ``coef = (b, A) = peel_force_coefficients(V)``: the generated
    ``peel_force_lnv`` / ``peel_force_fp`` / ``peel_force_fpp`` unchanged (the inlined law's arithmetic)."""
    if form == LAW_LNV:
        return peel_force_lnv_jit(x, coef[0], coef[1])
    if form == LAW_FP:
        f, fp = peel_force_fp_jit(x, coef[0], coef[1])
        return f, fp, np.nan
    return peel_force_fpp_jit(x, coef[0], coef[1])


@kernel(signature=LAW_SIG, lazy=True)
def unused_law(x, coef, form):
    """The law argument of a driver with the paper's law inlined, which never calls it
    (:attr:`peelapprox.law._compiled.CompiledLaw.arg`): a trivial kernel of the law type, so that the default
    path does not compile :func:`paper_law` (a cold start compiles less)."""
    return np.nan, np.nan, np.nan


@kernel(inline="always")
def pack_inlined(p, law, coef):
    """What a field with the paper's law inlined receives from a driver copy: its parameter vector ``p`` (fvV
    reads ``p[M_B], p[M_A]``); ``law`` and ``coef`` unused (:func:`peelapprox._compiled._jit.rebind`)."""
    return p


@kernel(inline="always")
def pack_law(p, law, coef):
    """What a field taking the law as an argument receives from a driver copy: ``(p, law, coef)``."""
    return (p, law, coef)


#: The compiled laws by kind (module docstring).
LAWS = {"paper": paper_law}


def paper_coefficients(V: float) -> np.ndarray:
    """``coef`` of :func:`paper_law` for the pull speed V: ``[b, A] = peel_force_coefficients(V)``."""
    b, A = peel_force_coefficients(V)
    return np.array([b, A], dtype=float)
