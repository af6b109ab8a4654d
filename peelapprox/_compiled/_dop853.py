"""The one compiled integrator: Dormand–Prince 8(5,3) with dense output, in numba.

Both compiled solvers of the package use this module: the hybrid (ε → 0) DAE
solver (``exact._hybrid``) and the reduced branch-wise equations
(``peelapprox._reduced._segment_kernel``).  Each of them owns its *driver* (what happens at
events, jumps and output), never the step itself.

Method
------
Dormand–Prince 8(5,3) with its 7th-order dense output (Hairer, Nørsett &
Wanner, *Solving ODEs I*, II.10), using the package's copy of scipy's coefficient
tables (:mod:`peelapprox._compiled._dop853_tableau`, with its provenance and licence) and scipy's step-size
controller (safety 0.9, factors in [0.2, 10], error exponent -1/8, no growth
right after a rejection).  Tolerance semantics are scipy's: a step is accepted
when the RMS over components of ``err_i / (atol_i + rtol·max(|y_i|, |y_new_i|))``
is below 1, with the combined 5th/3rd-order error estimate of DOP853.

Use
---
``make_dop853(rhs)`` binds the pieces that call a vector field
``rhs(y, p, out)`` (a numba-jitted function writing dy/dx into ``out``) and
returns them as a :class:`Dop853` module object.  The field is bound as a
closure variable, not passed as an argument, so that it is inlined into the
stages (through a first-class function argument it is an indirect call LLVM
cannot inline: ``docs/performance.md``).  Every piece here, bound or not, is
a ``kernel(inner=True)`` helper (:func:`peelapprox._compiled._jit.kernel`): compiled
into the driver that calls it, without Python wrappers or cache files of its
own, and cached inside that driver, whose cache index carries a hash of all
kernel sources, so a changed field, tableau or ``_generated.py`` is always
recompiled.  The bound pieces are renamed after the field, so that a cold
run's compile listing (``comparisons.benchmark.cold_start --detail``) tells
the fields apart.
"""

from __future__ import annotations

import types
from collections.abc import Callable

import numpy as np

from . import _dop853_tableau as _dop
from ._jit import kernel

__all__ = [
    "Dop853",
    "make_dop853",
    "combine",
    "workspace",
    "interp1",
    "interp_mean",
    "solve_theta_mean",
    "interp",
    "solve_theta",
    "crossing",
    "state_at",
    "N_STAGES",
    "N_STAGES_EXTENDED",
    "STEP_OK",
    "STEP_FAILED",
]

N_STAGES = _dop.N_STAGES  # 12
N_STAGES_EXTENDED = _dop.N_STAGES_EXTENDED  # 16
_NS = N_STAGES
_NX = N_STAGES_EXTENDED
_A = np.ascontiguousarray(_dop.A[:_NS, :_NS])
_B = np.ascontiguousarray(_dop.B)
_E3 = np.ascontiguousarray(_dop.E3)
_E5 = np.ascontiguousarray(_dop.E5)
_D = np.ascontiguousarray(_dop.D)
_AX = np.ascontiguousarray(_dop.A[_NS + 1 :])

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
ERR_EXP = -1.0 / 8.0
#: a step is abandoned after this many successive rejections
MAX_REJECTIONS = 60

STEP_OK = 0
STEP_FAILED = 1


class Dop853(types.ModuleType):
    """Compiled DOP853 pieces bound to one vector field (see :func:`make_dop853`).

    A module object rather than a tuple: numba reads a global module's attributes as the functions they are,
    and each piece is a ``kernel(inner=True)`` helper (plain function, compiled into the driver that calls it).

    Attributes
    ----------
    initial_step : ``(y0, f0, p, rtol, atol, work) -> h0``
        Hairer's starting-step heuristic (as ``scipy.integrate`` select_initial_step);
        ``work`` is a ``(3, n)`` scratch array; costs one field evaluation.
    step : ``(y, f0, h, p, rtol, atol, K, y_new, tmp, sc) -> (status, h, h_next, n_rejected, n_rhs)``
        One *accepted* step from ``y`` (with ``f0 = rhs(y)``), retrying with
        smaller ``h`` after rejections.  On return ``y_new`` holds the new
        state, ``K[N_STAGES]`` the field there, ``h`` the step taken and
        ``h_next`` the proposed next step.  ``status`` is ``STEP_FAILED`` after
        ``MAX_REJECTIONS`` successive rejections or an underflowing step.
    dense : ``(y_old, y_new, K, h, p, Fc, tmp)``
        The extra stages and the 7 interpolation rows ``Fc`` of the step just
        taken (costs ``N_STAGES_EXTENDED - N_STAGES - 1 = 3`` field evaluations).
    ensure_dense : ``(done, y_old, y_new, K, h, p, Fc, tmp, cnt, i_rhs) -> True``
        ``dense`` unless ``done`` (the coefficients of this step already exist),
        adding its field evaluations to the counter ``cnt[i_rhs]``: the drivers'
        lazy idiom ``done = ensure_dense(done, ...)``.
    """

    initial_step: Callable
    step: Callable
    dense: Callable
    ensure_dense: Callable


