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
    mass matrix M, the model written in DiffSL
    (:func:`peelapprox.kernels.diffsl_code`, printed from the symbolic source) and
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
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from exact import lyapunov_variational as lyapunov_regularized
from exact._simulate import _atol_vector, initial_state
from peelapprox._params import EPS_RANGE
from peelapprox._peelforce import branch_structure
from peelapprox._validate import choice, duration, in_range, reals
from peelapprox._validate import params as _params
from peelapprox.kernels import (
    DIFFSL_INPUTS,
    DIFFSL_TANGENT_INPUTS,
    DIFFSOL_OPTIONS,
    PeerUnavailableError,
    diffsl_code,
    diffsl_inputs,
    diffsl_model,
    import_optional,
)

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
    "DIFFSL_INPUTS",
    "DIFFSL_TANGENT_INPUTS",
    "DIFFSOL_OPTIONS",
    "TANGENT_OPTIONS",  # noqa: F822 - moved to exact._variational, re-exported by __getattr__ below
    "tangent_solve",  # noqa: F822 - idem
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
    return import_optional(mod, pip, f"peer {peer!r}")


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


def __getattr__(name: str):
    """``TANGENT_OPTIONS`` and ``tangent_solve`` moved with the ε-variational Lyapunov exponent
    (``lyapunov_regularized``, now :func:`exact.lyapunov_variational`) to :mod:`exact._variational`."""
    if name in ("TANGENT_OPTIONS", "tangent_solve"):
        from exact import _variational

        return getattr(_variational, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
