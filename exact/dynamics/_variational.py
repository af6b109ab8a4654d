"""The largest Lyapunov exponent of the ε-regularised system (XDAE) from its own variational equations.

The state ``X = (α, ω, F, v)`` of ``M Ẋ = φ(X)``, ``M = diag(1, 1, 1, ε)``, and a tangent vector obeying
``M δẊ = (∂φ/∂X) δX`` are integrated together by diffsol's BDF, on the ``tangent=True`` DiffSL model printed
from the symbolic source (:func:`peelapprox.kernels.diffsl_code`).  At ε > 0 the jumps are fast smooth
transits which the variational equations follow; the hybrid solver's saltation matrices
(:mod:`exact._tangent`) are their ε → 0 limit.

pydiffsol is optional (the ``bench`` extra); it is imported when the model is compiled, and a missing
package raises :class:`peelapprox.kernels.PeerUnavailableError` (an ``ImportError``) naming the extra.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from peelapprox import EPS_DEFAULT, T_TRANSIENT, SolverFailure
from peelapprox.kernels import (
    ALL_LAWS,
    DIFFSOL_OPTIONS,
    compiled_law,
    diffsl_inputs,
    diffsl_model,
    regularized_field_jacobian,
    regularized_law_field,
    regularized_parameters,
)
from peelapprox.validate import duration, function, in_range, optional, state
from peelapprox.validate import eps as _eps
from peelapprox.validate import params as _params

from .._initial import initial_state
from .._method_contract import default_atol

if TYPE_CHECKING:  # pragma: no cover
    from peelapprox import PeelParams

    from ._benettin import LyapunovResult

__all__ = ["TANGENT_OPTIONS", "VARIATIONAL_LAWS", "VARIATIONAL_LAWS_NOTE", "lyapunov_variational", "tangent_solve"]

#: Who refuses a tabulated law, and why (the ``where`` of the refusal): the DiffSL model is printed from the law's
#: sympy form, which a table does not have.
VARIATIONAL_LAWS_NOTE = ("lyapunov method 'variational' (lyapunov_variational: its DiffSL model is printed from the "
                         "law's closed form, which a table lacks; the methods 'two-trajectory', 'tangent' and "
                         "'return-map' run any law)")
#: The laws the variational method runs (:func:`peelapprox._law.law_label` names): every law with a closed form.
VARIATIONAL_LAWS = tuple(x for x in ALL_LAWS if x not in ("tabulated", "smoothed"))  # no closed form

#: pydiffsol options of the tangent model: :data:`peelapprox.kernels.DIFFSOL_OPTIONS` and a
#: practically unlimited number of error-test failures per solve (the default,
#: 40, stops sporadic chunks at fold transits with "Exceeded maximum number of
#: error test failures": at V = 2, I = 1e-4, ε = 1e-7, rtol 1e-10 after 4 s, and
#: at ε = 1e-8 after 10-20 s; with this option the same runs complete).
TANGENT_OPTIONS = dict(DIFFSOL_OPTIONS, max_error_test_failures=100_000)


def _slow_tangent(params, x, w, scale):
    """A tangent vector with (α, ω, F) part ``w * scale`` and δv on the tangent of the slow manifold
    ``φ_v = 0`` (``∂φ_v/∂X · δX = 0``), so the first step needs no fast relaxation of δv."""
    y = np.asarray(x, float)
    cl = compiled_law(params.force, params.V)
    if cl.inlined:
        Jx = regularized_field_jacobian(y, regularized_parameters(params, 1.0))  # eps = 1: ∂φ/∂X
    else:
        Jx = regularized_law_field()[1](y, regularized_parameters(params, 1.0, ALL_LAWS), cl.fn, cl.coef)
    d = np.zeros(4)
    d[:3] = np.asarray(w, float) * scale
    d[3] = -float(Jx[3, :3] @ d[:3]) / float(Jx[3, 3])
    return d


def _state_dict(x) -> dict:
    return dict(zip(("alpha", "omega", "F", "v"), map(float, x)))


def tangent_solve(ode, params, eps: float, atol: np.ndarray, x, d, duration: float, *, t_start: float = 0.0):
    """One solve of the ``tangent=True`` model from state ``x`` and tangent ``d`` over ``duration`` seconds.

    ``ode`` is :func:`peelapprox.kernels.diffsl_model` ``(params.geometry, tangent=True)`` with ``rtol`` set
    and ``atol`` = 1; the state is scaled by ``atol`` and the tangent by the same scales.  Returns ``(x, d, steps,
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


def lyapunov_variational(params: PeelParams, *, eps: float = EPS_DEFAULT, t_transient: float = T_TRANSIENT,
                         T: float = 50.0, tau: float = 0.5, rtol: float = 1e-8, alpha0: float = 0.0,
                         progress: Callable[[float, float], None] | None = None) -> LyapunovResult:
    """Largest Lyapunov exponent of the ε-regularised system (XDAE) from its variational equations, in bits/s.

    About 0.35 s of wall time per simulated second at V = 2.5, I = 1e-4, rtol 1e-8; needs pydiffsol (the
    ``bench`` extra).

    The state ``X = (α, ω, F, v)`` of ``M Ẋ = φ(X)`` and a tangent vector obeying
    ``M δẊ = (∂φ/∂X) δX`` are integrated together by diffsol's BDF (the ``tangent=True`` model of
    :func:`peelapprox.kernels.diffsl_code`; ∂φ/∂X printed from the symbolic model).  Nothing special happens
    at the jumps:
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
        Bad arguments (the message names the argument and its range); a law ``params.force`` other than the
        paper's (the message names the method and the law: the DiffSL model is printed from fvV only, for now).
    peelapprox.kernels.PeerUnavailableError
        (an ``ImportError``) pydiffsol is not installed (``pip install peelapprox[bench]``).
    peelapprox.SolverFailure
        diffsol gave up (its message, and the state at the start of the failing interval, are attached).
    """
    from .._shared import natural_scales
    from ._benettin import BenettinResult, LyapunovResult

    T, tau, t_transient, eps, rtol, atol, alpha0, progress = _checked_arguments(params, eps, t_transient, T, tau,
                                                                                rtol, alpha0, progress)
    ode = _tangent_model(params, rtol)
    scale = natural_scales(params)
    s0 = initial_state(params, alpha0=alpha0)
    x = np.array([s0.alpha, s0.omega, s0.F, s0.v])
    d = _slow_tangent(params, x, np.array([0.3, 0.3, 1.0]) / math.sqrt(1.18), scale)
    n_tr = math.ceil(t_transient / tau - 1e-9) if t_transient > 0 else 0
    n = max(1, math.ceil(T / tau - 1e-9))
    chunks = ([t_transient / n_tr] * n_tr if n_tr else []) + [T / n] * n
    wall0 = time.perf_counter()
    logs, steps, crossings, window_crossings = _intervals(ode, params, eps, atol, x, d, chunks, n_tr, scale,
                                                          progress, t_transient + T)
    b = BenettinResult.from_logs(logs, np.full(n, T / n), 1.0, time.perf_counter() - wall0)  # unit tangent
    ln2 = math.log(2.0)
    return LyapunovResult(b.exponent, b.exponent / ln2, b.stderr / ln2, b, params, T / n, window_crossings,
                          method=f"variational equations of the ε-regularised system (ε = {eps:g}, diffsol BDF)",
                          notes=[f"steps={steps}", f"crossings={crossings}", f"solves={len(chunks)}",
                                 f"rtol={rtol:g}"])


def _checked_arguments(params, eps, t_transient, T, tau, rtol, alpha0, progress) -> tuple:
    """:func:`lyapunov_variational`'s arguments checked, in this order (the first bad one is named), with the
    atol of ``rtol``: ``(T, tau, t_transient, eps, rtol, atol, alpha0, progress)``."""
    T, tau = duration("T", T), duration("tau", tau)
    t_transient = duration("t_transient", t_transient, zero=True)
    _params("params", params, laws=VARIATIONAL_LAWS, where=VARIATIONAL_LAWS_NOTE)
    from .._shared import paper_model_only

    paper_model_only(params, "lyapunov method 'variational' (the paper's eps-scheme)", "use method='two-trajectory'")
    duration("t_end", t_transient + T)  # the checks of the regularised runs (comparisons' run_peer)
    eps = _eps("eps", eps)
    rtol = in_range("rtol", rtol, 0.0, 1.0, lo_open=True, hi_open=True)
    atol = default_atol("regularized", rtol)
    alpha0 = state("alpha0", alpha0, "alpha")
    progress = optional(function, "progress", progress)
    return T, tau, t_transient, eps, rtol, atol, alpha0, progress


def _tangent_model(params: PeelParams, rtol: float):
    """The compiled tangent DiffSL model of ``params`` (scaled atol 1, :data:`TANGENT_OPTIONS`)."""
    ode = diffsl_model(params.geometry, tangent=True, force=params.force)
    ode.rtol, ode.atol, ode.t0 = rtol, 1.0, 0.0
    for name, val in TANGENT_OPTIONS.items():
        setattr(ode.options, name, val)
    return ode


def _intervals(ode, params: PeelParams, eps: float, atol: np.ndarray, x: np.ndarray, d: np.ndarray,
               chunks: list[float], n_tr: int, scale: np.ndarray,
               progress: Callable[[float, float], None] | None, t_total: float) -> tuple[np.ndarray, int, int, int]:
    """State and tangent solved over ``chunks`` (the first ``n_tr`` the transient), the tangent renormalised after
    each (``progress(t_done, t_total)``): the measured intervals' log growths, the steps, the crossings and those
    of the measured window."""
    logs = np.empty(len(chunks) - n_tr)
    steps = crossings = window_crossings = 0
    t_done = 0.0
    for i, dt in enumerate(chunks):
        x, d, st, nc = tangent_solve(ode, params, eps, atol, x, d, dt, t_start=t_done)
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
            progress(t_done, t_total)
    return logs, steps, crossings, window_crossings
