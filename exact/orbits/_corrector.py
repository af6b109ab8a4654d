"""The parameter of a continuation and the bordered Newton corrector.

A branch point is ``w = (α, ω R/V, λ/Λ)``: the scaled section state of an orbit's first AB→CD jump and the
parameter λ (V, I, k or a family law's coefficient) over a scale Λ.  :func:`bordered_newton` solves

    P^n(x; λ) - x = 0,        τ · (w - w_ref) = 0

for ``(x, λ)``: the period-n closing condition and one linear condition, which is the pseudo-arclength condition
of a continuation step (``τ`` the branch's secant, ``w_ref`` the predicted point), a natural step
(``τ = (0, 0, 1)``: λ fixed) or the amplitude condition of a branch switch (``τ`` along a multiplier's
eigenvector).  The Jacobian is ``[[DP^n - 1, ∂P^n/∂λ], [τ]]`` with ``DP^n`` from the saltation tangent
(:func:`exact.orbits._section.compose`) and ``∂P^n/∂λ`` by a forward difference (step ``1e-7 max(|λ|, Λ)``: its error,
~1e-6 relative, slows Newton's convergence to linear with that rate, no more; not computed for a natural step,
where it does not enter).  A step that does not reduce the
closing residual is halved (at most 8 times).
"""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Callable

import numpy as np

from peelapprox import PeelForce, PeelParams
from peelapprox.errors import WallBudget
from peelapprox.validate import ArgumentTypeError

from .. import _models  # noqa: F401  (the built-in models registered before VARIANT_PARAMETERS is read)
from .._model import model_parameters
from ._periodic import PeriodicOrbit, check_wall, make_orbit
from ._section import compose, section_return_n, system_of

__all__ = ["PARAMETERS", "VARIANT_PARAMETERS", "bordered_newton", "branch_tangent", "check_parameter",
           "parameter_value", "with_parameter"]

#: The parameters of :func:`exact.continue_orbit` besides a family law's coefficients (``"force.<name>"``).
PARAMETERS = ("V", "I", "k")
#: The model variants' parameters (``PeelParams`` fields, with their ranges; the numeric ``parameters`` of the
#: models in ``exact.MODELS``: ``exact._model.model_parameters``): :func:`with_parameter` and
#: :func:`exact.orbit_diagram` take them (a brute-force diagram over the tape mass or the load), the
#: continuation does not (its section map is the massless model's).  ``"load_mass"`` and ``"load"`` set
#: ``loading="load"`` (their model's ``selected_by``); ``"tape_mass"`` 0 is the massless model (``tape_mass=None``).
VARIANT_PARAMETERS = tuple(model_parameters())
#: Relative forward-difference step of ``∂P^n/∂λ``.
FD_STEP = 1e-7


def check_parameter(params: PeelParams, parameter: object) -> str:
    """``parameter`` if it names a parameter of a continuation of ``params``' orbits: V, I, k or a coefficient
    ``"force.<name>"`` of its family law; ArgumentTypeError for a non-string (None), ValueError for another name,
    each listing the valid ones."""
    if not isinstance(parameter, str):
        law = params.force
        coefs = ", ".join(f"force.{c}" for c, _ in law.coefficients) if law.kind == "family" else ""
        raise ArgumentTypeError(f"parameter must be one of {', '.join(PARAMETERS)}"
                                + (f" or a coefficient of the family law params.force ({coefs})" if coefs else "")
                                + f" (a str), got {parameter!r} ({type(parameter).__name__})")
    _coefficient(params, parameter)
    return parameter


def _coefficient(params: PeelParams, parameter: str) -> str | None:
    """The family coefficient named by ``parameter`` (None for V, I, k and the variants' parameters); ValueError
    naming the valid ones."""
    if parameter in PARAMETERS or parameter in VARIANT_PARAMETERS:
        return None
    law = params.force
    name = parameter.removeprefix("force.")
    coefs = dict(law.coefficients)
    if not parameter.startswith("force.") or law.kind != "family" or name not in coefs:
        have = ", ".join(f"force.{c}" for c in coefs) if law.kind == "family" else "none (not a family law)"
        raise ValueError(f"parameter must be one of {', '.join(PARAMETERS)} or a coefficient of the family law "
                         f"params.force ({have}) — or, for with_parameter and orbit_diagram, a model variant's "
                         f"{', '.join(VARIANT_PARAMETERS)} — got {parameter!r}")
    return name


def with_parameter(params: PeelParams, parameter: str, value: float) -> PeelParams:
    """``params`` with ``parameter`` (V, I, k, a variant's ``tape_mass``, ``load_mass`` or ``load``
    (:data:`VARIANT_PARAMETERS`), or ``"force.<coefficient>"`` of a family law) set to ``value``.

    ``tape_mass`` 0 gives the massless model (``tape_mass=None``); ``load_mass`` and ``load`` switch on
    ``loading="load"``.  The value is checked by :class:`peelapprox.PeelParams` (ValueError naming the field
    and its range)."""
    name = _coefficient(params, parameter)
    owner = model_parameters().get(parameter)
    if owner is not None:  # a model's parameter, set with the field values that select that model (a load's)
        if isinstance(value, numbers.Real) and not isinstance(value, bool):
            value = float(value)  # PeelParams stores a float; a numpy 0 is then its "unset" 0 (tape_mass=None)
        return params.replace(**dict(owner.selected_by), **{parameter: value})
    if name is None:
        return params.replace(**{parameter: value})
    law = params.force
    return params.replace(force=PeelForce.family(str(law.name), **{**dict(law.coefficients), name: value}))


