"""External compiled peer solvers on the paper's ε-regularised system.

The system is the one integrated by ``exact.simulate(method="regularized")``
(see :mod:`exact._regularized`): state ``X = (α, ω, F, v)``,

    M Ẋ = φ(X),   M = diag(1, 1, 1, ε),

with φ from :func:`peelapprox._generated.regularized_rhs` (FLOW1, FLOW2,
flow3 and ``φ_v = F (1 - cos θ) - f(v, V)``), the closure of ``cos θ`` given by
``params.geometry`` and the peel force f of Eq. (fvV).  The same initial state
as the hybrid and the scipy solvers (:func:`exact.initial_state`) is used.

Peers
-----
``"ida"``
    SUNDIALS IDA (variable-order, variable-step BDF for implicit DAEs) through
    ``sksundae.ida`` in residual form ``r = M Ẋ - φ(X)``, with the analytic
    Jacobian ``∂r/∂X + c_j ∂r/∂Ẋ = -∂φ/∂X + c_j M`` and a consistent ``Ẋ(0)``.
``"cvode"``
    SUNDIALS CVODE through ``sksundae.cvode`` on the equivalent ODE
    ``Ẋ = M⁻¹ φ(X)``: BDF, dense direct linear solver, analytic Jacobian.
``"diffsol"``
    pydiffsol (the Rust crate diffsol): its BDF (NDF, after ode15s) with the
    mass matrix M, the model written in DiffSL (:func:`diffsl_code`) and
    JIT-compiled by LLVM; the Jacobian comes from the compiler's automatic
    differentiation.

The two SUNDIALS peers call back into Python for every right-hand-side or
Jacobian evaluation; the callbacks are the numba-compiled kernels of
:mod:`exact._regularized` (``_fun``, ``_jac``), so only the call overhead is
Python.  diffsol evaluates the model in JIT-compiled code with no Python in
the loop.

Tolerances
----------
Every peer controls the local error per step in a weighted RMS norm,
``sqrt(mean_i (err_i / (atol_i + rtol |X_i|))^2) <= 1``, as scipy's solvers do,
with ``atol`` defaulting to ``rtol * exact.ATOL_SCALE["regularized"]``
exactly as ``exact.simulate(method="regularized")``.  pydiffsol accepts only a
scalar ``atol``; the DiffSL model therefore integrates the scaled state
``y_i = X_i / atol_i`` with ``atol = 1``, which gives exactly the weights
``atol_i + rtol |X_i|`` on X (the relative part is scale invariant).  The
tolerances are *local*: equal ``rtol`` does not mean equal global accuracy
across peers (different methods, orders and error estimators).

Jumps
-----
A jump is recorded where v crosses the inflection velocity ``v_infl`` of
``f(·, V)`` in either direction, as :mod:`exact._regularized` does.  IDA and
CVODE locate it with their root finders (``eventsfn``, non-terminal, on
``v - v_infl``).  For diffsol the DiffSL model carries ``stop { v - v_infl }``
with an identity ``reset``: diffsol's root finder stops the integration at the
crossing, records the state twice (before and after the identity reset) and
restarts the BDF there; those duplicated output times are the crossing
times.  (Restarting at each crossing is part of diffsol's cost.)

Time
----
``wall_time`` is ``time.perf_counter()`` around the integration call only
(``solve``).  Model construction is reported separately in
``compile_time``: for diffsol the DiffSL JIT compilation, for the SUNDIALS
peers the loading (from numba's on-disk cache) or compiling of the numba
kernels, which happens once per process, plus the solver object's
construction.
"""

from __future__ import annotations

import functools
import importlib
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from exact._simulate import _atol_vector, initial_state
from peelapprox import GEOMETRIES, SolverFailure
from peelapprox._params import EPS_RANGE, T_TRANSIENT
from peelapprox._peelforce import branch_structure
from peelapprox._validate import choice, duration, function, in_range, optional, reals, state
from peelapprox._validate import params as _params

if TYPE_CHECKING:  # pragma: no cover
    from peelapprox import PeelParams

