"""The SUNDIALS peers through scikit-sundae: IDA on the residual ``M Ẋ − φ(X)`` and CVODE on ``Ẋ = M⁻¹ φ(X)``,
both BDF with the analytic Jacobian and dense LU, the crossings of ``v = v_infl`` by their root finders
(:mod:`comparisons.benchmark.peers` has the common rules)."""

from __future__ import annotations

import math
import time

import numpy as np

from peelapprox.kernels import (
    ALL_LAWS,
    Q_EPS,
    compiled_law,
    regularized_field,
    regularized_field_jacobian,
    regularized_law_field,
    regularized_parameters,
)

__all__ = ["run", "smoke"]

#: Step budget passed to SUNDIALS (its default, 500 per output interval, is far too small for save-every-step solves).
_MAX_NUM_STEPS = 100_000_000


def smoke(sun, peer: str) -> bool:
    """Whether CVODE or IDA (``peer``) of the imported sksundae ``sun`` solves ``y' = -y`` to 1e-3."""
    if peer == "cvode":
        def rhs(t, y, yp):
            yp[0] = -y[0]
        r = sun.cvode.CVODE(rhs).solve([0.0, 1.0], [1.0])
    else:
        def res(t, y, yp, out):
            out[0] = yp[0] + y[0]
        r = sun.ida.IDA(res).solve([0.0, 1.0], [1.0], [-1.0])
    return bool(r.success) and abs(float(r.y[-1, 0]) - math.exp(-1.0)) < 1e-3


def run(sun, peer, params, t_end, eps, rtol, atol, y0, vm):
    """Integrate with IDA or CVODE (``sun``: the imported sksundae) from ``y0``; the fields of a PeerResult."""
    c0 = time.perf_counter()
    cl = compiled_law(params.force, params.V)  # the paper's law: fvV inlined in the field (the default)
    q = regularized_parameters(params, eps, ("paper",) if cl.inlined else ALL_LAWS)
    q1 = q.copy()
    q1[Q_EPS] = 1.0  # with eps = 1 the kernels give phi and d(phi)/dX themselves (M = I)
    if cl.inlined:
        field, field_jac = regularized_field, regularized_field_jacobian
    else:  # the law as an argument: every law, tables included
        lfun, ljac = regularized_law_field()
        field = lambda y, q: lfun(y, q, cl.fn, cl.coef)  # noqa: E731
        field_jac = lambda y, q: ljac(y, q, cl.fn, cl.coef)  # noqa: E731
    field(y0, q), field_jac(y0, q)
    mass = np.array([1.0, 1.0, 1.0, eps])
    mass_m = np.diag(mass)
    common = dict(rtol=rtol, atol=atol, num_events=1, max_num_steps=_MAX_NUM_STEPS, linsolver="dense")
    if peer == "cvode":
        def rhs(t, y, yp):
            yp[:] = field(y, q)

        def jac(t, y, yp, JJ):
            JJ[:, :] = field_jac(y, q)

        def events(t, y, ev):
            ev[0] = y[3] - vm

        events.terminal, events.direction = [False], [0]
        solver = sun.cvode.CVODE(rhs, method="BDF", jacfn=jac, eventsfn=events, **common)
        args = ([0.0, t_end], y0)
    else:
        def res(t, y, yp, out):
            out[:] = mass * yp - field(y, q1)

        def jac_dae(t, y, yp, r, cj, JJ):  # IDA's signatures differ from CVODE's: own names (mypy [misc])
            JJ[:, :] = cj * mass_m - field_jac(y, q1)

        def events_dae(t, y, yp, ev):
            ev[0] = y[3] - vm

        events_dae.terminal, events_dae.direction = [False], [0]
        solver = sun.ida.IDA(res, jacfn=jac_dae, eventsfn=events_dae, **common)
        args = ([0.0, t_end], y0, field(y0, q))  # consistent yp0 = M^-1 phi(y0)
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
