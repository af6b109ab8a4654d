"""The peel front's compiled loop: DOP853 on the front's field, the mean front's jumps, the local branch switches,
output and breakdown checks, all inside one numba function (:func:`run_front`), entered from Python only when a
buffer fills, a step budget of the call is spent or the run ends (:mod:`exact.front._run`).

Integrator: :mod:`peelapprox._compiled._dop853` (the package's one compiled integrator, scipy's tolerance semantics) on
the
state of :func:`peelapprox.kernels.front_rhs`.  Every step costs O(N) (13 field evaluations, each two passes over
the strips) and allocates nothing: the work arrays come from Python.

Events, located on the step's 7th-order dense output:

* the **mean front's jump**: v̄ = mean v_j crossing the inflection velocity v_infl of f, as the tape-mass model's
  driver records its jumps (``exact.simulate(method="smooth")``); root of the interpolated mean by the package's
  Illinois regula falsi (``solve_theta_mean`` of :mod:`peelapprox.kernels`; each evaluation O(N));
* a **local branch switch**: strip j's v_j crossing v_infl within a step (one per strip and step: two crossings
  of one strip inside one step are not seen, a step being far shorter than a local switch's transit).
"""

from __future__ import annotations

import numpy as np
from numba import types as _t

from peelapprox.kernels import (
    FQ_GAMMA,
    FQ_N,
    FQ_PERIODIC,
    FY_ALPHA,
    FY_EAE,
    FY_OMEGA,
    FY_STRIPS,
    LAW_TYPE,
    N_STAGES,
    STEP_FAILED,
    interp,
    kernel,
    make_dop853,
    solve_theta,
    solve_theta_mean,
)
from peelapprox.kernels import front_rhs as _rhs

_dop = make_dop853(_rhs)

# statuses
DONE, OUT_FULL, JUMPS_FULL, LOCAL_FULL, PAUSE, STEP_FAIL, ARREST, SLACK, DOMAIN, NONFINITE = range(10)
# st: the driver's state between calls (S_NEXT_SAVE: the index k of the next grid point k dt_save)
S_T, S_H, S_NEXT_SAVE, S_BAD_J = range(4)
N_ST = 4
# counters
C_STEPS, C_REJ, C_RHS, C_JUMPS, C_LOCAL, C_NOUT, C_NJOUT, C_NLOUT = range(8)
N_C = 8
# global output columns (one row per stored point)
G_T, G_ALPHA, G_OMEGA, G_F, G_V, G_PAE, G_EAE, G_PHI, G_W, G_NDW, G_WIN, G_WPEEL = range(12)
N_G = 12
# opts: rtol, t_end, t_store, v_mid, v_arrest, v_lo, v_hi, dt_save (0: every step)
O_RTOL, O_TEND, O_TSTORE, O_VMID, O_VARREST, O_VLO, O_VHI, O_DTSAVE = range(8)
N_O = 8


@kernel(inline="always")
def _mean_v(y, n):
    s = 0.0
    for j in range(n):
        s += y[FY_STRIPS + n + j]
    return s / n


@kernel(inline="always")
def _diag(t, y, q, v_mid, row):
    """The global columns (G_*) of the state y at time t into ``row``."""
    n = int(q[FQ_N])
    sF = 0.0
    sv = 0.0
    sl = 0.0
    sl2 = 0.0
    up = 0
    ndw = 0
    pae = 0.0
    for j in range(n):
        v = y[FY_STRIPS + n + j]
        sF += y[FY_STRIPS + j]
        sv += v
        lv = np.log(v)
        sl += lv
        sl2 += lv * lv
        if v > v_mid:
            up += 1
        if j > 0:
            d = v - y[FY_STRIPS + n + j - 1]
            pae += d * d
            if (v > v_mid) != (y[FY_STRIPS + n + j - 1] > v_mid):
                ndw += 1
    if q[FQ_PERIODIC] != 0.0 and n > 1:  # periodic: the bond N-1 -- 0
        d = y[FY_STRIPS + n] - y[FY_STRIPS + 2 * n - 1]
        pae += d * d
        if (y[FY_STRIPS + n] > v_mid) != (y[FY_STRIPS + 2 * n - 1] > v_mid):
            ndw += 1
    ml = sl / n
    var = sl2 / n - ml * ml
    row[G_T] = t
    row[G_ALPHA] = y[FY_ALPHA]
    row[G_OMEGA] = y[FY_OMEGA]
    row[G_F] = sF / n
    row[G_V] = sv / n
    row[G_PAE] = q[FQ_GAMMA] * pae
    row[G_EAE] = y[FY_EAE]
    row[G_PHI] = up / n
    row[G_W] = np.sqrt(var) if var > 0.0 else 0.0
    row[G_NDW] = ndw
    row[G_WIN] = y[FY_STRIPS + 2 * n]
    row[G_WPEEL] = y[FY_STRIPS + 2 * n + 1]


