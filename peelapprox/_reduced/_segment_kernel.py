"""The compiled reduced-segment integrator: its parameter layout, vector field and event driver.

The equations and their desingularised form are described in :mod:`peelapprox._reduced._segment` (the public
:func:`~peelapprox.reduced_segment`, which validates the arguments, packs :func:`segment_parameters` and calls
:func:`run`).  The α equations come from :mod:`peelapprox._reduced._alpha`, where each is written once: the closed forms
(``"sinusoid"``, ``"harmonic"``, ``"exponential"``) are evaluated at the state's t by the same functions the
public ``sinusoid_alpha``, ``harmonic_alpha``, ``cd_decay_alpha`` call, and the restoring term ``-F R α/I`` of
approxalpha/Airy is the one :func:`~peelapprox.alpha_numerical` integrates.  The damping terms of Airy1/Airy2
and genalpha are written here multiplied by ``dt/ds = v f'`` with ``f'`` cancelled, the form that stays smooth
through the fold.

Parameter vector ``q``: the model block of :mod:`peelapprox._packing` (``M_V``, ``M_I``, ``M_K``, ``M_R``,
``M_B``, ``M_A``; the reduced equations are linear in α and read neither ``M_L`` nor ``M_GEOM``), then this
driver's fields ``Q_*`` from index ``N_M``.

The peel-force law: the driver body :func:`_run` is compiled twice (:func:`peelapprox._compiled._jit.rebind`),
as the hybrid solver's (``exact._hybrid_driver``):

* ``run(False)`` -- the paper's law fvV **inlined** (:func:`field`, ``q`` carrying ``b, A``): the default path,
  bitwise the numbers of 0.2.0;
* ``run(True)`` -- the law as an **argument** ``law`` of type :data:`peelapprox.law._abi.LAW_TYPE` with its
  coefficients ``coef`` (:func:`field_law`: ``law(ln v, coef, LAW_LNV)``), for any compiled law
  (:func:`peelapprox.law._compiled.compiled_law`) without compiling again.

Both are compiled for the one signature :data:`RUN_SIG` on first use and cached across processes; the law's
field is compiled without numba's reference-counting runtime (``kernel(nrt=False)``), which would wrap every
indirect law call in atomic reference-count updates.  Where the law may be evaluated (its domain) is the
caller's floor and ceiling ``x_lo``/``x_hi`` of ln v (:func:`peelapprox.reduced_segment`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import types as _t

from .._compiled._dop853 import N_STAGES as _NS
from .._compiled._dop853 import STEP_FAILED, crossing, interp, interp1, make_dop853, solve_theta, state_at, workspace
from .._compiled._jit import compile_only, kernel, rebind
from .._packing import M_A, M_B, M_I, M_K, M_R, M_V, N_M
from .._status import DONE, F_NONPOSITIVE, MAX_STEPS, NONFINITE, OUT_FULL, STEP_FAIL, T_MAX, V_CEILING, V_FLOOR
from ..law._abi import LAW_LNV, LAW_TYPE, pack_inlined, pack_law
from ..law._paper import peel_force_fp_jit
from ._alpha import _decay, _harmonic, _restoring, _sinusoid

__all__ = ["ALPHA_MODELS", "RUN_SIG", "V_EQUATIONS", "alpha_of", "field", "field_law", "run", "segment_parameters"]

#: α models accepted by :func:`peelapprox.reduced_segment` (:mod:`peelapprox._reduced._segment`); the code of each is
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


@kernel(inline="always")  # inlined into both fields: the arithmetic of the field of 0.2.0
def _field_at(y, q, v, g, out):
    """d(t, ln v, F, α, α̇)/ds at y with ``v = exp(y[1])`` and ``g = v f'(v)`` already evaluated (both fields)."""
    F = y[2]
    V, I, k, R = q[M_V], q[M_I], q[M_K], q[M_R]
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


