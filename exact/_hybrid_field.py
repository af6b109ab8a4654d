"""The hybrid solver's desingularised field and pull force, the paper's law fvV inlined: the field
d(τ, α, ω, u)/ds of CONSTR solved for F with u = ln v and dt/ds = v f'(v) (its derivation: the module docstring of
``exact/_hybrid.py``, whose compiled loop, the saltation tangent and ``exact.hybrid_field`` all use it; the
law-as-argument variants are bound in ``exact/_hybrid_driver.py``)."""

from __future__ import annotations

import numpy as np

from peelapprox.kernels import (
    M_A,
    M_B,
    M_GEOM,
    M_I,
    M_K,
    M_L,
    M_R,
    M_V,
    closure,
    constraint_rate,
    kernel,
    peel_force_fp_jit,
    peel_force_lnv_jit,
    slow_rates,
)


@kernel(inline="always")
def _closure(alpha, p):
    return closure(alpha, p[M_GEOM], p[M_R], p[M_L])


@kernel
def pull_force(alpha, v, p):
    """F = f(v, V) / (1 + c(α))  (CONSTR solved for F), the paper's law inlined (fvV, ``p[M_B], p[M_A]``)."""
    f, _ = peel_force_fp_jit(v, p[M_B], p[M_A])
    c, _ = _closure(alpha, p)
    return f / (1.0 + c)


@kernel(inline="always")
def _field(y, p, v, f, g, out):
    """The field at ``y`` given ``v = e^u``, ``f(v)`` and ``g = v f'(v)`` (whichever law gave them)."""
    if not (v > 0.0):  # trial stage left the model's domain (v underflowed): poison the step
        for i in range(4):
            out[i] = np.nan
        return
    c, dc = _closure(y[1], p)
    if not (1.0 + c > 0.0):  # the peel geometry degenerates (alpha -> -pi/2): outside the domain as well
        for i in range(4):
            out[i] = np.nan
        return
    F = f / (1.0 + c)
    ad, wd, Fd = slow_rates(y[1], y[2], F, v, c, p[M_V], p[M_I], p[M_K], p[M_R])
    (Gd,) = constraint_rate(F, Fd, c, dc, ad)
    out[0] = g
    out[1] = g * ad
    out[2] = g * wd
    out[3] = Gd  # d(ln v)/ds = (dv/ds)/v = Ġ


@kernel
def _rhs(y, p, out):
    """Desingularised vector field d(τ, α, ω, u)/ds, u = ln v, dt/ds = v f'(v) (module docstring), the paper's law
    inlined: the field of the saltation tangent (``exact._tangent``) and of ``exact.hybrid_field``."""
    v, f, g = peel_force_lnv_jit(y[3], p[M_B], p[M_A])  # g = v f'(v) = df/d(ln v) = dt/ds
    _field(y, p, v, f, g, out)