@kernel(inline="always")
def _store(t, y, q, v_mid, out_g, out_y, cnt, store_front):
    i = cnt[C_NOUT]
    _diag(t, y, q, v_mid, out_g[i])
    if store_front:
        for k in range(out_y.shape[1]):
            out_y[i, k] = y[FY_STRIPS + k]
    cnt[C_NOUT] = i + 1


@kernel(inline="always")
def _checks(y, n, opts, st):
    """A status for the accepted state y (DONE: none), the offending strip in st[S_BAD_J]."""
    sF = 0.0
    for i in range(y.shape[0]):
        if not np.isfinite(y[i]):
            return NONFINITE
    for j in range(n):
        v = y[FY_STRIPS + n + j]
        sF += y[FY_STRIPS + j]
        if not v > opts[O_VARREST]:
            st[S_BAD_J] = j
            return ARREST
        if not opts[O_VLO] <= v <= opts[O_VHI]:
            st[S_BAD_J] = j
            return DOMAIN
    if not sF > 0.0:
        return SLACK
    return DONE


@kernel(inline="always")
def _mean_jump(t, h_done, y, y_new, K, P, Fc, tmp, cnt, jbuf, n, v_mid, t_store, dense):
    """The mean front's jump in the step from (t, y) to y_new, if v̄ crossed v_mid: counted, and stored in jbuf
    from t_store on; returns whether the dense output is built."""
    vm0, vm1 = _mean_v(y, n), _mean_v(y_new, n)
    if (vm0 > v_mid) == (vm1 > v_mid):
        return dense
    dense = _dop.ensure_dense(dense, y, y_new, K, h_done, P, Fc, tmp, cnt, C_RHS)
    x = solve_theta_mean(y, Fc, FY_STRIPS + n, n, v_mid, vm0 - v_mid, 1.0, vm1 - v_mid)
    tj = t + x * h_done
    cnt[C_JUMPS] += 1
    if tj >= t_store:
        interp(y, Fc, x, tmp)
        k = cnt[C_NJOUT]
        jbuf[k, 0] = tj
        jbuf[k, 1] = 1.0 if vm0 > v_mid else 0.0
        jbuf[k, 2] = 1.0 if vm1 > v_mid else 0.0
        jbuf[k, 3] = tmp[FY_ALPHA]
        jbuf[k, 4] = tmp[FY_OMEGA]
        sF = 0.0
        for j in range(n):
            sF += tmp[FY_STRIPS + j]
        jbuf[k, 5] = sF / n
        jbuf[k, 6] = v_mid
        jbuf[k, 7] = v_mid
        cnt[C_NJOUT] = k + 1
    return dense


@kernel(inline="always")
def _local_switches(t, h_done, y, y_new, K, P, Fc, tmp, cnt, lbuf, n, v_mid, t_store, dense):
    """Every strip whose v_j crossed v_mid in the step: counted, and stored in lbuf from t_store on; returns
    whether the dense output is built."""
    for j in range(n):
        i = FY_STRIPS + n + j
        if (y[i] > v_mid) != (y_new[i] > v_mid):
            dense = _dop.ensure_dense(dense, y, y_new, K, h_done, P, Fc, tmp, cnt, C_RHS)
            x = solve_theta(y, Fc, i, v_mid, y[i] - v_mid, 1.0, y_new[i] - v_mid)
            cnt[C_LOCAL] += 1
            tl = t + x * h_done
            if tl >= t_store:
                k = cnt[C_NLOUT]
                lbuf[k, 0] = tl
                lbuf[k, 1] = j
                lbuf[k, 2] = 1.0 if y_new[i] > v_mid else 0.0
                cnt[C_NLOUT] = k + 1
    return dense


