"""The model variants' compiled fields (the follow-ups of the paper's model): the tape-mass model and the constant load.

Three smooth ODE systems in the state ``y = (α, ω, F, v)`` or ``(α, ω, F, v, V_p)``, each with its analytic
Jacobian, rendered from :func:`peelapprox._compiled._symbolic.variant_system` into
:mod:`peelapprox._compiled._generated`:

=============  ======  ===================================================================================
model          states  equations
=============  ======  ===================================================================================
``"tape"``     4       FLOW1, flow3, the tape-mass model's ω̇ and v̇
(:func:`peelapprox._compiled._symbolic.tape_mass_rates`)
``"tape_load"`` 5      the same with ``V → V_p`` and ``M V̇_p = F_L - F``
``"eps_load"`` 5       the massless tape under a load: XDAE (``ε v̇ = F(1 - cos θ) - f``) with ``V → V_p``
=============  ======  ===================================================================================

The peel-force law is an argument (``law(v, coef, LAW_FP)``, :mod:`peelapprox.law._abi`), so every law runs
through the one compiled field per model; the law is evaluated at the **fixed** pull speed its coefficients
were packed for (``params.V``), also under a load where the pull speed ``V_p`` varies (docs/constant-load.md).
The parameter vector is the model block followed by ``(m or ε, M, F_L)`` (:func:`variant_parameters`).
Each field and Jacobian is compiled on first use for its one signature (loaded from numba's cache after).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit
from numba import types as _nb

from .._compiled import _generated as _g
from .._compiled._jit import compile_only, kernel, rebind
from .._compiled._model_jit import closure_d2, regularized_rhs
from .._packing import M_GEOM, M_I, M_K, M_L, M_R, M_V, N_M, model_block
from ..law import ALL_LAWS
from ..law._abi import LAW_FP, LAW_TYPE, paper_law

__all__ = ["VARIANT_MODELS", "Q_MASS", "Q_LOAD_MASS", "Q_LOAD", "variant_parameters", "variant_field",
           "bound_variant_field"]

#: The variants' names and their numbers of states.
VARIANT_MODELS = {"tape": 4, "tape_load": 5, "eps_load": 5}
#: Indices after the model block: the tape mass m (or ε for ``"eps_load"``), the loading mass M, the load F_L.
Q_MASS, Q_LOAD_MASS, Q_LOAD = N_M, N_M + 1, N_M + 2

_tape_rhs = kernel(inline="always")(_g.tape_rhs)
_load_rate = kernel(inline="always")(_g.load_rate)
_tape_jac = kernel(inline="always")(_g.tape_jacobian)
_tape_load_jac = kernel(inline="always")(_g.tape_load_jacobian)
_eps_load_jac = kernel(inline="always")(_g.eps_load_jacobian)


def variant_parameters(params: Any, mass: float, load_mass: float = 1.0, load: float = 0.0) -> np.ndarray:
    """The parameter vector of the variant fields: the model block (:func:`model_block`, any law), then ``mass``
    (the tape mass m [kg], or ε for ``"eps_load"``), ``load_mass`` M [kg] and ``load`` F_L [N] (unused by
    ``"tape"``)."""
    q = model_block(params, N_M + 3, ALL_LAWS)
    q[Q_MASS], q[Q_LOAD_MASS], q[Q_LOAD] = mass, load_mass, load
    return q


@kernel(inline="always")
def _square(j, n):
    """The row-major ``n * n`` tuple ``j`` as an (n, n) array."""
    out = np.empty((n, n))
    for i in range(n * n):
        out[i // n, i % n] = j[i]
    return out


@kernel
def _tape_field(y, q, law, coef):
    """The tape-mass model under velocity control: ``(α̇, ω̇, Ḟ, v̇)``."""
    v = max(y[3], 1e-300)  # implicit-solver iterates may probe v <= 0; accepted steps are checked
    f, _, _ = law(v, coef, LAW_FP)
    c, dc, _ = closure_d2(y[0], q[M_GEOM], q[M_R], q[M_L])
    r = _tape_rhs(y[0], y[1], y[2], v, q[M_V], c, dc, f, q[Q_MASS], q[M_I], q[M_K], q[M_R])
    return np.array([r[0], r[1], r[2], r[3]])


@kernel
def _tape_jacobian(y, q, law, coef):
    v = max(y[3], 1e-300)
    f, fp, _ = law(v, coef, LAW_FP)
    c, dc, ddc = closure_d2(y[0], q[M_GEOM], q[M_R], q[M_L])
    j = _tape_jac(y[0], y[1], y[2], v, c, dc, ddc, f, fp, q[Q_MASS], q[M_V], q[M_I], q[M_K], q[M_R])
    return _square(j, 4)


@kernel
def _tape_load_field(y, q, law, coef):
    """The tape-mass model under a load: ``(α̇, ω̇, Ḟ, v̇, V̇_p)``."""
    v = max(y[3], 1e-300)
    f, _, _ = law(v, coef, LAW_FP)
    c, dc, _ = closure_d2(y[0], q[M_GEOM], q[M_R], q[M_L])
    r = _tape_rhs(y[0], y[1], y[2], v, y[4], c, dc, f, q[Q_MASS], q[M_I], q[M_K], q[M_R])
    return np.array([r[0], r[1], r[2], r[3], _load_rate(y[2], q[Q_LOAD_MASS], q[Q_LOAD])[0]])


@kernel
def _tape_load_jacobian(y, q, law, coef):
    v = max(y[3], 1e-300)
    f, fp, _ = law(v, coef, LAW_FP)
    c, dc, ddc = closure_d2(y[0], q[M_GEOM], q[M_R], q[M_L])
    j = _tape_load_jac(y[0], y[1], y[2], v, c, dc, ddc, f, fp, y[4], q[Q_MASS], q[Q_LOAD_MASS], q[Q_LOAD],
                       q[M_I], q[M_K], q[M_R])
    return _square(j, 5)


@kernel
def _eps_load_field(y, q, law, coef):
    """The ε-regularised massless tape under a load: ``(α̇, ω̇, Ḟ, v̇, V̇_p)``."""
    v = max(y[3], 1e-300)
    f, _, _ = law(v, coef, LAW_FP)
    c, _, _ = closure_d2(y[0], q[M_GEOM], q[M_R], q[M_L])
    r = regularized_rhs(y[0], y[1], y[2], v, c, f, q[Q_MASS], y[4], q[M_I], q[M_K], q[M_R])
    return np.array([r[0], r[1], r[2], r[3], _load_rate(y[2], q[Q_LOAD_MASS], q[Q_LOAD])[0]])


@kernel
def _eps_load_jacobian(y, q, law, coef):
    v = max(y[3], 1e-300)
    f, fp, _ = law(v, coef, LAW_FP)
    c, dc, ddc = closure_d2(y[0], q[M_GEOM], q[M_R], q[M_L])
    j = _eps_load_jac(y[0], y[1], y[2], v, c, dc, ddc, f, fp, y[4], q[Q_MASS], q[Q_LOAD_MASS], q[Q_LOAD],
                      q[M_I], q[M_K], q[M_R])
    return _square(j, 5)


_FIELDS = {"tape": (_tape_field, _tape_jacobian), "tape_load": (_tape_load_field, _tape_load_jacobian),
           "eps_load": (_eps_load_field, _eps_load_jacobian)}


def variant_field(model: str) -> tuple[Any, Any]:
    """``(field, jacobian)`` of a variant (module docstring): ``field(y, q, law, coef)`` -> rates (a new array),
    ``jacobian(y, q, law, coef)`` -> the (n, n) Jacobian; compiled for that one signature on first use."""
    if model not in _FIELDS:
        raise ValueError(f"model must be one of {sorted(_FIELDS)}, got {model!r}")
    fun, jac = _FIELDS[model]
    _compile_once(fun, jac, _nb.float64[::1], _nb.float64[::1], LAW_TYPE, _nb.float64[::1])
    return fun, jac


def _compile_once(fun: Any, jac: Any, *args: Any) -> None:
    """Compile a field (returning a 1-d array) and its Jacobian (a 2-d array) for the one signature ``args``, on
    first use only, and allow no other."""
    for d, ret in ((fun, _nb.float64[::1]), (jac, _nb.float64[:, ::1])):
        compile_only(d, ret(*args))



# The fields with the paper's law bound in (the default law): each body inlined into a module-level copy that
# reads the law as a global (``_rebind``), so the law call is static and numba caches the copy.
def _paper_copy(fn: Any, name: str) -> Any:
    body = kernel(inline="always", name=f"{name}_body")(fn.py_func)

    def bound(y, q, coef):  # pragma: no cover - compiled
        return _BODY(y, q, _LAW, coef)  # noqa: F821 - globals of the rebound copy

    bound.__qualname__ = bound.__name__ = name
    return kernel(rebind(bound, _BODY=body, _LAW=paper_law), name=name)


_PAPER = {m: (_paper_copy(f, f"variant_{m}_field_paper"), _paper_copy(j, f"variant_{m}_jacobian_paper"))
          for m, (f, j) in {"tape": (_tape_field, _tape_jacobian), "tape_load": (_tape_load_field, _tape_load_jacobian),
                            "eps_load": (_eps_load_field, _eps_load_jacobian)}.items()}
_BOUND: dict[tuple[str, int], tuple[Any, Any, Any]] = {}


def bound_variant_field(model: str, law: Any) -> tuple[Any, Any]:
    """``(field, jacobian)`` of a variant with the peel-force ``law`` (``CompiledLaw.fn``) bound in:
    ``field(y, q, coef)``, ``jacobian(y, q, coef)``.

    Passing the law as an argument from Python (:func:`variant_field`) costs ~65 µs per call (numba types the
    function argument at every call); with the law bound in, ~1 µs (docs/tape-mass.md, "Which integrator").  The
    paper's law (:func:`peelapprox.law._abi.paper_law`) is bound in cached kernels (compiled once per machine);
    another law in a closure compiled once per process (~2 s) and kept.
    """
    fun, jac = variant_field(model)
    if law is paper_law:
        bf, bj = _PAPER[model]
        _compile_once(bf, bj, _nb.float64[::1], _nb.float64[::1], _nb.float64[::1])
        return bf, bj
    key = (model, id(law))
    if key not in _BOUND:

        @njit(cache=False)  # a closure over the law: numba cannot cache it
        def bfun(y, q, coef):  # pragma: no cover - compiled
            return fun(y, q, law, coef)

        @njit(cache=False)
        def bjac(y, q, coef):  # pragma: no cover - compiled
            return jac(y, q, law, coef)

        _BOUND[key] = (bfun, bjac, law)  # the law kept alive, so its id stays unique
    return _BOUND[key][0], _BOUND[key][1]
