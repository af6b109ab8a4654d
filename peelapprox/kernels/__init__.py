"""The one door through which the solvers of ``exact`` get the model's compiled pieces.

Everything here is compiled by :func:`peelapprox._compiled._jit.kernel` from the one generated source
(:mod:`peelapprox._compiled._generated`, written by :mod:`peelapprox._compiled._symbolic`), compiled once, and shared by
every
driver: the peel force (fvV) in the velocity and in the ln v form, the law ABI by which a driver takes the
peel-force law as a function argument with its coefficients as data (:mod:`peelapprox.law._abi`: ``LAW_SIG``,
``LAW_TYPE``, the forms ``LAW_*``, the compiled laws ``LAWS``; the tabulated law ``table_law`` and its packing
``table_coefficients``, :mod:`peelapprox.law._table_jit`; the laws generated from their symbolic form,
:func:`family_kernel` and :func:`expression_kernel` of :mod:`peelapprox.law.codegen`), the ``cos θ`` closures with the
geometry switch, the slow rates (FLOW1, FLOW2, flow3), the constraint rate (Eq. vdot), the regularised
system XDAE and its Jacobian (also as whole fields of the state and a packed parameter vector, the form the
stiff solvers call), and the model variants' fields (the tape mass, the constant load:
:mod:`peelapprox.kernels._variant_fields`).  The model block every driver's parameter vector starts with
(:mod:`peelapprox._packing`: the index constants ``M_*``, its length ``N_M``, :func:`model_block`), the DOP853 pieces
(:mod:`peelapprox._compiled._dop853`), the kernel compiler and the status codes (:mod:`peelapprox._status`) are offered
here too, so ``exact`` needs no private module of ``peelapprox`` for its kernels.  The same system written in
DiffSL and JIT-compiled by pydiffsol (optional, the ``bench`` extra; :mod:`peelapprox.kernels._diffsl`) is offered here
for the ε-variational Lyapunov exponent of ``exact`` and the peers of ``comparisons``.

The model functions are ``inline="always"``: numba inlines them into the fields at the IR level (as separate
compiled functions their calls cost half of a field evaluation, 72 -> 35 ns measured).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import types as _nb

from .. import _status as status
from .._compiled._dop853 import (
    MAX_REJECTIONS,
    N_STAGES,
    STEP_FAILED,
    crossing,
    interp,
    interp1,
    interp_mean,
    make_dop853,
    solve_theta,
    solve_theta_mean,
    state_at,
    workspace,
)
from .._compiled._jit import compile_only, kernel, rebind
from .._compiled._model_jit import (
    closure,
    closure_d2,
    closure_exact,
    closure_exact_d2,
    closure_paper,
    closure_paper_d2,
    constraint_rate,
    regularized_jacobian,
    regularized_rhs,
    slow_rates,
)
from .._deadline import Expired as BuildExpired
from .._deadline import caller_budget
from .._packing import M_A, M_B, M_GEOM, M_I, M_K, M_L, M_R, M_V, MODEL_FIELDS, N_M, model_block
from ..front._field import (
    FQ_GAMMA,
    FQ_N,
    FQ_PERIODIC,
    FY_ALPHA,
    FY_EAE,
    FY_OMEGA,
    FY_STRIPS,
    N_FQ,
    N_FY_TAIL,
    front_field,
    front_parameters,
    front_rhs,
    front_state_size,
)
from ..law import ALL_LAWS
from ..law._abi import (
    LAW_FP,
    LAW_FPP,
    LAW_LNV,
    LAW_SIG,
    LAW_TYPE,
    LAWS,
    pack_inlined,
    pack_law,
    paper_coefficients,
    paper_law,
)
from ..law._compiled import U_ZERO, CompiledLaw, compiled_law, law_domain
from ..law._kernels import expression_kernel, family_kernel
from ..law._paper import _invert as branch_inverse_at
from ..law._paper import peel_force_coefficients, peel_force_fp_jit, peel_force_fpp_jit, peel_force_lnv_jit
from ..law._table_jit import table_coefficients, table_law
from ._cachestatus import cache_status, cpu_name, record_warmup
from ._diffsl import (
    DIFFSL_INPUTS,
    DIFFSL_TANGENT_INPUTS,
    DIFFSOL_OPTIONS,
    PeerUnavailableError,
    diffsl_code,
    diffsl_inputs,
    diffsl_model,
    import_optional,
)
from ._variant_fields import VARIANT_MODELS, bound_variant_field, variant_field, variant_parameters

#: Index of ε in the regularised system's parameter vector, after the model block.
Q_EPS = N_M

__all__ = [
    "kernel", "rebind", "compile_only", "status",
    "peel_force_fp_jit", "peel_force_fpp_jit", "peel_force_lnv_jit",
    "LAW_SIG", "LAW_TYPE", "LAW_LNV", "LAW_FP", "LAW_FPP", "LAWS", "paper_law", "paper_coefficients",
    "pack_inlined", "pack_law",
    "ALL_LAWS", "CompiledLaw", "compiled_law", "law_domain", "U_ZERO",
    "table_law", "table_coefficients", "family_kernel", "expression_kernel",
    "closure_paper", "closure_exact", "closure", "closure_d2", "closure_paper_d2", "closure_exact_d2",
    "slow_rates", "constraint_rate",
    "regularized_rhs", "regularized_jacobian", "regularized_parameters", "Q_EPS", "regularized_field",
    "regularized_field_jacobian", "regularized_law_field", "peel_force_coefficients", "branch_inverse_at",
    "MODEL_FIELDS", "M_V", "M_I", "M_K", "M_R", "M_L", "M_B", "M_A", "M_GEOM", "N_M", "model_block",
    "VARIANT_MODELS", "variant_field", "variant_parameters", "bound_variant_field",
    "MAX_REJECTIONS", "N_STAGES", "STEP_FAILED", "crossing", "interp", "interp1", "make_dop853", "solve_theta",
    "state_at", "workspace", "interp_mean", "solve_theta_mean",
    "front_rhs", "front_field", "front_parameters", "front_state_size", "FQ_N", "FQ_GAMMA", "FQ_PERIODIC", "N_FQ",
    "FY_ALPHA", "FY_OMEGA", "FY_EAE", "FY_STRIPS", "N_FY_TAIL",
    "DIFFSL_INPUTS", "DIFFSL_TANGENT_INPUTS", "DIFFSOL_OPTIONS", "PeerUnavailableError", "diffsl_code",
    "diffsl_inputs", "diffsl_model", "import_optional",
    "BuildExpired", "caller_budget",  # a public call's max_wall handed down to the law compilation it triggers
    "cache_status", "cpu_name", "record_warmup",  # the private kernel cache: its state, the warm-up's record
]

def regularized_parameters(params, eps: float, laws: tuple[str, ...] = ("paper",)) -> np.ndarray:
    """The parameter vector ``q`` of :func:`regularized_field` / :func:`regularized_field_jacobian`: the model
    block (:func:`model_block`: V, I, k, R, l, the fvV coefficients b and A, the geometry flag) followed by ε at
    index :data:`Q_EPS` (= ``N_M``); ``laws`` as for :func:`model_block` (:data:`ALL_LAWS` for the fields of
    :func:`regularized_law_field`)."""
    q = model_block(params, N_M + 1, laws)
    q[Q_EPS] = eps
    return q


@kernel(inline="always")
def _field_at(y, q, v, f):
    """XDAE's ``M⁻¹ φ`` at ``y`` given ``v`` and ``f(v)`` (whichever law gave it), as a new array."""
    c, _ = closure(y[0], q[M_GEOM], q[M_R], q[M_L])
    r = regularized_rhs(y[0], y[1], y[2], v, c, f, q[Q_EPS], q[M_V], q[M_I], q[M_K], q[M_R])
    return np.array([r[0], r[1], r[2], r[3]])