def parameter_value(params: PeelParams, parameter: str) -> float:
    """The value of ``parameter`` in ``params`` (:func:`with_parameter`)."""
    name = _coefficient(params, parameter)
    if name is None:
        x = getattr(params, parameter)
        return 0.0 if x is None else float(x)  # tape_mass None: the massless model
    return float(dict(params.force.coefficients)[name])


def _residual(x: np.ndarray, xn: np.ndarray, scale: np.ndarray) -> float:
    return float(np.linalg.norm((xn - x) / scale) / max(1.0, float(np.linalg.norm(x / scale))))


def bordered_newton(params_at: Callable[[float], PeelParams], n: int, x0: np.ndarray, lam0: float,
                    tau: np.ndarray, w_ref: np.ndarray, scale: np.ndarray, lam_scale: float, *, tol: float,
                    rtol: float, max_iter: int = 8, max_dlam: float = math.inf, wall: WallBudget | None = None
                    ) -> tuple[PeriodicOrbit, float]:
    """Solve the bordered system of the module docstring from ``(x0, lam0)``: ``(orbit, λ)``.

    Converged when the closing residual ``|P^n(x) - x| / max(1, |x|)`` (in ``x / scale``) is at most ``tol`` and
    the linear condition holds to ``1e-9 max(1, |w_ref|)``.  A Newton step that would move λ by more than
    ``max_dlam`` is shortened to it.  ``wall``, the caller's wall-clock budget, is checked before each iteration
    and each halved step (:func:`exact.orbits._periodic.check_wall`).

    Raises
    ------
    ValueError
        No convergence in ``max_iter`` iterations (the residuals listed) or a singular bordered Jacobian.
    ModelBreakdown, SolverBudgetExceeded, SolverFailure
        A return breaks down or never comes; ``wall`` is spent (``budget="max_wall"``).
    """
    wall0 = time.perf_counter()
    x, lam = np.asarray(x0, dtype=float).copy(), float(lam0)
    history: list[float] = []
    steps = 0
    eye = np.eye(2)
    for _ in range(max_iter):
        check_wall(wall, "continuation", x)
        p = params_at(lam)
        ts = system_of(p)
        cp = compose(p, ts, x, n, rtol)
        steps += cp.steps
        xn = cp.x
        w = np.concatenate([x / scale, [lam / lam_scale]])
        res, c = _residual(x, xn, scale), float(tau @ (w - w_ref))
        history.append(res)
        if res <= tol and abs(c) <= 1e-9 * max(1.0, float(np.linalg.norm(w_ref))):
            return make_orbit(p, ts, cp, history, steps, wall0), lam
        A = np.zeros((3, 3))
        A[:2, :2] = cp.jacobian * scale[None, :] / scale[:, None] - eye
        A[2] = tau
        if tau[0] != 0 or tau[1] != 0 or c != 0:  # else λ stays: the column does not enter the step
            d = FD_STEP * max(abs(lam), lam_scale)
            p2 = params_at(lam + d)
            it = section_return_n(p2, system_of(p2), x, n, rtol)
            steps += it.steps
            A[:2, 2] = (it.x - xn) / scale / (d / lam_scale)
        try:
            dw = np.linalg.solve(A, -np.concatenate([(xn - x) / scale, [c]]))
        except np.linalg.LinAlgError:
            raise ValueError(f"bordered Newton: singular Jacobian at λ={lam:.10g}") from None
        s = min(1.0, max_dlam / lam_scale / abs(dw[2])) if dw[2] != 0 else 1.0
        for _ in range(9):  # halve a step that does not reduce the closing residual
            check_wall(wall, "continuation", x)
            wt = w + s * dw
            xt, lt = wt[:2] * scale, float(wt[2] * lam_scale)
            pt = params_at(lt)
            it = section_return_n(pt, system_of(pt), xt, n, rtol)
            steps += it.steps
            if _residual(xt, it.x, scale) < res:
                break
            s *= 0.5
        x, lam = xt, lt
    raise ValueError(f"Newton did not close the period-{n} orbit to tol={tol} in max_iter={max_iter} "
                     f"iterations; residuals {', '.join(f'{r:.3g}' for r in history)}")


def branch_tangent(params_at: Callable[[float], PeelParams], orbit: PeriodicOrbit, lam: float, scale: np.ndarray,
                   lam_scale: float, rtol: float) -> np.ndarray:
    """The unit tangent of the branch at ``orbit`` in ``w`` (module docstring): the null vector of the closing
    condition's Jacobian ``[DP^n - 1, ∂P^n/∂λ]`` (the cross product of its two rows), with ``∂P^n/∂λ`` by the
    forward difference of :func:`bordered_newton`.  Its sign is the caller's to choose."""
    x = orbit.section_states[0]
    d = FD_STEP * max(abs(lam), lam_scale)
    p0, p1 = params_at(lam), params_at(lam + d)
    xn0 = section_return_n(p0, system_of(p0), x, orbit.n, rtol).x
    xn1 = section_return_n(p1, system_of(p1), x, orbit.n, rtol).x
    A = np.empty((2, 3))
    A[:, :2] = orbit.monodromy * scale[None, :] / scale[:, None] - np.eye(2)
    A[:, 2] = (xn1 - xn0) / scale / (d / lam_scale)
    t = np.cross(A[0], A[1])
    return t / np.linalg.norm(t)