@kernel(inline="always")
def _save_grid(t, t_new, h_done, y, y_new, K, P, Fc, tmp, ye, cnt, st, q, v_mid, t_store, dt_save, out_g, out_y,
               store_front, dense):
    """Store the grid points k dt_save in (t, t_new] (from t_store on) from the dense output; returns whether it
    is built."""
    while st[S_NEXT_SAVE] * dt_save <= t_new:
        ts = st[S_NEXT_SAVE] * dt_save
        if ts >= t_store:
            dense = _dop.ensure_dense(dense, y, y_new, K, h_done, P, Fc, tmp, cnt, C_RHS)
            x = (ts - t) / h_done
            interp(y, Fc, min(max(x, 0.0), 1.0), ye)
            _store(ts, ye, q, v_mid, out_g, out_y, cnt, store_front)
        st[S_NEXT_SAVE] += 1.0
    return dense


_A1, _A2 = _t.float64[::1], _t.float64[:, ::1]
#: The one signature of :func:`run_front` (the law a typed function argument, so the loop is compiled once per
#: machine and runs every compiled law).
RUN_SIG = _t.int64(_A1, _A1, _A1, LAW_TYPE, _A1, _A1, _A1, _A2, _A2, _A2, _A2, _t.int64[::1], _t.int64, _t.boolean,
                   _A2, _A1, _A1, _A1, _A2, _A1, _A2)


@kernel(signature=RUN_SIG, nrt=False, lazy=True)
def run_front(y, st, q, law, coef, atol, opts, out_g, out_y, jbuf, lbuf, cnt, max_call_steps, store_front,
              K, y_new, tmp, sc, Fc, ye, work):
    """Advance the front from ``(st[S_T], y)`` until t_end, a full buffer, a failure or ``max_call_steps`` steps;
    returns the status (module constants).  ``y`` and ``st`` are updated in place to the last accepted state."""
    P = (q, law, coef)
    n = int(q[FQ_N])
    rtol, t_end, t_store, v_mid, dt_save = opts[O_RTOL], opts[O_TEND], opts[O_TSTORE], opts[O_VMID], opts[O_DTSAVE]
    t = st[S_T]
    h = st[S_H]
    calls = 0
    _rhs(y, P, K[0])
    cnt[C_RHS] += 1
    if cnt[C_STEPS] == 0 and dt_save == 0.0 and t >= t_store and cnt[C_NOUT] == 0:
        _store(t, y, q, v_mid, out_g, out_y, cnt, store_front)
    if not h > 0.0:
        h = _dop.initial_step(y, K[0], P, rtol, atol, work)
        cnt[C_RHS] += 1
    while t < t_end:
        if calls >= max_call_steps:
            return PAUSE
        if cnt[C_NOUT] >= out_g.shape[0]:
            return OUT_FULL
        if cnt[C_NJOUT] >= jbuf.shape[0]:
            return JUMPS_FULL
        if cnt[C_NLOUT] + n > lbuf.shape[0]:
            return LOCAL_FULL
        h = min(h, t_end - t)
        if dt_save > 0.0 and cnt[C_NOUT] + h / dt_save + 2.0 > out_g.shape[0]:
            return OUT_FULL
        for i in range(y.shape[0]):
            tmp[i] = K[0, i]
        status, h_done, h_next, n_rej, n_rhs = _dop.step(y, tmp, h, P, rtol, atol, K, y_new, ye, sc)
        cnt[C_REJ] += n_rej
        cnt[C_RHS] += n_rhs
        if status == STEP_FAILED:
            st[S_H] = h_done
            return STEP_FAIL
        bad = _checks(y_new, n, opts, st)
        if bad != DONE:
            st[S_H] = h_done
            return bad
        t_new = t + h_done
        if t_new > t_end or t_end - t_new < 1e-15 * t_end:
            t_new = t_end
        dense = _mean_jump(t, h_done, y, y_new, K, P, Fc, tmp, cnt, jbuf, n, v_mid, t_store, False)
        if n > 1:
            dense = _local_switches(t, h_done, y, y_new, K, P, Fc, tmp, cnt, lbuf, n, v_mid, t_store, dense)
        if dt_save > 0.0:
            dense = _save_grid(t, t_new, h_done, y, y_new, K, P, Fc, tmp, ye, cnt, st, q, v_mid, t_store, dt_save,
                               out_g, out_y, store_front, dense)
        elif t_new >= t_store:
            _store(t_new, y_new, q, v_mid, out_g, out_y, cnt, store_front)
        for i in range(y.shape[0]):
            y[i] = y_new[i]
            K[0, i] = K[N_STAGES, i]
        t = t_new
        h = h_next
        st[S_T] = t
        st[S_H] = h
        cnt[C_STEPS] += 1
        calls += 1
    return DONE
