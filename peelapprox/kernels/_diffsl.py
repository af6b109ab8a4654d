"""The ε-regularised system (XDAE) written in DiffSL, the model language of diffsol, printed from the symbolic
source :mod:`peelapprox._compiled._symbolic` (no second copy of the formulas), and JIT-compiled by pydiffsol.

The state is ``X = (α, ω, F, v)`` of ``M Ẋ = φ(X)``, ``M = diag(1, 1, 1, ε)``, with φ = (FLOW1, FLOW2,
flow3, ``F (1 - cos θ) - f(v, V)``) and the peel force f of Eq. (fvV); ``tangent=True`` adds the
variational equations ``M δẊ = (∂φ/∂X) δX``.  pydiffsol accepts only a scalar ``atol``, so the model
integrates the scaled state ``y_i = X_i / s_i`` (``s`` = the absolute tolerances) with ``atol = 1``, which
gives exactly the weights ``s_i + rtol |X_i|`` on X.  ``stop { v - vm }`` with an identity ``reset`` marks
the crossings of the inflection velocity ``vm``.

pydiffsol is optional (the ``bench`` extra): it is imported only by :func:`diffsl_model`, and a missing
package is a :class:`PeerUnavailableError` (an ``ImportError``) naming the extra.  Users: the peers of
``comparisons`` and the ε-variational Lyapunov exponent of ``exact``; both reach this module through
:mod:`peelapprox.kernels`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._ranges import GEOMETRIES
from ..io import optional_import
from ..law import PeelForce, branch_structure

if TYPE_CHECKING:  # pragma: no cover
    from .._params import PeelParams

__all__ = ["DIFFSL_INPUTS", "DIFFSL_TANGENT_INPUTS", "DIFFSOL_OPTIONS", "PeerUnavailableError", "diffsl_code",
           "diffsl_inputs", "diffsl_model", "import_optional"]


class PeerUnavailableError(ImportError):
    """The package a peer needs is missing or does not work here."""


def import_optional(module: str, pip: str, who: str):
    """Import the optional package ``module`` (pip name ``pip``) that ``who`` needs.

    Raises
    ------
    PeerUnavailableError
        If it does not import; the message names the pip package and the ``bench`` extra
        (:func:`peelapprox.io.optional_import`'s message).
    """
    return optional_import(module, who, "bench", pip=pip, error=PeerUnavailableError)


#: pydiffsol ``Ode.options`` changed from their defaults to pass the folds (see the Notes of ``comparisons``'
#: ``run_peer``): a fresh Newton matrix and right-hand-side Jacobian at every step (defaults: after 20 and 50
#: steps) and ``min_timestep`` 1e-18 instead of 1e-13.
DIFFSOL_OPTIONS = dict(min_timestep=1e-18, update_jacobian_after_steps=1, update_rhs_jacobian_after_steps=1)


#: Inputs of the DiffSL model, in order (``in_i``): physical parameters, the
#: inflection velocity, the initial state and the state scales (= atol).
DIFFSL_INPUTS = ("V", "I", "k", "R", "l", "eps", "vm", "a0", "w0", "F0", "v0", "sa", "sw", "sF", "sv")

#: Further inputs of the ``tangent=True`` model: the initial tangent δX and its scales.
DIFFSL_TANGENT_INPUTS = ("d0a", "d0w", "d0F", "d0v", "ta", "tw", "tF", "tv")


def _law_expression(force):
    """f(v, V) of the law ``force`` (None or the paper's: fvV) in the symbols of :mod:`peelapprox._compiled._symbolic`.

    Raises
    ------
    ValueError
        For a tabulated law (no closed form to write in DiffSL), naming ``params.force``.
    """
    from .._compiled import _symbolic as S
    from ..law import _symbolic as L

    try:
        e = L.law_expression(force or PeelForce.paper())
    except ValueError:
        raise ValueError(f"params.force: {force!r} is tabulated and cannot be written in DiffSL: the diffsol peer and "
                         "the eps-variational Lyapunov method need a closed-form law (an expression or a family); "
                         "the hybrid, regularised and SUNDIALS solvers run tables") from None
    return e.xreplace({L.v: S.v, L.V: S.V})


def _diffsl_expressions(geometry: str, force=None) -> dict:
    """DiffSL (C-syntax) expressions of c(α), φ_α, φ_ω, φ_F and φ_v, printed from the one symbolic source
    :mod:`peelapprox._compiled._symbolic` (``cos_theta_expr``, ``equations_of_motion``; fvV inside CONSTR, or the law
    ``force`` in its place, :mod:`peelapprox.law._symbolic`), so the peer integrates the same model as every other
    solver without a second copy of the formulas.  The pull force is named ``Fp`` in DiffSL (``F_i`` is
    DiffSL's right-hand side)."""
    import sympy as sp

    from .._compiled import _symbolic as S

    Fp = sp.Symbol("Fp", real=True)
    alpha_dot, omega_dot, F_dot, constraint = S.equations_of_motion(S.c_)
    f_law, fvv = _law_expression(force), S.peel_force_expr(S.v, S.V)
    if f_law != fvv:  # CONSTR with the law instead of fvV
        constraint = constraint + fvv - f_law
    sub = {S.F: Fp}
    code = {name: sp.ccode(e.xreplace(sub)) for name, e in
            (("phi_a", alpha_dot), ("phi_w", omega_dot), ("phi_F", F_dot), ("phi_v", constraint))}
    code["c"] = sp.ccode(-S.cos_theta_expr(geometry))
    # the variational equations: the Jacobian of φ = (ε-row undone) of the XDAE Jacobian, in c, dc = dc/dα
    # and fp = ∂f/∂v, with their expressions for this closure
    _, J, fp = S.regularized_system()
    J = J.copy()
    J[3, :] = J[3, :] * S.eps
    code["dc"] = sp.ccode(sp.diff(-S.cos_theta_expr(geometry), S.alpha))
    code["fp"] = sp.ccode(sp.diff(f_law, S.v))
    code["jac"] = [[sp.ccode(sp.expand(J[i, j]).xreplace(sub)) for j in range(4)] for i in range(4)]
    return code


def diffsl_code(geometry: str = "paper", *, tangent: bool = False, force=None) -> str:
    """The DiffSL source of the regularised system for pydiffsol.

    Printed from the symbolic model (:func:`_diffsl_expressions`).  The state is ``y = X / s`` with
    ``s = (sa, sw, sF, sv)`` (the absolute tolerances, see the module
    docstring), the mass matrix is ``diag(1, 1, 1, eps)`` and
    ``F_i = φ_i(s ∘ y) / s_i``.  ``stop``/``reset`` mark the crossings of
    ``v = vm``.

    With ``tangent=True`` the model also carries the variational equations of XDAE,
    ``M δẊ = (∂φ/∂X)(X) δX``, in four more states ``z = δX / t`` with scales
    ``t = (ta, tw, tF, tv)`` and initial value ``(d0a, d0w, d0F, d0v)``
    (inputs :data:`DIFFSL_TANGENT_INPUTS`, after :data:`DIFFSL_INPUTS`).  ∂φ/∂X is
    the Jacobian of :func:`peelapprox._compiled._symbolic.regularized_system`, printed with the
    closure's ``dc/dα`` and ``f' = ∂f/∂v`` of fvV.

    Parameters
    ----------
    geometry : {"paper", "exact"}
        Closure of ``cos θ`` (``PeelParams.geometry``).
    tangent : bool, keyword-only
        Append the variational equations (8 states instead of 4).
    force : PeelForce, optional, keyword-only
        The peel-force law (``PeelParams.force``; None: fvV), printed from its sympy form.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        For a tabulated law (no closed form), naming ``params.force``.
    """
    if geometry not in GEOMETRIES:
        raise ValueError(f"geometry must be one of {GEOMETRIES}, got {geometry!r}")
    names = DIFFSL_INPUTS + (DIFFSL_TANGENT_INPUTS if tangent else ())
    inputs = ", ".join(f"{n} = 1.0" for n in names)
    e = _diffsl_expressions(geometry, force)
    u = ["ya = a0 / sa", "yw = w0 / sw", "yF = F0 / sF", "yv = v0 / sv"]
    du = ["dya", "dyw", "dyF", "dyv"]
    mass = ["dya", "dyw", "dyF", "eps * dyv"]
    rhs = [f"({e[k]}) / s{c}" for k, c in zip(("phi_a", "phi_w", "phi_F", "phi_v"), "awFv")]
    extra = ""
    if tangent:
        u += [f"z{c} = d0{c} / t{c}" for c in "awFv"]
        du += [f"dz{c}" for c in "awFv"]
        mass += ["dza", "dzw", "dzF", "eps * dzv"]
        for i, ci in enumerate("awFv"):
            terms = " + ".join(f"({e['jac'][i][j]}) * z{cj} * t{cj}" for j, cj in enumerate("awFv")
                               if e["jac"][i][j] != "0")
            rhs.append(f"({terms}) / t{ci}")
        extra = f"dc {{ {e['dc']} }}\nfp {{ {e['fp']} }}\n"
    states = [x.split(" =")[0] for x in u]
    newline = ",\n  "
    return f"""
in_i {{ {inputs} }}
u_i {{ {", ".join(u)} }}
dudt_i {{ {", ".join(d + " = 0.0" for d in du)} }}
alpha {{ ya * sa }}
omega {{ yw * sw }}
Fp {{ yF * sF }}
v {{ yv * sv }}
c {{ {e["c"]} }}
{extra}M_i {{ {", ".join(mass)} }}
F_i {{
  {newline.join(rhs)},
}}
stop {{ v - vm }}
reset_i {{ {", ".join(states)} }}
"""


def diffsl_model(geometry: str = "paper", *, tangent: bool = False, force=None):
    """JIT-compile :func:`diffsl_code` into a ``pydiffsol.Ode`` (dense LU, BDF).

    Raises
    ------
    PeerUnavailableError
        If pydiffsol is not installed.
    ValueError
        For a law that cannot be written in DiffSL (a table; an expression using a function DiffSL lacks),
        naming ``params.force``.
    """
    ds = import_optional("pydiffsol", "pydiffsol", "peer 'diffsol'")
    code = diffsl_code(geometry, tangent=tangent, force=force)
    try:
        return ds.Ode(code, matrix_type=ds.nalgebra_dense, ode_solver=ds.bdf)
    except Exception as exc:  # pydiffsol reports a DiffSL compile error as its own exception type
        raise ValueError(f"params.force: {force!r} cannot be compiled to DiffSL: {exc}") from None


def diffsl_inputs(params: PeelParams, eps: float, state, scale, tangent=None, tangent_scale=None) -> np.ndarray:
    """The ``in_i`` vector of :func:`diffsl_code` (order :data:`DIFFSL_INPUTS`, then
    :data:`DIFFSL_TANGENT_INPUTS` when ``tangent`` is given).

    Parameters
    ----------
    params : PeelParams
    eps : float
        Regularisation ε.
    state : sequence of 4 floats
        Initial ``(α, ω, F, v)``.
    scale : sequence of 4 floats
        State scales ``s`` (``y = X / s``), all > 0.
    tangent, tangent_scale : sequences of 4 floats, optional
        Initial tangent ``δX`` and its scales ``t`` (``z = δX / t``), for the
        ``tangent=True`` model; ``tangent_scale`` defaults to ``scale``.
    """
    vm = branch_structure(params.V, force=params.force).v_inflection
    out = [params.V, params.I, params.k, params.R, params.l, eps, vm, *state, *scale]
    if tangent is not None:
        out += [*tangent, *(scale if tangent_scale is None else tangent_scale)]
    return np.array(out, dtype=float)