@kernel
def field(y, q, out):
    """d(t, ln v, F, α, α̇)/ds with dt/ds = v f'(v) (module docstring), the paper's law fvV inlined (``q``
    carries its coefficients ``b, A``)."""
    v = np.exp(y[1])
    F = y[2]
    if not (v > 0.0 and F > 0.0 and np.isfinite(v)):
        for i in range(5):
            out[i] = np.nan
        return
    f, fp = peel_force_fp_jit(v, q[M_B], q[M_A])
    _field_at(y, q, v, v * fp, out)


@kernel(nrt=False)  # no reference counting around the law call (exact._hybrid_driver: 62 vs 29 ns per field)
def field_law(y, P, out):
    """:func:`field` for the law of ``P = (q, law, coef)``: ``law(ln v, coef, LAW_LNV)`` gives ``(v, f, v f')``."""
    q, law, coef = P
    F = y[2]
    v, f, g = law(y[1], coef, LAW_LNV)
    if not (v > 0.0 and F > 0.0 and np.isfinite(v) and np.isfinite(g)):
        for i in range(5):
            out[i] = np.nan
        return
    _field_at(y, q, v, g, out)


@kernel
def _store(out, row, y, q):
    """Row ``row`` of the output: (t, v, F, α, α̇) at state y."""
    al, ad = alpha_of(y, q)
    out[row, 0] = y[0]
    out[row, 1] = np.exp(y[1])
    out[row, 2] = y[2]
    out[row, 3] = al
    out[row, 4] = ad


def alpha_at(y: np.ndarray, q: np.ndarray) -> tuple[float, float]:
    """(α, α̇) at the state ``y`` (:func:`alpha_of`) from Python, through the driver's own compiled :func:`_store`
    (compiled with it, or loaded from the cache): calling :func:`alpha_of` from Python compiled it, and the
    closed forms it inlines, a second time."""
    row = np.empty((1, 5))
    _store(row, 0, y, q)
    return float(row[0, 3]), float(row[0, 4])


#: The pieces :func:`_run` calls, bound per copy (:data:`_RUNS`): the field ``_FIELD(y, P, out)``, ``P =
#: _PACK(q, law, coef)`` and ``_dop``, the DOP853 pieces of the field.  Never compiled with these placeholders.
_FIELD: Any = None
_PACK: Any = None
_dop: Any = None
#: The body :func:`_drive` of the copy a driver :func:`_run` calls (bound per copy, :data:`_DRIVES`).
_DRIVE: Any = None


def _run(y, q, law, coef, rtol, atol, x_f, x_lo, x_hi, upward, t_max, max_steps, save_mode, t_eval, out, cnt):
    """Integrate from y until ln v crosses x_f (upward or downward); y holds the final state.  The peel force is
    ``law`` with ``coef``, or the paper's law inlined (:func:`run`).  :func:`_drive` with a workspace of its own."""
    K, y_new, f0, tmp, sc, work, Fc, ye = workspace(5)
    return _DRIVE(y, q, law, coef, rtol, atol, x_f, x_lo, x_hi, upward, t_max, max_steps, save_mode, t_eval, out,
                  cnt, K, y_new, f0, tmp, sc, work, Fc, ye)