@kernel(inline="always")
def _jacobian_at(y, q, v, fp):
    """The Jacobian of :func:`_field_at` given ``v`` and ``f'(v)``, a (4, 4) array."""
    c, dc = closure(y[0], q[M_GEOM], q[M_R], q[M_L])
    j = regularized_jacobian(y[0], y[1], y[2], v, c, dc, fp, q[Q_EPS], q[M_V], q[M_I], q[M_K], q[M_R])
    out = np.empty((4, 4))
    for i in range(16):
        out[i // 4, i % 4] = j[i]
    return out


@kernel
def regularized_field(y, q):
    """XDAE's ``M⁻¹ φ(X)`` at ``y = (α, ω, F, v)`` as a new array (``q``: :func:`regularized_parameters`)."""
    v = max(y[3], 1e-300)  # Newton iterates may probe v <= 0; accepted steps are checked
    f, _ = peel_force_fp_jit(v, q[M_B], q[M_A])
    return _field_at(y, q, v, f)


@kernel
def regularized_field_jacobian(y, q):
    """The Jacobian of :func:`regularized_field`, a (4, 4) array (with ``eps = 1`` in ``q``: ∂φ/∂X itself)."""
    v = max(y[3], 1e-300)
    _, fp = peel_force_fp_jit(v, q[M_B], q[M_A])
    return _jacobian_at(y, q, v, fp)


@kernel
def _regularized_field_law(y, q, law, coef):
    """:func:`regularized_field` for the law ``law`` with the coefficients ``coef`` (``LAW_FP``)."""
    v = max(y[3], 1e-300)
    f, _, _ = law(v, coef, LAW_FP)
    return _field_at(y, q, v, f)


@kernel
def _regularized_field_jacobian_law(y, q, law, coef):
    """:func:`regularized_field_jacobian` for the law ``law`` with the coefficients ``coef``."""
    v = max(y[3], 1e-300)
    _, fp, _ = law(v, coef, LAW_FP)
    return _jacobian_at(y, q, v, fp)


def regularized_law_field() -> tuple[Any, Any]:
    """``(field, jacobian)`` of the regularised system (XDAE) with the peel-force law as an argument:
    ``field(y, q, law, coef)`` and ``jacobian(y, q, law, coef)`` as :func:`regularized_field` and
    :func:`regularized_field_jacobian` with ``law`` (:data:`LAW_TYPE`) and its coefficients ``coef``.  Compiled
    for that signature (``y`` writeable or read-only) on first use (loaded from numba's cache when it is there),
    so every law and every coefficient vector runs without compiling again."""
    a1 = _nb.float64[::1]
    ro = _nb.Array(_nb.float64, 1, "C", readonly=True)  # the state as SUNDIALS passes it
    for d, ret in ((_regularized_field_law, a1), (_regularized_field_jacobian_law, _nb.float64[:, ::1])):
        compile_only(d, ret(a1, a1, LAW_TYPE, a1), ret(ro, a1, LAW_TYPE, a1))
    return _regularized_field_law, _regularized_field_jacobian_law