@kernel(inner=True)
def workspace(n):
    """Scratch arrays for a driver on an n-dimensional state:
    ``(K, y_new, f0, tmp, sc, work, Fc, ye)`` with K of shape (16, n), work (3, n), Fc (7, n)."""
    return (np.empty((_NX, n)), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty((3, n)),
            np.empty((7, n)), np.empty(n))


@kernel(inner=True)
def _norm(x):
    n = x.shape[0]
    s = 0.0
    for i in range(n):
        s += x[i] * x[i]
    return np.sqrt(s / n)


@kernel(inner=True)
def combine(y, h, K, coef, n, out):
    """out = y + h * sum_{j<n} coef[j] K[j]  (an RK stage argument or the step result)."""
    for i in range(y.shape[0]):
        acc = 0.0
        for j in range(n):
            acc += K[j, i] * coef[j]
        out[i] = y[i] + h * acc


@kernel(inner=True)
def interp1(y_old, Fc, x, i):
    """Component i of the dense output at fraction x ∈ [0, 1] of the step."""
    yv = 0.0
    for r in range(6, -1, -1):
        yv += Fc[r, i]
        if (6 - r) % 2 == 0:
            yv *= x
        else:
            yv *= 1.0 - x
    return yv + y_old[i]


@kernel(inner=True)
def interp(y_old, Fc, x, out):
    """The whole dense-output state at fraction x of the step."""
    for i in range(y_old.shape[0]):
        out[i] = interp1(y_old, Fc, x, i)


@kernel(inner=True)
def interp_mean(y_old, Fc, x, i0, n):
    """The mean of the ``n`` dense-output components ``i0 … i0 + n - 1`` at fraction x of the step (summed in
    index order, then divided by n: for n = 1, bitwise :func:`interp1` of component ``i0``)."""
    s = 0.0
    for j in range(n):
        s += interp1(y_old, Fc, x, i0 + j)
    return s / n


@kernel(inner=True)
def solve_theta_mean(y_old, Fc, i0, n, target, g0, xb, g1):
    """x in [0, xb] with :func:`interp_mean` ``(x, i0, n)`` = target: the one Illinois root-finder.

    ``g0``, ``g1`` are the values minus target at 0 and xb, of opposite sign
    (or ``g1 == 0``, which returns xb).  Illinois-modified regula falsi, to ~1 ulp in x.
    The peel front's driver finds the mean front's jump with it (the mean of the strips' velocities);
    :func:`solve_theta` is its case n = 1.
    """
    if g1 == 0.0:
        return xb
    a, b = 0.0, xb
    ga, gb = g0, g1
    side = 0
    for _ in range(200):
        x = (a * gb - b * ga) / (gb - ga)
        if not (a < x < b):
            x = 0.5 * (a + b)
        gx = interp_mean(y_old, Fc, x, i0, n) - target
        if gx == 0.0:
            return x
        if (gx > 0.0) == (gb > 0.0):
            b, gb = x, gx
            if side == 1:
                ga *= 0.5
            side = 1
        else:
            a, ga = x, gx
            if side == -1:
                gb *= 0.5
            side = -1
        if b - a <= 4e-16:
            break
    return b if abs(gb) < abs(ga) else a


@kernel(inner=True)
def solve_theta(y_old, Fc, i, target, g0, xb, g1):
    """x in [0, xb] with interp1(x, i) = target.

    ``g0``, ``g1`` are the values minus target at 0 and xb, of opposite sign
    (or ``g1 == 0``).  Illinois-modified regula falsi, to ~1 ulp in x (:func:`solve_theta_mean` of one component).
    """
    return solve_theta_mean(y_old, Fc, i, 1, target, g0, xb, g1)


@kernel(inner=True)
def crossing(y_old, Fc, i, target, xb, value_b):
    """Fraction x in [0, xb] of the step where the increasing component i reaches
    ``target`` (0 if it is already there); ``value_b`` is its value at xb."""
    if target <= y_old[i]:
        return 0.0
    return solve_theta(y_old, Fc, i, target, y_old[i] - target, xb, value_b - target)


@kernel(inner=True)
def state_at(y_old, Fc, i, target, xb, value_b, out):
    """Dense-output state where the increasing component i equals ``target``
    (a ``t_eval`` point); component i is set to ``target`` exactly."""
    interp(y_old, Fc, crossing(y_old, Fc, i, target, xb, value_b), out)
    out[i] = target