__all__ = [
    "PEERS",
    "PeerResult",
    "PeerUnavailableError",
    "available_peers",
    "run_peer",
    "diffsl_code",
    "diffsl_model",
    "diffsl_inputs",
    "DIFFSL_TANGENT_INPUTS",
    "TANGENT_OPTIONS",
    "tangent_solve",
    "lyapunov_regularized",
]

#: The peers :func:`run_peer` knows.
PEERS = ("ida", "cvode", "diffsol")

#: Package (import name, pip name) each peer needs.
_PACKAGES = {
    "ida": ("sksundae", "scikit-sundae"),
    "cvode": ("sksundae", "scikit-sundae"),
    "diffsol": ("pydiffsol", "pydiffsol"),
}

#: Step budget passed to SUNDIALS (its default, 500 per output interval, is far too small for save-every-step solves).
_MAX_NUM_STEPS = 100_000_000


class PeerUnavailableError(ImportError):
    """The package a peer needs is missing or does not work here."""


@dataclass(frozen=True)
class PeerResult:
    """Outcome of one peer run.

    Attributes
    ----------
    peer : str
        One of :data:`PEERS`.
    eps, rtol : float
        Regularisation ε and relative tolerance used.
    atol : ndarray, shape (4,)
        Absolute tolerances used for ``(α, ω, F, v)``.
    jump_t, jump_F : ndarray
        Times [s] where v crossed the inflection velocity (either direction)
        and F [N] there, in time order.  On failure: IDA and CVODE keep the
        crossings found before the solver stopped; diffsol raises inside its
        ``solve`` and returns nothing, so they are empty.
    n_steps : int
        Accepted steps (IDA, CVODE: internal steps returned by the one-step
        solve; diffsol: output intervals of ``solve``, crossings not counted);
        -1 if unavailable.
    n_rhs : int
        Right-hand-side (IDA: residual) evaluations; -1 if the peer does not
        expose it (diffsol).
    wall_time : float
        Seconds spent in the integration call only.
    compile_time : float
        Seconds spent building the model in this call (JIT compilation,
        kernel loading, solver construction).
    status : str
        ``"ok"`` or ``"failed: <message>"``.
    """

    peer: str
    eps: float
    rtol: float
    atol: np.ndarray
    jump_t: np.ndarray
    jump_F: np.ndarray
    n_steps: int
    n_rhs: int
    wall_time: float
    compile_time: float
    status: str


# --------------------------------------------------------------------------
# availability
# --------------------------------------------------------------------------


def _import(peer: str):
    mod, pip = _PACKAGES[peer]
    try:
        return importlib.import_module(mod)
    except ImportError as exc:
        raise PeerUnavailableError(
            f"peer {peer!r} needs the package {pip!r} (import {mod}), which is not installed: "
            f"pip install {pip} (or the 'bench' extra: pip install peelapprox[bench])"
        ) from exc


@functools.cache
def _works(peer: str) -> bool:
    try:
        mod = _import(peer)
        if peer == "diffsol":
            ode = mod.Ode("u { 1.0 } F { -u }")
            return abs(float(ode.solve(np.zeros(0), 1.0).ys[0, -1]) - math.exp(-1.0)) < 1e-3
        if peer == "cvode":
            def rhs(t, y, yp):
                yp[0] = -y[0]
            r = mod.cvode.CVODE(rhs).solve([0.0, 1.0], [1.0])
        else:
            def res(t, y, yp, out):
                out[0] = yp[0] + y[0]
            r = mod.ida.IDA(res).solve([0.0, 1.0], [1.0], [-1.0])
        return bool(r.success) and abs(float(r.y[-1, 0]) - math.exp(-1.0)) < 1e-3
    except Exception:  # noqa: BLE001 - any failure means "not usable here"
        return False


def available_peers() -> tuple[str, ...]:
    """The peers whose package imports and solves a one-line ODE here.

    Returns
    -------
    tuple of str
        A subset of :data:`PEERS`, in that order.  The check runs once per
        process and peer.
    """
    return tuple(p for p in PEERS if _works(p))


# --------------------------------------------------------------------------
# the model in DiffSL
# --------------------------------------------------------------------------

