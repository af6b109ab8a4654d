"""The peel front's compiled vector field (docs/peel-front.md, "Equations").

State ``y = (α, ω, E_AE, F_0 … F_{N-1}, v_0 … v_{N-1}, W_in, W_peel)`` with ``F_j = k u_j`` (the pull force the
whole tape would carry at strip j's stretch; the pull force is ``F = mean F_j = k ū``), ``v_j`` the local peel
velocity, ``E_AE`` the integrated acoustic emission, ``W_in = ∫ F̄ V dt`` the work of the pull and
``W_peel = ∫ N⁻¹ Σ f(v_j) v_j dt`` the energy dissipated at the peel front (the energy balance's integrals).
The mean ``(α̇, ω̇, F̄̇, v̄̇)`` is the tape-mass model's field (``tape_rhs`` of :mod:`peelapprox._compiled._generated`,
generated from :mod:`peelapprox._compiled._symbolic`) evaluated with the mean peel force ``f̄ = mean f(v_j)``: the same
code as the tape-mass model's, so N = 1 is that model.  Each strip adds its deviation from the mean::

    Ḟ_j = k (V + c (R ω - v̄) - v_j)
    v̇_j = v̄̇ + [(F_j - F̄) - (f(v_j) - f̄) - (κ/4) (Δ F)_j + (N Γ) (Δ v)_j] / m
    Ė_AE = Γ Σ_bonds (v_{j+1} - v_j)²

Δ is the discrete Laplacian (free or periodic ends); ``κ/4 = N k_c / k``.  The sympy derivation of these rates
from the front's Lagrangian and Rayleigh function is :mod:`peelapprox.front._symbolic` (a test compares them).
Cost: one pass over the strips for the means, one for the rates -- O(N), no N × N array.

A strip with ``v_j <= 0`` (a trial stage outside the law's domain) makes the whole field NaN: the DOP853 step
is then rejected and retried smaller (:mod:`peelapprox._compiled._dop853`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import types as _nb

from .._compiled import _generated as _g
from .._compiled._jit import compile_only, kernel
from .._compiled._model_jit import closure_d2
from .._packing import M_GEOM, M_I, M_K, M_L, M_R, M_V, N_M, model_block
from ..law import ALL_LAWS
from ..law._abi import LAW_FP, LAW_TYPE

__all__ = ["FQ_MASS", "FQ_N", "FQ_KC4", "FQ_NGAMMA", "FQ_GAMMA", "FQ_PERIODIC", "N_FQ", "FY_ALPHA", "FY_OMEGA",
           "FY_EAE", "FY_STRIPS", "N_FY_TAIL", "front_parameters", "front_rhs", "front_field", "front_state_size"]

#: Parameter vector: the model block, then m [kg], N, κ/4 = N k_c/k, N Γ [N s/m], Γ [N s/m], 1.0 if periodic.
FQ_MASS, FQ_N, FQ_KC4, FQ_NGAMMA, FQ_GAMMA, FQ_PERIODIC = range(N_M, N_M + 6)
N_FQ = N_M + 6
#: State layout: α, ω, E_AE, then the N forces F_j, then the N velocities v_j, then W_in and W_peel (the last two).
FY_ALPHA, FY_OMEGA, FY_EAE, FY_STRIPS = 0, 1, 2, 3
#: The components after the strips: W_in, W_peel (at ``size - 2`` and ``size - 1``).
N_FY_TAIL = 2

_tape_rhs = kernel(inline="always")(_g.tape_rhs)


def front_state_size(n: int) -> int:
    """Length of the state vector for N = n strips: ``5 + 2 n``."""
    return FY_STRIPS + 2 * n + N_FY_TAIL


def front_parameters(fp: Any) -> np.ndarray:
    """The parameter vector of :func:`front_rhs` for a :class:`~peelapprox.FrontParams` (module docstring)."""
    q = model_block(fp.base, N_FQ, ALL_LAWS)
    q[FQ_MASS], q[FQ_N] = fp.m, float(fp.N)
    q[FQ_KC4] = fp.N * fp.k_c / fp.base.k
    q[FQ_NGAMMA], q[FQ_GAMMA] = fp.N * fp.Gamma, fp.Gamma
    q[FQ_PERIODIC] = 1.0 if fp.ends == "periodic" else 0.0
    return q


@kernel(inline="always")
def _lap(x, j, n, periodic):
    """``(Δx)_j`` of the n-vector ``x``: ``x_{j+1} - 2 x_j + x_{j-1}``, a missing neighbour dropped (free ends)
    or wrapped (periodic)."""
    s = 0.0
    if j > 0:
        s += x[j - 1] - x[j]
    elif periodic and n > 1:
        s += x[n - 1] - x[j]
    if j < n - 1:
        s += x[j + 1] - x[j]
    elif periodic and n > 1:
        s += x[0] - x[j]
    return s


@kernel(nrt=False)
def front_rhs(y, P, out):
    """The front's field at ``y`` into ``out`` (module docstring); ``P = (q, law, coef)``."""
    q, law, coef = P
    n = int(q[FQ_N])
    periodic = q[FQ_PERIODIC] != 0.0
    Fs = y[FY_STRIPS:FY_STRIPS + n]
    vs = y[FY_STRIPS + n:FY_STRIPS + 2 * n]
    dF = out[FY_STRIPS:FY_STRIPS + n]
    dv = out[FY_STRIPS + n:FY_STRIPS + 2 * n]
    sF = 0.0
    sv = 0.0
    sf = 0.0
    sfv = 0.0
    for j in range(n):
        v = vs[j]
        if not v > 0.0:
            for i in range(out.shape[0]):
                out[i] = np.nan
            return
        f, _, _ = law(v, coef, LAW_FP)
        dv[j] = f  # kept here until the second pass
        sF += Fs[j]
        sv += v
        sf += f
        sfv += f * v
    Fm, vm, fm = sF / n, sv / n, sf / n
    c, dc, _ = closure_d2(y[FY_ALPHA], q[M_GEOM], q[M_R], q[M_L])
    r = _tape_rhs(y[FY_ALPHA], y[FY_OMEGA], Fm, vm, q[M_V], c, dc, fm, q[FQ_MASS], q[M_I], q[M_K], q[M_R])
    out[FY_ALPHA] = r[0]
    out[FY_OMEGA] = r[1]
    k, m, kc4, ng = q[M_K], q[FQ_MASS], q[FQ_KC4], q[FQ_NGAMMA]
    shift = q[M_V] + c * (q[M_R] * y[FY_OMEGA] - vm)
    eae = 0.0
    for j in range(n):
        coupling = 0.0
        if n > 1:
            coupling = ng * _lap(vs, j, n, periodic) - kc4 * _lap(Fs, j, n, periodic)
            if j < n - 1 or periodic:
                d = vs[(j + 1) % n] - vs[j]
                eae += d * d
        dv[j] = r[3] + ((Fs[j] - Fm) - (dv[j] - fm) + coupling) / m
        dF[j] = k * (shift - vs[j])
    out[FY_EAE] = q[FQ_GAMMA] * eae
    out[FY_STRIPS + 2 * n] = Fm * q[M_V]
    out[FY_STRIPS + 2 * n + 1] = sfv / n


@kernel(nrt=False)
def _front_field(y, q, law, coef, out):
    front_rhs(y, (q, law, coef), out)


def front_field() -> Any:
    """``field(y, q, law, coef, out)``: :func:`front_rhs` callable from Python (the law as
    ``CompiledLaw.fn``), compiled for that one signature on first use."""
    a1 = _nb.float64[::1]
    return compile_only(_front_field, _nb.void(a1, a1, LAW_TYPE, a1, a1))