def make_dop853(rhs) -> Dop853:
    """The DOP853 step, starting-step and dense-output pieces bound to ``rhs`` (compiled by the driver calling them).

    Parameters
    ----------
    rhs : numba dispatcher
        ``rhs(y, p, out)`` writes the vector field at ``y`` (parameters ``p``)
        into ``out``.  A field that cannot be evaluated (a trial stage left the
        domain) should write NaN: the step is then rejected and retried with
        ``h/4``.

    Returns
    -------
    Dop853
    """

    tag = _cache_tag(rhs)

    def jit(fn):
        return kernel(fn, name=f"{fn.__name__}__{tag}", inner=True)

    dense = jit(_dense_for(rhs))
    pieces = Dop853(f"dop853__{tag}")
    pieces.initial_step, pieces.step, pieces.dense, pieces.ensure_dense = (
        jit(_initial_step_for(rhs)), jit(_step_for(rhs)), dense, jit(_ensure_dense_for(dense)))
    return pieces


# The pieces' Python functions, closed over the field (numba freezes a closure's free variables as globals).
def _initial_step_for(rhs):
    def initial_step(y0, f0, p, rtol, atol, work):
        n = y0.shape[0]
        sc = work[0]
        tmp = work[1]
        f1 = work[2]
        for i in range(n):
            sc[i] = atol[i] + abs(y0[i]) * rtol
        for i in range(n):
            tmp[i] = y0[i] / sc[i]
        d0 = _norm(tmp)
        for i in range(n):
            tmp[i] = f0[i] / sc[i]
        d1 = _norm(tmp)
        if d0 < 1e-5 or d1 < 1e-5:
            h0 = 1e-6
        else:
            h0 = 0.01 * d0 / d1
        for i in range(n):
            tmp[i] = y0[i] + h0 * f0[i]
        rhs(tmp, p, f1)
        for i in range(n):
            tmp[i] = (f1[i] - f0[i]) / sc[i]
        d2 = _norm(tmp) / h0
        if not np.isfinite(d2):
            return h0 * 1e-3
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
        return min(100.0 * h0, h1)

    return initial_step


def _step_for(rhs):
    def step(y, f0, h, p, rtol, atol, K, y_new, tmp, sc):
        n = y.shape[0]
        rejected = False
        n_rej = 0
        n_rhs = 0
        while True:
            for i in range(n):  # not K[0, :] = f0: numba compiles a shape-mismatch message for that (~4 s)
                K[0, i] = f0[i]
            for s in range(1, _NS):
                combine(y, h, K, _A[s], s, tmp)
                rhs(tmp, p, K[s])
            combine(y, h, K, _B, _NS, y_new)
            rhs(y_new, p, K[_NS])
            n_rhs += _NS
            e5 = 0.0
            e3 = 0.0
            for i in range(n):
                sc[i] = atol[i] + max(abs(y[i]), abs(y_new[i])) * rtol
                a5 = 0.0
                a3 = 0.0
                for j in range(_NS + 1):
                    a5 += K[j, i] * _E5[j]
                    a3 += K[j, i] * _E3[j]
                a5 /= sc[i]
                a3 /= sc[i]
                e5 += a5 * a5
                e3 += a3 * a3
            if e5 == 0.0 and e3 == 0.0:
                err = 0.0
            else:
                err = abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n)
            if err < 1.0:
                if err == 0.0:
                    fac = MAX_FACTOR
                else:
                    fac = min(MAX_FACTOR, SAFETY * err**ERR_EXP)
                if rejected:
                    fac = min(1.0, fac)
                return STEP_OK, h, h * fac, n_rej, n_rhs
            # rejected (err >= 1, or NaN from a stage outside the domain)
            if err != err or err == np.inf:
                h *= 0.25
            else:
                h *= max(MIN_FACTOR, SAFETY * err**ERR_EXP)
            rejected = True
            n_rej += 1
            if n_rej > MAX_REJECTIONS or h <= 1e-300:
                return STEP_FAILED, h, h, n_rej, n_rhs

    return step


def _dense_for(rhs):
    def dense(y_old, y_new, K, h, p, Fc, tmp):
        n = y_old.shape[0]
        for si in range(_NX - _NS - 1):
            s = _NS + 1 + si
            combine(y_old, h, K, _AX[si], s, tmp)
            rhs(tmp, p, K[s])
        f_new = K[_NS]
        for i in range(n):
            dy = y_new[i] - y_old[i]
            Fc[0, i] = dy
            Fc[1, i] = h * K[0, i] - dy
            Fc[2, i] = 2.0 * dy - h * (f_new[i] + K[0, i])
            for r in range(4):
                acc = 0.0
                for j in range(_NX):
                    acc += _D[r, j] * K[j, i]
                Fc[3 + r, i] = h * acc

    return dense


def _ensure_dense_for(dense_j):
    def ensure_dense(done, y_old, y_new, K, h, p, Fc, tmp, cnt, i_rhs):
        if not done:
            dense_j(y_old, y_new, K, h, p, Fc, tmp)
            cnt[i_rhs] += _NX - _NS - 1
        return True

    return ensure_dense


def _cache_tag(rhs) -> str:
    # The field's module and qualname, as a name suffix for its pieces (their
    # compile events then say which field they were compiled for).
    py = getattr(rhs, "py_func", rhs)
    return f"{py.__module__}.{py.__qualname__}".replace(".", "_").replace("<", "").replace(">", "")