#: Inputs of the DiffSL model, in order (``in_i``): physical parameters, the
#: inflection velocity, the initial state and the state scales (= atol).
DIFFSL_INPUTS = ("V", "I", "k", "R", "l", "eps", "vm", "a0", "w0", "F0", "v0", "sa", "sw", "sF", "sv")

#: Further inputs of the ``tangent=True`` model: the initial tangent δX and its scales.
DIFFSL_TANGENT_INPUTS = ("d0a", "d0w", "d0F", "d0v", "ta", "tw", "tF", "tv")



def _diffsl_expressions(geometry: str) -> dict:
    """DiffSL (C-syntax) expressions of c(α), φ_α, φ_ω, φ_F and φ_v, printed from the one symbolic source
    :mod:`peelapprox._symbolic` (``cos_theta_expr``, ``equations_of_motion``; fvV inside CONSTR), so the
    peer integrates the same model as every other solver without a second copy of the formulas.  The pull
    force is named ``Fp`` in DiffSL (``F_i`` is DiffSL's right-hand side)."""
    import sympy as sp

    from peelapprox import _symbolic as S

    Fp = sp.Symbol("Fp", real=True)
    alpha_dot, omega_dot, F_dot, constraint = S.equations_of_motion(S.c_)
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
    code["fp"] = sp.ccode(sp.diff(S.peel_force_expr(S.v, S.V), S.v))
    code["jac"] = [[sp.ccode(sp.expand(J[i, j]).xreplace(sub)) for j in range(4)] for i in range(4)]
    return code


