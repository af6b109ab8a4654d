"""The hybrid (ε → 0) solver: a compiled, event-driven DOP853 integrator.

Formulation
-----------
The paper's DAE (FLOW1, FLOW2, flow3, CONSTR) is index 1 on each stable branch
of ``f`` and has impasse points at the folds, where ``f'(v) = 0`` and the root
``v(G)`` of CONSTR has a square-root singularity.  We never solve CONSTR for v.
Instead CONSTR is solved for the pull force, which is always well posed
(``1 - cos θ = 1 + c(α) > 0``)::

    F = f(v, V) / (1 + c(α))                                     (CONSTR)

and ``u = ln v`` is carried as a state obeying the differentiated constraint
Eq. (vdot), ``f'(v) v̇ = Ġ`` with ``G = F (1 + c)``.  Time is then
reparametrised by ``dt/ds = v f'(v) = ∂f/∂(ln v)`` (a desingularisation of the
impasse point)::

    dt/ds = v f'(v)
    dα/ds = v f'(v) (ω - v/R)                                     (FLOW1)
    dω/ds = v f'(v) (-F R c(α) / I)                               (FLOW2)
    du/ds = Ġ,   Ġ = Ḟ (1 + c) + F c'(α) α̇,  Ḟ from flow3        (vdot)

This vector field is smooth through the folds: the fold is simply the
transversal event ``v = v_max`` (on AB) or ``v = v_min`` (on CD), where
``du/ds = Ġ ≠ 0``.  At the fold ``dt/ds = dα/ds = dω/ds = 0``, so the event
time, α, ω and F are *stationary* in s: an error δs in locating the event
costs only O(δs²) in the jump time and jump state.  Along the branch f' > 0
and ``t(s)`` is increasing, so the branch solution is the DAE solution, with
the constraint satisfied to rounding by construction.

Why ``v f'`` rather than ``f'``: on AB ``f' ∝ v^-0.85`` swings by a factor ~3
within one inertial α-oscillation (v oscillates), while ``v f' ≈ 16.5 v^0.15``
barely moves; measured at V=1, I=1e-5 this saves 35 % of the steps at equal
jump-time error.

Why ``u = ln v`` rather than v: v > 0 by construction, and v is controlled
relatively (the error test sees ``δv/v``) down to the model's breakdown.  On
AB the level ``G = f(v)`` approaches ``f(0+, V)`` as ``110 v^0.15``, so v must
be followed over some 60 decades before G is within rounding of f(0+): with v
as the state (absolute tolerance ~1e-14 m/s) the run had to stop at a floor
``v = 1e-9`` m/s where G was still ~5 N above f(0+) — a numerical stop
reported as a breakdown.  In u, ``du/ds = Ġ`` is smooth and
bounded there, and the breakdown is declared by the model's criterion:
``G - f(0+) <= BREAKDOWN_LEVEL`` (1e-10 relative), i.e. ``v <= v_breakdown``
(~1e-67 m/s, :class:`peelapprox.BranchStructure`).

At the fold v jumps to the landing root on the other branch (``f = f_max`` on
CD, or ``f = f_min`` on AB) with (α, ω, F) continuous: this is the ε → 0 limit
of the paper's singularly perturbed scheme (the fast fibre is ``α, ω, F`` =
const).

Folded singularities
--------------------
Where the fold is reached with ``Ġ = 0`` (a folded singularity: v̇ = Ġ/f'
stays finite, the canard point of the fold) the desingularised field has an
equilibrium on the fold and the solution approaches ``v_fold`` only
exponentially in s, with t increments that shrink below the step's error
tolerance.  Two guards keep this finite and monotone: the fold event fires at
``v_fold (1 ∓ FOLD_REL)`` (relative 1e-9; after a transversal approach this
moves the jump time by ``f''(δ v_fold)²/(2Ġ)``, below 1e-16 s on the paper's
scenes, and by ``δ v_fold/|v̇|`` near a folded singularity, ~1e-11 s), and
``τ`` is kept non-decreasing from step to step (τ does not enter the field,
so this changes nothing else).  The jump itself is taken at ``v = v_fold``
exactly, so the stored before-jump state lies on the fold.  Found by the
trajectory-invariant property test (``tests/test_properties.py``) at V = 3.875,
I = 10^-3.25, α0 = 0.25, where stored time went back by 8.5e-13 s.

Integrator
----------
The one compiled integrator of the package, :mod:`peelapprox._compiled._dop853`
(Dormand–Prince 8(5,3), scipy's coefficients and controller, scipy's
tolerance semantics), on the state ``y = (τ, α, ω, ln v)`` where ``τ = t - t_seg``
is the time since the segment started (so the error control of the time is
relative to the segment duration, not to the absolute time).  This module is
its event driver: folds, jumps, t_end, output and breakdown checks.

Everything per step runs inside one numba function; Python is entered only
when an output buffer fills or the run ends.  That function, :func:`_run`, is
compiled twice by :mod:`exact._hybrid_driver`: with the paper's law fvV inlined
(the default) and with the peel-force law as a typed function argument.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from peelapprox.kernels import (
    MAX_REJECTIONS,
    N_M,
    STEP_FAILED,
    crossing,
    interp,
    interp1,
    kernel,
    solve_theta,
    state_at,
    workspace,
)
from peelapprox.kernels import N_STAGES as _NS
from peelapprox.kernels import status as _st

# the field, in its own module, is read through this one too (exact._hybrid_driver, exact._tangent, tests)
from ._hybrid_field import _closure
from ._hybrid_field import _field as _field
from ._hybrid_field import _rhs as _rhs
from ._hybrid_field import pull_force as pull_force

DONE, OUT_FULL, JUMPS_FULL, PAUSE, STEP_FAIL = _st.DONE, _st.OUT_FULL, _st.JUMPS_FULL, _st.PAUSE, _st.STEP_FAIL
NO_ROOT, NO_LANDING, GEOMETRY, V_CEILING = _st.NO_ROOT, _st.NO_LANDING, _st.GEOMETRY, _st.V_CEILING

# ---------------------------------------------------------------- layouts
# parameter vector: the model block of peelapprox.kernels (M_V ... M_GEOM), then this driver's fields
# (v-valued entries are velocities [m/s]; the U entries their logarithms, the state's variable)
(P_VMAX, P_VMIN, P_VLCD, P_VLAB, P_UFLOOR, P_UCEIL, P_FOLDS, P_UEV_AB, P_UEV_CD) = range(N_M, N_M + 9)
N_P = N_M + 9
# solver state vector (S_U holds u = ln v)
S_T0, S_TAU, S_AL, S_OM, S_U, S_H, S_BR = range(7)
N_S = 7
# counters
C_STEPS, C_REJ, C_RHS, C_JUMPS, C_NOUT, C_NJOUT, C_TEVAL = range(7)
N_C = 7
# output columns
O_T, O_AL, O_OM, O_F, O_V = range(5)
N_O = 5
# jump columns, the order of exact.Jumps.from_buffer
J_T, J_FROM, J_TO, J_ALPHA, J_OMEGA, J_F, J_V_BEFORE, J_V_AFTER = range(8)
N_J = 8
#: the fold event fires at v = v_max (1 - FOLD_REL) on AB, v_min (1 + FOLD_REL)
#: on CD (module docstring, "Folded singularities")
FOLD_REL = 1e-9
# save modes
SAVE_STEPS, SAVE_TEVAL, SAVE_NONE = 0, 1, 2


@kernel(inner=True)
def _store(out, nrow, t, y, v, F, br_arr, br):
    out[nrow, O_T] = t
    out[nrow, O_AL] = y[1]
    out[nrow, O_OM] = y[2]
    out[nrow, O_F] = F
    out[nrow, O_V] = v
    br_arr[nrow] = br


@kernel(inner=True)
def _in_domain(y, p):
    """A state the driver may use: finite, v = exp(u) > 0 and 1 + c(α) > 0 (where the field is defined)."""
    for i in range(4):
        if not np.isfinite(y[i]):
            return False
    if not 0.0 < np.exp(y[3]) < np.inf:
        return False
    c, _ = _closure(y[1], p)
    return 1.0 + c > 0.0


@kernel(inner=True)
def _finite_rows(Fc):
    """All dense-output coefficients finite (the extra stages stayed in the domain)."""
    for r in range(Fc.shape[0]):
        for i in range(Fc.shape[1]):
            if not np.isfinite(Fc[r, i]):
                return False
    return True


@kernel(inner=True)
def _save(st, y, h):
    """Write the resumable solver state (y and the next step size) into st."""
    st[S_TAU] = y[0]
    st[S_AL] = y[1]
    st[S_OM] = y[2]
    st[S_U] = y[3]
    st[S_H] = h


@kernel(inner=True)
def _resume(st, y):
    """Read the resumable solver state into y; returns ``(t0, branch, h)``."""
    y[0] = st[S_TAU]
    y[1] = st[S_AL]
    y[2] = st[S_OM]
    y[3] = st[S_U]
    return st[S_T0], int(st[S_BR]), st[S_H]


@kernel(inner=True)
def _end(st, y, ye, h, status):
    """Stop the call at ``ye`` (copied into y; the next call continues with step h) and return ``status``."""
    for i in range(4):
        y[i] = ye[i]
    _save(st, y, h)
    return status


_GO = -1  # _room_left: nothing stops the call before the next step


@kernel(inner=True)
def _room_left(calls, max_call_steps, save_mode, cnt, nout_cap, njump_cap):
    """The status that ends the call before the next step (its step quota used, or a buffer without room for what
    a step may store), else ``_GO``: budgets and buffers are checked between steps only."""
    if calls >= max_call_steps:
        return PAUSE
    if save_mode == SAVE_STEPS and cnt[C_NOUT] + 2 > nout_cap:
        return OUT_FULL
    if cnt[C_NJOUT] + 1 > njump_cap:
        return JUMPS_FULL
    return _GO


@kernel(inner=True)
def _fold_crossing(y, y_new, p, br):
    """``(crossed, u_event, g_start, g_end)``: whether the step ``[y, y_new]`` reaches the fold event of branch br
    (AB: u rises to ``P_UEV_AB``; CD: falls to ``P_UEV_CD``), the event level and ``u - u_event`` at both ends."""
    uf = p[P_UEV_AB] if br == 0 else p[P_UEV_CD]
    gA = y[3] - uf
    gB = y_new[3] - uf
    return (gB >= 0.0 if br == 0 else gB <= 0.0), uf, gA, gB


@kernel(inner=True)
def _record_jump(jbuf, cnt, tj, br, ye, F, v_before, v_after):
    """Store the jump at ``tj`` from branch br at state ``ye`` (α, ω; F the pull force) in the next row of jbuf."""
    k = cnt[C_NJOUT]
    jbuf[k, J_T] = tj
    jbuf[k, J_FROM] = br
    jbuf[k, J_TO] = 1 - br
    jbuf[k, J_ALPHA] = ye[1]
    jbuf[k, J_OMEGA] = ye[2]
    jbuf[k, J_F] = F
    jbuf[k, J_V_BEFORE] = v_before
    jbuf[k, J_V_AFTER] = v_after
    cnt[C_NJOUT] += 1


@kernel(inner=True)
def _land(st, y, ye, tj, br, v_after):
    """The state after the jump at ``tj`` onto branch br: τ from 0, (α, ω) those of ``ye``, v the landing root."""
    y[0] = 0.0
    y[1] = ye[1]
    y[2] = ye[2]
    y[3] = np.log(v_after)
    st[S_T0] = tj
    st[S_BR] = br


@kernel(inner=True)
def _advance(y, y_new, f0, K):
    """Accept the plain step to ``y_new``: it becomes y, with its last stage as the field f0 there.  t(s)
    increases on a stable branch, but near a folded singularity its increments fall below the step's error
    tolerance (module docstring): τ is kept non-decreasing (τ does not enter the field)."""
    if y_new[0] < y[0]:
        y_new[0] = y[0]
    for i in range(4):
        y[i] = y_new[i]
        f0[i] = K[_NS, i]


#: The pieces :func:`_run` calls, bound per driver by :mod:`exact._hybrid_driver` (the paper's law inlined, or
#: the law as an argument): the field ``_FIELD(y, P, out)``, the pull force ``_PULL(alpha, v, P)``,
#: ``P = _PACK(p, law, coef)`` and ``_dop``, the DOP853 pieces of the field; and the step's pieces below that call
#: them (:data:`BOUND_HELPERS`), each bound per driver too.  Never compiled with these placeholders.
_FIELD: Any = None
_PULL: Any = None
_PACK: Any = None
_dop: Any = None


def _fold_event(y, y_new, K, h, P, p, Fc, tmp, cnt, br):
    """``(ok, dense, x_fold)``: the fold inside the step ``[y, y_new]`` as a fraction of it (2: none), located on
    the dense output (``dense``: whether it was built); ``ok`` False if that output left the domain."""
    dense = False
    x_fold = 2.0
    ok = True
    if p[P_FOLDS] != 0.0:
        crossed, uf, gA, gB = _fold_crossing(y, y_new, p, br)
        if crossed:
            dense = _dop.ensure_dense(dense, y, y_new, K, h, P, Fc, tmp, cnt, C_RHS)
            ok = _finite_rows(Fc)
            if ok:
                x_fold = solve_theta(y, Fc, 3, uf, gA, 1.0, gB)
    return ok, dense, x_fold


def _end_event(y, y_new, K, h, P, Fc, tmp, cnt, dense, x_fold, tau_end):
    """``(ok, dense, x_end, x_stop)``: t_end (τ = ``tau_end``) inside the step as a fraction of it (2: none), and
    where the step stops, ``min(x_fold, x_end, 1)``.  τ increases up to the fold (f' > 0 on the branch) and
    falls again beyond it, so t_end is looked for in ``[0, min(x_fold, 1)]``."""
    x_end = 2.0
    ok = True
    if x_fold <= 1.0:
        x_b = x_fold
        tau_b = interp1(y, Fc, x_fold, 0)
    else:
        x_b = 1.0
        tau_b = y_new[0]
    if tau_b >= tau_end:
        dense = _dop.ensure_dense(dense, y, y_new, K, h, P, Fc, tmp, cnt, C_RHS)
        ok = _finite_rows(Fc)
        if ok:
            x_end = crossing(y, Fc, 0, tau_end, x_b, tau_b)
    return ok, dense, x_end, min(x_fold, x_end, 1.0)


def _teval_output(y, y_new, K, h, P, p, Fc, tmp, cnt, dense, x_stop, t_eval, t0, out, out_br, br, ye):
    """Store the states at the times of ``t_eval`` strictly before the step's stop ``x_stop``; ``(ok, dense)``,
    ``ok`` False if an interpolated state left the domain."""
    if x_stop < 1.0:
        tau_stop = interp1(y, Fc, x_stop, 0)
    else:
        tau_stop = y_new[0]
    while cnt[C_TEVAL] < t_eval.shape[0] and t_eval[cnt[C_TEVAL]] - t0 <= tau_stop:
        te = t_eval[cnt[C_TEVAL]]
        dense = _dop.ensure_dense(dense, y, y_new, K, h, P, Fc, tmp, cnt, C_RHS)
        state_at(y, Fc, 0, te - t0, x_stop, tau_stop, ye)
        if not _in_domain(ye, p):
            return False, dense
        ve = np.exp(ye[3])
        _store(out, cnt[C_NOUT], te, ye, ve, _PULL(ye[1], ve, P), out_br, br)
        cnt[C_NOUT] += 1
        cnt[C_TEVAL] += 1
    return True, dense


def _reach_end(st, y, ye, h_next, P, t_end, t0, t_store, save_mode, out, out_br, cnt, br):
    """The step reached t_end at ``ye``: store it (``save="steps"``) and stop with DONE."""
    ye[0] = t_end - t0
    if save_mode == SAVE_STEPS and t_end >= t_store:
        ve = np.exp(ye[3])
        _store(out, cnt[C_NOUT], t_end, ye, ve, _PULL(ye[1], ve, P), out_br, br)
        cnt[C_NOUT] += 1
    return _end(st, y, ye, h_next, DONE)


def _jump(st, y, ye, p, P, f0, work, rtol, atol, t0, br, t_store, save_mode, out, out_br, jbuf, cnt, h):
    """The jump at the fold reached at ``ye``: v exactly at the fold value, (α, ω, F) continuous, onto the landing
    root of the other branch, and a fresh first step there.  Returns ``(status, br, t0, h)``: ``_GO`` and the
    new branch, segment start and step, or NO_LANDING (a CD→AB jump without a landing root)."""
    v_fold = p[P_VMAX] if br == 0 else p[P_VMIN]
    ye[3] = np.log(v_fold)
    ye[0] = max(ye[0], y[0])  # as for a plain step (_advance)
    tj = t0 + ye[0]
    Fj = _PULL(ye[1], v_fold, P)
    v_after = p[P_VLCD] if br == 0 else p[P_VLAB]
    if br == 1 and not (v_after > 0.0):
        return _end(st, y, ye, h, NO_LANDING), br, t0, h
    if tj >= t_store:
        if save_mode == SAVE_STEPS:
            _store(out, cnt[C_NOUT], tj, ye, v_fold, Fj, out_br, br)
            cnt[C_NOUT] += 1
        _record_jump(jbuf, cnt, tj, br, ye, Fj, v_fold, v_after)
    cnt[C_JUMPS] += 1
    br = 1 - br
    _land(st, y, ye, tj, br, v_after)
    if tj >= t_store and save_mode == SAVE_STEPS:
        _store(out, cnt[C_NOUT], tj, y, v_after, Fj, out_br, br)
        cnt[C_NOUT] += 1
    _FIELD(y, P, f0)
    h = _dop.initial_step(y, f0, P, rtol, atol, work)
    cnt[C_RHS] += 2
    return _GO, br, tj, h


def _plain_step(y, y_new, f0, K, P, t0, t_store, save_mode, out, out_br, cnt, br):
    """Accept the step to ``y_new`` (:func:`_advance`) and store its end (``save="steps"``)."""
    _advance(y, y_new, f0, K)
    if save_mode == SAVE_STEPS and t0 + y[0] >= t_store:
        v = np.exp(y[3])
        _store(out, cnt[C_NOUT], t0 + y[0], y, v, _PULL(y[1], v, P), out_br, br)
        cnt[C_NOUT] += 1


#: The step's pieces that call the bound pieces above, bound with them per driver (names of this module).
BOUND_HELPERS = ("_fold_event", "_end_event", "_teval_output", "_reach_end", "_jump", "_plain_step")


@kernel(inner=True)
def _stop_state(y, y_new, Fc, x_fold, x_end, x_stop, ye, p):
    """The state where the step stops into ``ye`` (interpolated at an event, else its end); whether it lies in the
    domain."""
    if x_fold <= 1.0 or x_end <= 1.0:
        interp(y, Fc, x_stop, ye)
        return _in_domain(ye, p)
    for i in range(4):
        ye[i] = y_new[i]
    return True


@kernel(inner=True)
def _left_domain(ye, p, br):
    """The breakdown at the accepted stop ``ye`` (the peel geometry degenerating, a CD runaway), else ``_GO``."""
    c_e, _ = _closure(ye[1], p)
    if not (1.0 + c_e > 1e-12):
        return GEOMETRY
    if br == 1 and ye[3] > p[P_UCEIL]:
        return V_CEILING
    return _GO


def _run(st, p, law, coef, rtol, atol, t_end, t_store, save_mode, t_eval, out, out_br, jbuf, cnt, max_call_steps):
    """Advance the hybrid solver from ``st`` until t_end or a buffer/quota limit.

    Returns a status code (module constants).  All state needed to continue is in ``st`` and ``cnt``; the caller
    empties full buffers and calls again.  In ``SAVE_TEVAL`` mode ``out`` must have a row per ``t_eval`` point.
    The peel force is ``law`` with ``coef``, or the paper's law inlined: :func:`exact._hybrid_driver.driver`.
    """
    P = _PACK(p, law, coef)  # what the field receives through the DOP853 pieces (placeholders above)
    K, y_new, f0, tmp, sc, work, Fc, ye = workspace(4)
    y = np.empty(4)
    t0, br, h = _resume(st, y)
    calls = 0
    n_bad = 0  # successive steps rejected for their dense output
    _FIELD(y, P, f0)
    cnt[C_RHS] += 1
    if h <= 0.0:
        h = _dop.initial_step(y, f0, P, rtol, atol, work)
        cnt[C_RHS] += 1
    while True:
        stop = _room_left(calls, max_call_steps, save_mode, cnt, out.shape[0], jbuf.shape[0])
        if stop != _GO:
            _save(st, y, h)
            return stop
        status, h, h_next, n_rej, n_rhs = _dop.step(y, f0, h, P, rtol, atol, K, y_new, tmp, sc)
        cnt[C_REJ] += n_rej
        cnt[C_RHS] += n_rhs
        if status == STEP_FAILED:
            _save(st, y, h)
            return STEP_FAIL
        # The step's own stages and end point lie in the domain (a stage outside poisons the error estimate), but
        # its dense output (three more stages) and the states interpolated from it need not: any such state
        # rejects the step like a failed error test (``ok``), so no non-finite state or v <= 0 is stored,
        # reported or continued from.
        nout0, nte0 = cnt[C_NOUT], cnt[C_TEVAL]
        ok, dense, x_fold = _fold_event(y, y_new, K, h, P, p, Fc, tmp, cnt, br)
        # breakdown on AB: the level F(1 + c) = f(v) reached f(0+) + BREAKDOWN_LEVEL, i.e. u <= ln v_breakdown
        # (or a user's v_floor), checked at step end
        if ok and br == 0 and y_new[3] <= p[P_UFLOOR] and x_fold > 1.0:
            cnt[C_STEPS] += 1
            return _end(st, y, y_new, h_next, NO_ROOT)
        x_end, x_stop = 2.0, 1.0
        if ok:
            ok, dense, x_end, x_stop = _end_event(y, y_new, K, h, P, Fc, tmp, cnt, dense, x_fold, t_end - t0)
        if ok and save_mode == SAVE_TEVAL:
            ok, dense = _teval_output(y, y_new, K, h, P, p, Fc, tmp, cnt, dense, x_stop, t_eval, t0, out, out_br,
                                      br, ye)
        if ok:
            ok = _stop_state(y, y_new, Fc, x_fold, x_end, x_stop, ye, p)
        if not ok:  # reject the step: forget its output, retry from y with a quarter of the step
            cnt[C_NOUT], cnt[C_TEVAL] = nout0, nte0
            cnt[C_REJ] += 1
            h *= 0.25
            n_bad += 1
            if n_bad > MAX_REJECTIONS or h <= 1e-300:
                _save(st, y, h)
                return STEP_FAIL
            continue
        if n_bad > 0:  # the step after a dense-output rejection does not grow (as after an error rejection)
            h_next = min(h_next, h)
            n_bad = 0
        cnt[C_STEPS] += 1
        calls += 1
        stop = _left_domain(ye, p, br)
        if stop != _GO:
            return _end(st, y, ye, h, stop)
        if x_end <= 1.0 and x_end <= x_fold:  # reached t_end (a fold exactly at t_end is left for a later call)
            return _reach_end(st, y, ye, h_next, P, t_end, t0, t_store, save_mode, out, out_br, cnt, br)
        if x_fold <= 1.0:
            stop, br, t0, h = _jump(st, y, ye, p, P, f0, work, rtol, atol, t0, br, t_store, save_mode, out, out_br,
                                    jbuf, cnt, h)
            if stop != _GO:
                return stop
            continue
        _plain_step(y, y_new, f0, K, P, t0, t_store, save_mode, out, out_br, cnt, br)
        h = h_next