def _drive(y, q, law, coef, rtol, atol, x_f, x_lo, x_hi, upward, t_max, max_steps, save_mode, t_eval, out, cnt, K,
           y_new, f0, tmp, sc, work, Fc, ye):
    """:func:`_run` in the workspace ``K, y_new, f0, tmp, sc, work, Fc, ye``
    (:func:`peelapprox._compiled._dop853.workspace` of 5; every entry written before it is read, so a caller running
    many segments allocates it once: :mod:`peelapprox._reduced._reducedmap_kernel`)."""
    P = _PACK(q, law, coef)  # what the field receives through the DOP853 pieces (placeholders above)
    cap = out.shape[0]
    n_te = t_eval.shape[0]

    _FIELD(y, P, f0)
    h = _dop.initial_step(y, f0, P, rtol, atol, work)
    cnt[C_RHS] += 2
    if save_mode == SAVE_STEPS:
        _store(out, cnt[C_NOUT], y, q)
        cnt[C_NOUT] += 1
    while True:
        if cnt[C_STEPS] >= max_steps:
            return MAX_STEPS
        if save_mode == SAVE_STEPS and cnt[C_NOUT] + 2 > cap:
            return OUT_FULL
        status, h, h_next, n_rej, n_rhs = _dop.step(y, f0, h, P, rtol, atol, K, y_new, tmp, sc)
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
            dense = _dop.ensure_dense(dense, y, y_new, K, h, P, Fc, tmp, cnt, C_RHS)
            x_exit = solve_theta(y, Fc, 1, x_f, gA, 1.0, gB)
        x_tmax = 2.0
        if y_new[0] >= t_max:
            dense = _dop.ensure_dense(dense, y, y_new, K, h, P, Fc, tmp, cnt, C_RHS)
            x_tmax = crossing(y, Fc, 0, t_max, 1.0, y_new[0])
        x_stop = min(x_exit, x_tmax, 1.0)
        if save_mode == SAVE_TEVAL:
            t_stop = interp1(y, Fc, x_stop, 0) if x_stop < 1.0 else y_new[0]
            while cnt[C_TEVAL] < n_te and t_eval[cnt[C_TEVAL]] <= t_stop:
                te = t_eval[cnt[C_TEVAL]]
                dense = _dop.ensure_dense(dense, y, y_new, K, h, P, Fc, tmp, cnt, C_RHS)
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


_A1 = _t.float64[::1]
#: The one signature of both copies of :func:`_run`: ``(y, q, law, coef, rtol, atol, x_f, x_lo, x_hi, upward,
#: t_max, max_steps, save_mode, t_eval, out, cnt) -> status``.
RUN_SIG = _t.int64(_A1, _A1, LAW_TYPE, _A1, _t.float64, _A1, _t.float64, _t.float64, _t.float64, _t.boolean,
                   _t.float64, _t.int64, _t.int64, _A1, _t.float64[:, ::1], _t.int64[::1])

#: The two copies of :func:`_drive` (compiled into their callers): the paper's law inlined (False) and the law as
#: an argument (True).
_DRIVES = {
    False: kernel(rebind(_drive, _FIELD=field, _PACK=pack_inlined, _dop=make_dop853(field)),
                  name="segment_drive_inlined", inner=True),
    True: kernel(rebind(_drive, _FIELD=field_law, _PACK=pack_law, _dop=make_dop853(field_law)),
                 name="segment_drive_law", inner=True),
}
#: The two copies of :func:`_run`: the paper's law inlined (False) and the law as an argument (True).
_RUNS = {law_argument: kernel(rebind(_run, _DRIVE=_DRIVES[law_argument]),
                              name=f"segment_run_{'law' if law_argument else 'inlined'}")
         for law_argument in (False, True)}


def run(law_argument: bool) -> Any:
    """The segment driver, compiled for :data:`RUN_SIG` on first use (loaded from numba's cache when it is there)
    and for no other signature.

    Parameters
    ----------
    law_argument : bool
        False: the paper's law fvV inlined, ``law`` and ``coef`` unused (the default path, the numbers of 0.2.0).
        True: the law ``law`` (:data:`peelapprox.law._abi.LAW_TYPE`) with the coefficients ``coef``; a new law or
        new coefficients compile nothing.

    Returns
    -------
    numba dispatcher
        ``run(y, q, law, coef, rtol, atol, x_f, x_lo, x_hi, upward, t_max, max_steps, save_mode, t_eval, out, cnt)
        -> status`` (:func:`_run`).
    """
    return compile_only(_RUNS[bool(law_argument)], RUN_SIG)