def diffsl_code(geometry: str = "paper", *, tangent: bool = False) -> str:
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
    the Jacobian of :func:`peelapprox._symbolic.regularized_system`, printed with the
    closure's ``dc/dα`` and ``f' = ∂f/∂v`` of fvV.

    Parameters
    ----------
    geometry : {"paper", "exact"}
        Closure of ``cos θ`` (``PeelParams.geometry``).
    tangent : bool, keyword-only
        Append the variational equations (8 states instead of 4).

    Returns
    -------
    str
    """
    if geometry not in GEOMETRIES:
        raise ValueError(f"geometry must be one of {GEOMETRIES}, got {geometry!r}")
    names = DIFFSL_INPUTS + (DIFFSL_TANGENT_INPUTS if tangent else ())
    inputs = ", ".join(f"{n} = 1.0" for n in names)
    e = _diffsl_expressions(geometry)
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


def diffsl_model(geometry: str = "paper", *, tangent: bool = False):
    """JIT-compile :func:`diffsl_code` into a ``pydiffsol.Ode`` (dense LU, BDF).

    Raises
    ------
    PeerUnavailableError
        If pydiffsol is not installed.
    """
    ds = _import("diffsol")
    return ds.Ode(diffsl_code(geometry, tangent=tangent), matrix_type=ds.nalgebra_dense, ode_solver=ds.bdf)


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
    vm = branch_structure(params.V).v_inflection
    out = [params.V, params.I, params.k, params.R, params.l, eps, vm, *state, *scale]
    if tangent is not None:
        out += [*tangent, *(scale if tangent_scale is None else tangent_scale)]
    return np.array(out, dtype=float)


# --------------------------------------------------------------------------
# running a peer
# --------------------------------------------------------------------------


def _check(peer, params, t_end, eps, rtol, atol):
    choice("peer", peer, PEERS)
    _params("params", params)
    t_end, eps = duration("t_end", t_end), in_range("eps", eps, *EPS_RANGE)
    rt = in_range("rtol", rtol, 0.0, 1.0, lo_open=True, hi_open=True)
    if atol is not None:
        reals("atol", atol, 0.0)  # kind and sign; exact.simulate's parser checks the shape
    a = _atol_vector("regularized", rt, atol)  # exact.simulate's default and checks
    if np.any(a == 0.0):  # the DiffSL model divides by atol (it integrates X / atol)
        raise ValueError(f"atol must be in (0, inf) for the peers, got {atol!r}")
    return t_end, eps, rt, a


def _qvec(params, eps):
    from exact._regularized import param_vector

    return param_vector(params, eps)


def _run_sundials(peer, params, t_end, eps, rtol, atol, y0, vm):
    sun = _import(peer)
    c0 = time.perf_counter()
    from exact._regularized import _fun, _jac  # numba kernels: load / compile once per process

    q = _qvec(params, eps)
    q1 = q.copy()
    q1[7] = 1.0  # with eps = 1 the kernels give phi and d(phi)/dX themselves (M = I)
    _fun(y0, q), _jac(y0, q)
    mass = np.array([1.0, 1.0, 1.0, eps])
    mass_m = np.diag(mass)
    common = dict(rtol=rtol, atol=atol, num_events=1, max_num_steps=_MAX_NUM_STEPS, linsolver="dense")
    if peer == "cvode":
        def rhs(t, y, yp):
            yp[:] = _fun(y, q)

        def jac(t, y, yp, JJ):
            JJ[:, :] = _jac(y, q)

        def events(t, y, ev):
            ev[0] = y[3] - vm

        events.terminal, events.direction = [False], [0]
        solver = sun.cvode.CVODE(rhs, method="BDF", jacfn=jac, eventsfn=events, **common)
        args = ([0.0, t_end], y0)
    else:
        def res(t, y, yp, out):
            out[:] = mass * yp - _fun(y, q1)

        def jac_dae(t, y, yp, r, cj, JJ):  # IDA's signatures differ from CVODE's: own names (mypy [misc])
            JJ[:, :] = cj * mass_m - _jac(y, q1)

        def events_dae(t, y, yp, ev):
            ev[0] = y[3] - vm

        events_dae.terminal, events_dae.direction = [False], [0]
        solver = sun.ida.IDA(res, jacfn=jac_dae, eventsfn=events_dae, **common)
        args = ([0.0, t_end], y0, _fun(y0, q))  # consistent yp0 = M^-1 phi(y0)
    compile_time = time.perf_counter() - c0
    w0 = time.perf_counter()
    try:
        r = solver.solve(*args)
    except Exception as exc:  # noqa: BLE001 - report, never raise, a solver failure
        return dict(wall_time=time.perf_counter() - w0, compile_time=compile_time, status=f"failed: {exc}",
                    jump_t=np.zeros(0), jump_F=np.zeros(0), n_steps=-1, n_rhs=-1)
    wall = time.perf_counter() - w0
    jt = np.zeros(0) if r.t_events is None else np.asarray(r.t_events, float).copy()
    jF = np.zeros(0) if r.y_events is None else np.asarray(r.y_events, float)[:, 2].copy()
    t_last = float(r.t[-1]) if len(r.t) else float("nan")
    if not r.success:
        status = f"failed: {r.message} (status {r.status}, t={t_last:.9g})"
    elif not t_last == t_end:
        status = f"failed: stopped at t={t_last:.9g} before t_end={t_end}"
    else:
        status = "ok"
    return dict(wall_time=wall, compile_time=compile_time, status=status, jump_t=jt, jump_F=jF,
                n_steps=len(r.t) - 1, n_rhs=int(r.nfev))


#: pydiffsol ``Ode.options`` changed from their defaults to pass the folds
#: (see :func:`run_peer`): a fresh Newton matrix and right-hand-side Jacobian at
#: every step (defaults: after 20 and 50 steps) and ``min_timestep`` 1e-18
#: instead of 1e-13.
DIFFSOL_OPTIONS = dict(min_timestep=1e-18, update_jacobian_after_steps=1, update_rhs_jacobian_after_steps=1)


def _run_diffsol(params, t_end, eps, rtol, atol, y0):
    c0 = time.perf_counter()
    ode = diffsl_model(params.geometry)
    ode.rtol, ode.atol, ode.t0 = rtol, 1.0, 0.0  # scalar atol 1 on y = X / atol
    for name, val in DIFFSOL_OPTIONS.items():
        setattr(ode.options, name, val)
    p = diffsl_inputs(params, eps, y0, atol)
    compile_time = time.perf_counter() - c0
    w0 = time.perf_counter()
    try:
        sol = ode.solve(p, t_end)
    except Exception as exc:  # noqa: BLE001 - report, never raise, a solver failure
        return dict(wall_time=time.perf_counter() - w0, compile_time=compile_time, status=f"failed: {exc}",
                    jump_t=np.zeros(0), jump_F=np.zeros(0), n_steps=-1, n_rhs=-1)
    wall = time.perf_counter() - w0
    ts = np.asarray(sol.ts, float)
    ys = np.asarray(sol.ys, float)
    dup = np.nonzero(np.diff(ts) == 0.0)[0]  # stop + identity reset: the crossing is stored twice
    jt = ts[dup].copy()
    jF = ys[2, dup] * atol[2]
    status = "ok" if ts.size and ts[-1] == t_end else f"failed: stopped at t={ts[-1] if ts.size else 0:.9g}"
    return dict(wall_time=wall, compile_time=compile_time, status=status, jump_t=jt, jump_F=jF,
                n_steps=int(ts.size - 1 - dup.size), n_rhs=-1)


def run_peer(
    peer: str,
    params: PeelParams,
    t_end: float,
    *,
    eps: float,
    rtol: float,
    atol: None | float | Sequence[float] = None,
    alpha0: float = 0.0,
) -> PeerResult:
    """Integrate the ε-regularised system from 0 to ``t_end`` with an external peer.

    Parameters
    ----------
    peer : {"ida", "cvode", "diffsol"}
        See the module docstring.
    params : PeelParams
        Physical parameters and ``geometry`` (closure of ``cos θ``).
    t_end : float
        Final time [s], > 0.
    eps : float
        Regularisation ε > 0 (the paper: 1e-7).
    rtol : float
        Relative tolerance, in (0, 1).
    atol : None, float or 4 floats, optional
        Absolute tolerances for ``(α, ω, F, v)``, all > 0; default
        ``rtol * exact.ATOL_SCALE["regularized"]`` as in
        ``exact.simulate(method="regularized")``.
    alpha0 : float
        Initial α; the rest of the initial state is
        :func:`exact.initial_state` ``(params, alpha0=alpha0)``.

    Returns
    -------
    PeerResult
        Crossings of the inflection velocity, counters and timings.  A solver
        failure does not raise: ``status`` is ``"failed: <message>"``.

    Raises
    ------
    ValueError
        Unknown ``peer``, ``eps <= 0``, ``rtol`` outside (0, 1), bad
        ``t_end``/``atol``/``params``, or an ``alpha0`` with no consistent
        initial state; the message names the argument and its valid range.
    PeerUnavailableError
        (an ``ImportError``) if the peer's package is not installed.

    Notes
    -----
    Options set beyond tolerances: SUNDIALS ``max_num_steps`` = 1e8 (the
    whole run is one ``solve``), analytic Jacobians, dense LU, all else at
    SUNDIALS' defaults (BDF up to order 5).  diffsol: :data:`DIFFSOL_OPTIONS`.
    With diffsol's defaults the stale Jacobian across a fold makes Newton
    fail ("Exceeded maximum number of nonlinear solver failures") at, e.g.,
    ε = 1e-7, rtol = 1e-6, and the restart after a crossing needs steps
    below the default ``min_timestep`` = 1e-13 s ("Step size is too small")
    at ε = 1e-9 or rtol <= 1e-10.
    """
    t_end, eps, rtol, a = _check(peer, params, t_end, eps, rtol, atol)
    s0 = initial_state(params, alpha0=alpha0)
    _import(peer)
    y0 = np.array([s0.alpha, s0.omega, s0.F, s0.v])
    vm = branch_structure(params.V).v_inflection
    if peer == "diffsol":
        out = _run_diffsol(params, t_end, eps, rtol, a, y0)
    else:
        out = _run_sundials(peer, params, t_end, eps, rtol, a, y0, vm)
    return PeerResult(peer=peer, eps=eps, rtol=rtol, atol=a, **out)


# --------------------------------------------------------------------------
# the largest Lyapunov exponent from the regularised system's variational equations
# --------------------------------------------------------------------------

#: pydiffsol options of the tangent model: :data:`DIFFSOL_OPTIONS` and a
#: practically unlimited number of error-test failures per solve (the default,
#: 40, stops sporadic chunks at fold transits with "Exceeded maximum number of
#: error test failures": at V = 2, I = 1e-4, ε = 1e-7, rtol 1e-10 after 4 s, and
#: at ε = 1e-8 after 10-20 s; with this option the same runs complete).
TANGENT_OPTIONS = dict(DIFFSOL_OPTIONS, max_error_test_failures=100_000)


def _slow_tangent(params, x, w, scale):
    """A tangent vector with (α, ω, F) part ``w * scale`` and δv on the tangent of the slow manifold
    ``φ_v = 0`` (``∂φ_v/∂X · δX = 0``), so the first step needs no fast relaxation of δv."""
    from exact._regularized import _jac, param_vector

    Jx = _jac(np.asarray(x, float), param_vector(params, 1.0))  # eps = 1: ∂φ/∂X itself
    d = np.zeros(4)
    d[:3] = np.asarray(w, float) * scale
    d[3] = -float(Jx[3, :3] @ d[:3]) / float(Jx[3, 3])
    return d


def _state_dict(x) -> dict:
    return dict(zip(("alpha", "omega", "F", "v"), map(float, x)))


def tangent_solve(ode, params, eps: float, atol: np.ndarray, x, d, duration: float, *, t_start: float = 0.0):
    """One solve of the ``tangent=True`` model from state ``x`` and tangent ``d`` over ``duration`` seconds.

    ``ode`` is :func:`diffsl_model` ``(params.geometry, tangent=True)`` with ``rtol`` set and ``atol`` = 1;
    the state is scaled by ``atol`` and the tangent by the same scales.  Returns ``(x, d, steps,
    crossings)`` at the end.  A diffsol failure raises :class:`peelapprox.SolverFailure` carrying
    ``t_start`` (the model time of ``x``, for the message) and the state and tangent there.
    """
    try:
        sol = ode.solve(diffsl_inputs(params, eps, x, atol, d), duration)
    except RuntimeError as exc:
        raise SolverFailure(f"diffsol (tangent model) failed in the interval [{t_start:g}, {t_start + duration:g}] s: "
                            f"{exc}", t=t_start, state=dict(_state_dict(x), tangent=[float(z) for z in d])) from exc
    ts = np.asarray(sol.ts, float)
    ys = np.asarray(sol.ys, float)[:, -1]
    n_cross = int(np.count_nonzero(np.diff(ts) == 0.0))
    return ys[:4] * atol, ys[4:] * atol, int(ts.size - 1 - n_cross), n_cross


def lyapunov_regularized(
    params: PeelParams,
    *,
    eps: float = 1e-7,
    t_transient: float = T_TRANSIENT,
    T: float = 50.0,
    tau: float = 0.5,
    rtol: float = 1e-8,
    alpha0: float = 0.0,
    progress=None,
):
    """Largest Lyapunov exponent of the ε-regularised system (XDAE) from its variational equations, in bits/s.

    About 0.35 s of wall time per simulated second at V = 2.5, I = 1e-4, rtol 1e-8; needs pydiffsol (the
    ``bench`` extra).

    The state ``X = (α, ω, F, v)`` of ``M Ẋ = φ(X)`` and a tangent vector obeying
    ``M δẊ = (∂φ/∂X) δX`` are integrated together by diffsol's BDF (the ``tangent=True`` model of
    :func:`diffsl_code`; ∂φ/∂X printed from the symbolic model).  Nothing special happens at the jumps:
    at ε > 0 they are fast but smooth transits, which the variational equations follow (the hybrid
    solver's saltation matrices are their ε → 0 limit).  The tangent starts as ``(0.3, 0.3, 1)`` in the
    scaled variables ``(δα/1 rad, δω/(V/R), δF/f_max)`` of :func:`peelapprox.lyapunov`, with δv on the
    tangent of the slow manifold; every ``tau`` seconds its size in those variables is measured and the
    tangent divided by it (and the solve restarted).  The exponent is the mean log growth over the ``T``
    seconds after ``t_transient``.  Tolerances: diffsol's local error test with weights
    ``atol_i + rtol |y_i|`` on the state and the tangent, ``atol`` = ``rtol * exact.ATOL_SCALE["regularized"]``
    for both (the tangent's size is ~1 after each renormalisation).

    Parameters
    ----------
    params : PeelParams
    eps : float, keyword-only
        Regularisation ε > 0 (the paper: 1e-7).
    t_transient, T : float
        Seconds integrated before measuring (>= 0) and measured (> 0).
    tau : float
        Renormalisation interval [s], > 0; the last transient interval and the measured ones are shortened so
        that ``t_transient`` and ``T`` are whole numbers of intervals.
    rtol : float
        diffsol's relative tolerance, in (0, 1).
    alpha0 : float
        Initial α; the rest of the initial state is :func:`exact.initial_state`.
    progress : callable, optional
        Called as ``progress(t_done, t_total)`` after each interval.

    Returns
    -------
    peelapprox.LyapunovResult
        ``benettin.local`` holds the per-interval rates, ``benettin.running`` the running estimate,
        ``n_jumps`` the crossings of the inflection velocity in the measured window, ``notes`` the step
        count, the crossings and the number of solves.

    Raises
    ------
    ValueError
        Bad arguments (the message names the argument and its range).
    PeerUnavailableError
        pydiffsol is not installed.
    peelapprox.SolverFailure
        diffsol gave up (its message, and the state at the start of the failing interval, are attached).
    """
    from peelapprox._dynamics import BenettinResult, LyapunovResult, natural_scales

    T, tau = duration("T", T), duration("tau", tau)
    t_transient = duration("t_transient", t_transient, zero=True)
    _, eps, rtol, a = _check("diffsol", params, t_transient + T, eps, rtol, None)
    alpha0 = state("alpha0", alpha0, "alpha")
    progress = optional(function, "progress", progress)
    ode = diffsl_model(params.geometry, tangent=True)
    ode.rtol, ode.atol, ode.t0 = rtol, 1.0, 0.0
    for name, val in TANGENT_OPTIONS.items():
        setattr(ode.options, name, val)

    scale = natural_scales(params)
    s0 = initial_state(params, alpha0=alpha0)
    x = np.array([s0.alpha, s0.omega, s0.F, s0.v])
    d = _slow_tangent(params, x, np.array([0.3, 0.3, 1.0]) / math.sqrt(1.18), scale)
    n_tr = math.ceil(t_transient / tau - 1e-9) if t_transient > 0 else 0
    n = max(1, math.ceil(T / tau - 1e-9))
    chunks = ([t_transient / n_tr] * n_tr if n_tr else []) + [T / n] * n
    logs = np.empty(n)
    steps = crossings = window_crossings = 0
    t_done = 0.0
    wall0 = time.perf_counter()
    for i, dt in enumerate(chunks):
        x, d, st, nc = tangent_solve(ode, params, eps, a, x, d, dt, t_start=t_done)
        size = float(np.linalg.norm(d[:3] / scale))
        if not (math.isfinite(size) and size > 0.0):
            raise SolverFailure(f"the tangent became {size!r} in the interval starting at t = {t_done:g} s",
                                t=t_done, state=_state_dict(x))
        d /= size
        steps += st
        crossings += nc
        if i >= n_tr:
            logs[i - n_tr] = math.log(size)
            window_crossings += nc
        t_done += dt
        if progress is not None:
            progress(t_done, t_transient + T)
    b = BenettinResult.from_logs(logs, np.full(n, T / n), math.nan, time.perf_counter() - wall0)
    ln2 = math.log(2.0)
    return LyapunovResult(b.exponent, b.exponent / ln2, b.stderr / ln2, b, params, T / n, window_crossings,
                          method=f"variational equations of the ε-regularised system (ε = {eps:g}, diffsol BDF)",
                          notes=[f"steps={steps}", f"crossings={crossings}", f"solves={len(chunks)}",
                                 f"rtol={rtol:g}"])
