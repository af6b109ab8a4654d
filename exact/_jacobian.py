"""The Jacobian of the hybrid solver's desingularised field, for the tangent dynamics (saltation tangent,
periodic orbits).

The field (``exact._hybrid._field``) in the parameter s, state ``y = (τ, α, ω, u = ln v)``, with
``g = v f'(v) = df/du`` and ``F = f / q``, ``q = 1 + c(α)`` (CONSTR)::

    dτ/ds = g,   dα/ds = g α̇,   dω/ds = g ω̇,   du/ds = Ġ = F α̇ c' + Ḟ q
    α̇ = ω - v/R (FLOW1),   ω̇ = -F R c / I (FLOW2),   Ḟ = k (V - v + c (R ω - v)) (flow3)

Its derivatives by the chain rule, with ``g_u = v f' + v² f''``, ``F_α = -F c'/q``, ``F_u = g/q``,
``α̇_u = -v/R``, ``ω̇_α = -(R/I)(F_α c + F c')``, ``ω̇_u = -(R/I) c F_u``, ``Ḟ_α = k c' (R ω - v)``,
``Ḟ_ω = k c R``, ``Ḟ_u = -k v q``::

    ∂(dτ/ds)/∂u = g_u
    ∂(dα/ds)/∂ω = g,          ∂(dα/ds)/∂u = g_u α̇ + g α̇_u
    ∂(dω/ds)/∂α = g ω̇_α,      ∂(dω/ds)/∂u = g_u ω̇ + g ω̇_u
    ∂Ġ/∂α = F_α α̇ c' + F α̇ c'' + Ḟ_α q + Ḟ c'
    ∂Ġ/∂ω = F c' + Ḟ_ω q,     ∂Ġ/∂u = F_u α̇ c' + F c' α̇_u + Ḟ_u q

(no dependence on τ).  It replaces a central difference of the field, whose ~1e-9 relative noise the step
control of a tight tangent integration chased with ever smaller steps.  Tested against a central difference
of the field in tests/test_orbits.py.
"""

from __future__ import annotations

import numpy as np

from peelapprox.kernels import (
    LAW_FPP,
    M_GEOM,
    M_I,
    M_K,
    M_L,
    M_R,
    M_V,
    closure_d2,
    kernel,
    peel_force_fpp_jit,
)
from peelapprox.kernels import M_A as _M_A
from peelapprox.kernels import M_B as _M_B

__all__ = ["field_jacobian", "jacobian_law", "jacobian_paper"]


@kernel(inline="always")
def field_jacobian(y, p, v, f, fp, fpp, J):
    """The 4×4 Jacobian ``J`` of the field at ``y`` given ``v = e^u`` and ``f, f', f''`` at v (module docstring)."""
    c, dc, ddc = closure_d2(y[1], p[M_GEOM], p[M_R], p[M_L])
    R, I, k, V = p[M_R], p[M_I], p[M_K], p[M_V]
    q = 1.0 + c
    g = v * fp
    gu = g + v * v * fpp
    F = f / q
    F_a = -F * dc / q
    F_u = g / q
    ad = y[2] - v / R
    ad_u = -v / R
    wd = -F * R * c / I
    wd_a = -(R / I) * (F_a * c + F * dc)
    wd_u = -(R / I) * c * F_u
    Fd = k * (V - v + c * (R * y[2] - v))
    Fd_a = k * dc * (R * y[2] - v)
    Fd_w = k * c * R
    Fd_u = -k * v * q
    for i in range(4):
        for j in range(4):
            J[i, j] = 0.0
    J[0, 3] = gu
    J[1, 2] = g
    J[1, 3] = gu * ad + g * ad_u
    J[2, 1] = g * wd_a
    J[2, 3] = gu * wd + g * wd_u
    J[3, 1] = F_a * ad * dc + F * ad * ddc + Fd_a * q + Fd * dc
    J[3, 2] = F * dc + Fd_w * q
    J[3, 3] = F_u * ad * dc + F * dc * ad_u + Fd_u * q


@kernel(inline="always")
def jacobian_paper(y, p, J):
    """:func:`field_jacobian` with the paper's law fvV inlined (``p[M_B], p[M_A]``)."""
    v = np.exp(y[3])
    f, fp, fpp = peel_force_fpp_jit(v, p[_M_B], p[_M_A])
    field_jacobian(y, p, v, f, fp, fpp, J)


@kernel(inline="always")
def jacobian_law(y, P, J):
    """:func:`field_jacobian` for the law of ``P = (p, law, coef)`` (``law(v, coef, LAW_FPP)``)."""
    p, law, coef = P
    v = np.exp(y[3])
    f, fp, fpp = law(v, coef, LAW_FPP)
    field_jacobian(y, p, v, f, fp, fpp, J)
