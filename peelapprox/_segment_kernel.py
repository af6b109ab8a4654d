"""The compiled reduced-segment integrator: its parameter layout, vector field and event driver.

The equations and their desingularised form are described in :mod:`peelapprox._segment` (the public
:func:`~peelapprox.reduced_segment`, which validates the arguments, packs :func:`segment_parameters` and calls
:func:`run`).  The α equations come from :mod:`peelapprox._alpha`, where each is written once: the closed forms
(``"sinusoid"``, ``"harmonic"``, ``"exponential"``) are evaluated at the state's t by the same functions the
public ``sinusoid_alpha``, ``harmonic_alpha``, ``cd_decay_alpha`` call, and the restoring term ``-F R α/I`` of
approxalpha/Airy is the one :func:`~peelapprox.alpha_numerical` integrates.  The damping terms of Airy1/Airy2
and genalpha are written here multiplied by ``dt/ds = v f'`` with ``f'`` cancelled, the form that stays smooth
through the fold.

Parameter vector ``q``: the model block of :mod:`peelapprox._packing` (``M_V``, ``M_I``, ``M_K``, ``M_R``,
``M_B``, ``M_A``; the reduced equations are linear in α and read neither ``M_L`` nor ``M_GEOM``), then this
driver's fields ``Q_*`` from index ``N_M``.
"""

from __future__ import annotations

import numpy as np

from ._alpha import _decay, _harmonic, _restoring, _sinusoid
from ._dop853 import N_STAGES as _NS
from ._dop853 import STEP_FAILED, crossing, interp, interp1, make_dop853, solve_theta, state_at, workspace
from ._jit import kernel
from ._packing import M_A, M_B, M_I, M_K, M_R, M_V, N_M
from ._peelforce import peel_force_fp_jit
from ._status import DONE, F_NONPOSITIVE, MAX_STEPS, NONFINITE, OUT_FULL, STEP_FAIL, T_MAX, V_CEILING, V_FLOOR

__all__ = ["ALPHA_MODELS", "V_EQUATIONS", "alpha_of", "field", "run", "segment_parameters"]

#: α models accepted by :func:`peelapprox.reduced_segment` (:mod:`peelapprox._segment`); the code of each is
#: its index (``AM_*``)
ALPHA_MODELS = (
    "sinusoid", "harmonic", "approxalpha", "airy2", "airy2_frozen", "airy1", "genalpha", "exponential", "static",
)
#: velocity equations accepted by :func:`peelapprox.reduced_segment`; the code of each is its index (``VE_*``)
V_EQUATIONS = ("approxvdot", "fullvdot")

AM_SIN, AM_HARM, AM_APPROX, AM_AIRY2, AM_AIRY2F, AM_AIRY1, AM_GEN, AM_EXP, AM_STATIC = range(len(ALPHA_MODELS))
VE_APPROX, VE_FULL = range(len(V_EQUATIONS))

# parameter vector: the model block, then (α model, v equation, F_in, v_in, f'(v_in), F_rate s, sinusoid amplitude
# and phase, α_in, α̇_in, τ = R f'(v_in)/F_in)
(Q_AM, Q_VE, Q_FIN, Q_VIN, Q_FPIN, Q_S, Q_AMP, Q_PH, Q_AIN, Q_ADIN, Q_TAU) = range(N_M, N_M + 11)
N_Q = N_M + 11
# counters
C_STEPS, C_REJ, C_RHS, C_NOUT, C_TEVAL = range(5)
# save modes
SAVE_STEPS, SAVE_TEVAL, SAVE_NONE = range(3)


def segment_parameters(model: np.ndarray, *, alpha_model: int, v_equation: int, F_in: float, v_in: float,
                       fp_in: float, F_rate: float, amplitude: float, phase: float, alpha_in: float,
                       alphadot_in: float, tau: float) -> np.ndarray:
    """The kernel's parameter vector: ``model`` (:func:`peelapprox._packing.model_block` of length ``N_Q``) with
    this driver's fields filled in (in place; returned)."""
    q = model
    q[Q_AM] = alpha_model
    q[Q_VE] = v_equation
    q[[Q_FIN, Q_VIN, Q_FPIN, Q_S, Q_AIN, Q_ADIN, Q_TAU]] = F_in, v_in, fp_in, F_rate, alpha_in, alphadot_in, tau
    q[Q_AMP] = amplitude
    q[Q_PH] = phase
    return q


@kernel(inline="always")  # inlined into the field (numba does not inline separate dispatchers)
def alpha_of(y, q):
    """(α, α̇) at state y: closed forms evaluated at t, else the state's own."""
    am = int(q[Q_AM])
    t = y[0]
    if am == AM_SIN:
        return _sinusoid(t, q[Q_AMP], q[Q_PH], q[Q_FIN], q[Q_S], q[M_R], q[M_I])
    if am == AM_HARM:
        return _harmonic(t, q[Q_AIN], q[Q_ADIN], q[Q_FIN], q[M_R], q[M_I])
    if am == AM_EXP:
        return _decay(t, q[Q_AIN], q[Q_TAU])
    if am == AM_STATIC:
        return q[Q_AIN], 0.0
    return y[3], y[4]


