"""The reduced return map's returns in compiled code: many returns per call of Python.

:meth:`peelapprox._reduced._reducedmap.ReturnMap.ret` runs one return as two calls of the segment driver
(:func:`peelapprox._reduced._segment_kernel.run`) from Python, each with its parameter vector, tolerances and horizon
built in Python: ~25 µs of set-up and dispatch per segment, more than a short segment's integration.
:func:`returns` runs the same arithmetic, in the same order, for many returns in one call (the same numbers
bitwise, the default chain's integrated α models with the paper's geometry ``1 - c(α) = 1 + sin α``):

* the AB→CD jump: ``F = f_max/(1 + sin α)``, ``α̇ += kick_ab``; a CD stay to ``v_min``;
* the CD→AB jump: ``G = f_min/(1 + sin α)``, ``α̇ += kick_cd``; an AB stay to ``v_max``;

each stay with the parameter vector, ``atol`` and horizon of :meth:`peelapprox._reduced._reducedmap.ReturnMap.lean`.  A
call stops after ``n`` returns, at a segment that does not reach its fold (its status, branch and final state
returned), or once ``step_cap`` integration steps are spent (the caller checks its wall-clock deadline between
calls, so a call's length is bounded whatever the returns cost).

Branch data ``b`` (one row per branch, 0 AB, 1 CD): ``(v_in, f'(v_in), F_rate, x_f, x_lo, x_hi, t_max (< 0:
the default horizon), max_steps, fold force, kick of the jump onto the branch, upward (1.0 on AB))``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import types as _t

from .._compiled._dop853 import workspace
from .._compiled._jit import compile_only, kernel, rebind
from .._packing import M_I, M_R
from .._status import DONE
from ..law._abi import LAW_TYPE
from . import _segment_kernel as K

__all__ = ["B_FOLD", "B_KICK", "N_B", "returns", "RETURNS_SIG"]

# the branch rows' columns (module docstring)
B_VIN, B_FPIN, B_S, B_XF, B_XLO, B_XHI, B_TMAX, B_STEPS, B_FOLD, B_KICK, B_UP = range(11)
N_B = 11
# the outputs' layout: info = (returns done, status, branch of the stop, steps), stop = final state and t_max
I_DONE, I_CODE, I_BRANCH, I_STEPS = range(4)

#: The segment driver body copy :func:`_returns` calls (:data:`peelapprox._reduced._segment_kernel._DRIVES`, bound
#: per copy, :data:`_COPIES`); never compiled unbound.
_DRIVE: Any = None


def _stay(y, q, b, row, law, coef, rtol, horizon, F, a, ad, atol, cnt, stop, dummy_t, dummy_out, ws):
    """One stay on branch ``row`` from ``(F, α, α̇)`` (:meth:`peelapprox._reduced._reducedmap.ReturnMap.lean`'s
    arithmetic) in the call's workspace ``ws``; ``q`` is the branch's parameter vector, whose entry fields are
    written here (the rest as the plan's); y holds the final state; the driver's status."""
    R, I = q[M_R], q[M_I]
    q[K.Q_FIN] = F
    q[K.Q_VIN] = b[row, B_VIN]
    q[K.Q_FPIN] = b[row, B_FPIN]
    q[K.Q_S] = b[row, B_S]
    q[K.Q_AIN] = a
    q[K.Q_ADIN] = ad
    q[K.Q_TAU] = R * b[row, B_FPIN] / F
    q[K.Q_AMP] = 0.0
    q[K.Q_PH] = 0.0
    Om = np.sqrt(R * F / I)
    a_scale = max(abs(a), abs(ad) / Om, 1e-8)
    atol[0] = rtol * 1e-3
    atol[1] = rtol * 1.0
    atol[2] = rtol * F
    atol[3] = rtol * a_scale
    atol[4] = rtol * (Om * a_scale)
    t_max = b[row, B_TMAX] if b[row, B_TMAX] >= 0.0 else horizon + 20.0 * 2.0 * np.pi / Om
    y[0] = 0.0
    y[1] = np.log(b[row, B_VIN])
    y[2] = F
    y[3] = a
    y[4] = ad
    for i in range(5):
        cnt[i] = 0
    stop[5] = t_max
    K_, y_new, f0, tmp, sc, work, Fc, ye = ws
    return _DRIVE(y, q, law, coef, rtol, atol, b[row, B_XF], b[row, B_XLO], b[row, B_XHI], b[row, B_UP] > 0.5,
                  t_max, np.int64(b[row, B_STEPS]), np.int64(K.SAVE_NONE), dummy_t, dummy_out, cnt, K_, y_new, f0, tmp,
                  sc, work, Fc, ye)


def _returns(x, n, q_ab, q_cd, b, law, coef, rtol, horizon, step_cap, recs, info, stop):
    """Up to ``n`` returns from the section point ``x = (α, α̇)`` (updated in place), each a row ``(F at the
    AB→CD jump, F at the CD→AB jump, CD stay, AB stay, α at the two jumps)`` of ``recs``; ``info`` gets the
    returns done, the status (DONE, or the stopping segment's), the stopping branch and the steps; ``stop``
    the stopping segment's final state and horizon."""
    y = np.empty(5)
    atol = np.empty(5)
    ws = workspace(5)  # one workspace and one parameter vector per branch for all the stays of the call
    qa = q_ab.copy()
    qc = q_cd.copy()
    cnt = np.zeros(5, dtype=np.int64)
    dummy_t = np.empty(0)
    dummy_out = np.empty((1, 5))
    steps = 0
    info[I_CODE] = DONE
    info[I_BRANCH] = -1
    done = 0
    while done < n and steps < step_cap:
        a0, ad = x[0], x[1]
        F = b[1, B_FOLD] / (1.0 + np.sin(a0))
        code = _stay(y, qc, b, 1, law, coef, rtol, horizon, F, a0, ad + b[1, B_KICK], atol, cnt, stop, dummy_t,
                     dummy_out, ws)
        steps += cnt[K.C_STEPS]
        if code != DONE:
            info[I_CODE], info[I_BRANCH] = code, 1
            break
        t_cd, a, ad = y[0], y[3], y[4]
        G = b[0, B_FOLD] / (1.0 + np.sin(a))
        code = _stay(y, qa, b, 0, law, coef, rtol, horizon, G, a, ad + b[0, B_KICK], atol, cnt, stop, dummy_t,
                     dummy_out, ws)
        steps += cnt[K.C_STEPS]
        if code != DONE:
            info[I_CODE], info[I_BRANCH] = code, 0
            break
        x[0], x[1] = y[3], y[4]
        recs[done, 0], recs[done, 1], recs[done, 2], recs[done, 3] = F, G, t_cd, y[0]
        recs[done, 4], recs[done, 5] = a0, a
        done += 1
    for i in range(5):
        stop[i] = y[i]
    info[I_DONE] = done
    info[I_STEPS] = steps


_A1 = _t.float64[::1]
#: ``(x, n, q_ab, q_cd, b, law, coef, rtol, horizon, step_cap, recs, info, stop) -> None``.
RETURNS_SIG = _t.void(_A1, _t.int64, _A1, _A1, _t.float64[:, ::1], LAW_TYPE, _A1, _t.float64, _t.float64, _t.int64,
                      _t.float64[:, ::1], _t.int64[::1], _A1)


def _copy(law_argument: bool) -> Any:
    stay = kernel(rebind(_stay, _DRIVE=K._DRIVES[law_argument]), inline="always",
                  name=f"reduced_stay_{'law' if law_argument else 'inlined'}")
    return kernel(rebind(_returns, _stay=stay), name=f"reduced_returns_{'law' if law_argument else 'inlined'}")


#: The two copies: the paper's law inlined in the segment driver (False) and the law as an argument (True).
_COPIES = {False: _copy(False), True: _copy(True)}


def returns(law_argument: bool) -> Any:
    """:func:`_returns` calling the segment driver copy ``law_argument``
    (:func:`peelapprox._reduced._segment_kernel.run`),
    compiled for :data:`RETURNS_SIG` on first use (from numba's cache when it is there)."""
    K.run(law_argument)  # the driver it calls, compiled (or loaded) and frozen first
    return compile_only(_COPIES[law_argument], RETURNS_SIG)