@kernel
def field(y, q, out):
    """d(t, ln v, F, α, α̇)/ds with dt/ds = v f'(v) (module docstring)."""
    v = np.exp(y[1])
    F = y[2]
    if not (v > 0.0 and F > 0.0 and np.isfinite(v)):
        for i in range(5):
            out[i] = np.nan
        return
    V, I, k, R = q[M_V], q[M_I], q[M_K], q[M_R]
    f, fp = peel_force_fp_jit(v, q[M_B], q[M_A])
    g = v * fp
    al, ad = alpha_of(y, q)
    am = int(q[Q_AM])
    if int(q[Q_VE]) == VE_APPROX:
        Fd = k * (V - v)
        N = Fd + F * ad
    else:
        Fd = k * (V - v + R * al * ad)
        N = Fd * (1.0 + al) + F * ad
    out[0] = g
    out[1] = N
    out[2] = g * Fd
    if am == AM_SIN or am == AM_HARM or am == AM_EXP or am == AM_STATIC:  # closed forms: α is not a state
        out[3] = 0.0
        out[4] = 0.0
        return
    out[3] = g * ad
    if am == AM_AIRY2F:
        Fi = q[Q_FIN]
        out[4] = g * _restoring(Fi, al, R, I) - g * Fi * ad / (R * q[Q_FPIN])
        return
    acc = g * _restoring(F, al, R, I)
    if am == AM_AIRY2:
        acc -= v * F * ad / R
    elif am == AM_AIRY1:
        acc -= v * (Fd + F * ad) / R
    elif am == AM_GEN:
        acc -= v * N / R
    out[4] = acc


_dop = make_dop853(field)


@kernel
def _store(out, row, y, q):
    """Row ``row`` of the output: (t, v, F, α, α̇) at state y."""
    al, ad = alpha_of(y, q)
    out[row, 0] = y[0]
    out[row, 1] = np.exp(y[1])
    out[row, 2] = y[2]
    out[row, 3] = al
    out[row, 4] = ad


@kernel
def run(y, q, rtol, atol, x_f, x_lo, x_hi, upward, t_max, max_steps, save_mode, t_eval, out, cnt):
    """Integrate from y until ln v crosses x_f (upward or downward); y holds the final state."""
    K, y_new, f0, tmp, sc, work, Fc, ye = workspace(5)
    cap = out.shape[0]
    n_te = t_eval.shape[0]

    field(y, q, f0)
    h = _dop.initial_step(y, f0, q, rtol, atol, work)
    cnt[C_RHS] += 2
    if save_mode == SAVE_STEPS:
        _store(out, cnt[C_NOUT], y, q)
        cnt[C_NOUT] += 1
    while True:
        if cnt[C_STEPS] >= max_steps:
            return MAX_STEPS
        if save_mode == SAVE_STEPS and cnt[C_NOUT] + 2 > cap:
            return OUT_FULL
        status, h, h_next, n_rej, n_rhs = _dop.step(y, f0, h, q, rtol, atol, K, y_new, tmp, sc)
        cnt[C_REJ] += n_rej
        cnt[C_RHS] += n_rhs
        if status == STEP_FAILED:
            return STEP_FAIL
        cnt[C_STEPS] += 1
        dense = False
        x_exit = 2.0
        gA = y[1] - x_f
        gB = y_new[1] - x_f
        if (upward and gB >= 0.0) or ((not upward) and gB <= 0.0):
            dense = _dop.ensure_dense(dense, y, y_new, K, h, q, Fc, tmp, cnt, C_RHS)
            x_exit = solve_theta(y, Fc, 1, x_f, gA, 1.0, gB)
        x_tmax = 2.0
        if y_new[0] >= t_max:
            dense = _dop.ensure_dense(dense, y, y_new, K, h, q, Fc, tmp, cnt, C_RHS)
            x_tmax = crossing(y, Fc, 0, t_max, 1.0, y_new[0])
        x_stop = min(x_exit, x_tmax, 1.0)
        if save_mode == SAVE_TEVAL:
            t_stop = interp1(y, Fc, x_stop, 0) if x_stop < 1.0 else y_new[0]
            while cnt[C_TEVAL] < n_te and t_eval[cnt[C_TEVAL]] <= t_stop:
                te = t_eval[cnt[C_TEVAL]]
                dense = _dop.ensure_dense(dense, y, y_new, K, h, q, Fc, tmp, cnt, C_RHS)
                state_at(y, Fc, 0, te, x_stop, t_stop, ye)
                _store(out, cnt[C_NOUT], ye, q)
                cnt[C_NOUT] += 1
                cnt[C_TEVAL] += 1
        if min(x_exit, x_tmax) <= 1.0:  # the exit or t_max lies in this step
            interp(y, Fc, x_stop, ye)
            for i in range(5):
                y[i] = ye[i]
            if x_exit <= x_tmax:
                y[1] = x_f
                code = DONE
            else:
                y[0] = t_max
                code = T_MAX
            if save_mode == SAVE_STEPS:
                _store(out, cnt[C_NOUT], y, q)
                cnt[C_NOUT] += 1
            return code
        for i in range(5):
            if not np.isfinite(y_new[i]):
                return NONFINITE
        for i in range(5):
            y[i] = y_new[i]
            f0[i] = K[_NS, i]
        h = h_next
        if save_mode == SAVE_STEPS:
            _store(out, cnt[C_NOUT], y, q)
            cnt[C_NOUT] += 1
        if y[1] <= x_lo:
            return V_FLOOR
        if y[1] >= x_hi:
            return V_CEILING
        if y[2] <= 0.0:
            return F_NONPOSITIVE
