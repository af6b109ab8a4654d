"""The lean path of the reduced segments: one branch planned once, its stays run through the compiled driver.

:func:`peelapprox.reduced_segment` (:mod:`peelapprox._reduced._segment`) validates every argument; a chain of
segments (:func:`peelapprox.approximate_attractor`) validates once, plans each branch once (:func:`segment_plan`)
and runs the compiled driver per stay (:func:`run_segment`): the one integrator and field of the public function
(:mod:`peelapprox._reduced._segment_kernel`), without its per-call checks.  The equations, the desingularised
time and the tolerance semantics are those of :mod:`peelapprox._reduced._segment`'s docstring.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field
from typing import Any, NamedTuple, cast

import numpy as np

from .._compiled._jit import wrapper_address as _wrapper_address
from .._packing import model_block
from .._params import PeelParams
from .._status import LAW_DOMAIN, NONFINITE, OUT_FULL, V_CEILING, V_FLOOR
from ..law import ALL_LAWS
from ..law._abi import LAW_SIG, LAW_TYPE
from ..law._compiled import CompiledLaw
from ..law._paper import paper_fp
from . import _segment_kernel as K
from ._alpha import _damping_time, _decay, _frozen_rate, _omega, _sinusoid, _wkb_match
from ._segment_kernel import ALPHA_MODELS, V_EQUATIONS

__all__ = ["SegmentPlan", "SegmentRun", "run_segment", "segment_plan", "segment_status"]


#: The compiled laws' addresses, looked up once per law while it lives: the lookup (~0.25 ms: numba's compile
#: result and LLVM's function table) is the same for every plan of the law, and a reduced map builds three plans
#: per call.
_ADDRESSES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


class _LawAddress:
    """A compiled law passed to the driver by its cached address (numba's wrapper-address protocol).

    Passing the law's dispatcher itself makes numba type it and look up its compiled wrapper on every call of
    the driver, ~35 µs: more than a short segment's integration.  This object carries the type
    (``_numba_type_``, :data:`peelapprox.law._abi.LAW_TYPE`) and the address, looked up once; the driver calls
    the same compiled law (measured: the same numbers bitwise, a 100-cycle reduced map at V = 2.26, I = 1e-2
    in 3.0 ms instead of 6.8 ms).
    """

    _numba_type_ = LAW_TYPE
    __slots__ = ("fn", "address")

    def __init__(self, fn: Any) -> None:
        self.fn = fn  # keeps the compiled law, and so its address, alive
        address = _ADDRESSES.get(fn)
        if address is None:
            address = _ADDRESSES[fn] = _wrapper_address(fn, LAW_SIG)
        self.address = address

    def __wrapper_address__(self) -> int:
        return self.address


@dataclass(frozen=True)
class SegmentPlan:
    """What one branch's reduced segments share, whatever their entry state (:func:`segment_plan`).

    ``q`` is the kernel's parameter vector with the model block and the entry-independent fields filled (α model,
    v equation, ``v_in``, ``f'(v_in)``, ``F_rate``); :func:`run_segment` copies it and fills the entry state.
    ``x_f``, ``x_lo``, ``x_hi`` are the exit, floor and ceiling of ln v; ``floor_law``/``ceiling_law`` say whether
    the floor (ceiling) is the law's domain rather than the e^60 fall (rise).  ``t_max`` None: the default horizon
    of :func:`reduced_segment`, from the entry force.
    """

    params: PeelParams
    law: CompiledLaw
    branch: str
    alpha_model: int
    v_equation: int
    v_in: float
    v_f: float
    fp_in: float
    F_rate: float
    x_f: float
    x_lo: float
    x_hi: float
    floor_law: bool
    ceiling_law: bool
    rtol: float
    t_max: float | None
    max_steps: int
    q: np.ndarray = field(repr=False)
    drive: Any = field(repr=False)
    law_arg: Any = field(repr=False)


class SegmentRun(NamedTuple):
    """One run of the compiled driver (:func:`run_segment`): its status code, the final state
    ``y = (t, ln v, F, α, α̇)`` (α, α̇ the state's: a closed form's are
    :func:`peelapprox._reduced._segment_kernel.alpha_at`
    of ``y, q``), the stored rows and counters, the parameter vector and the entry α, α̇, atol, t_max used."""

    code: int
    y: np.ndarray
    rows: np.ndarray
    cnt: np.ndarray
    q: np.ndarray
    alpha_in: float
    alphadot_in: float
    atol: np.ndarray
    t_max: float


def segment_plan(params: PeelParams, law: CompiledLaw, branch: str, *, v_in: float, v_f: float, alpha_model: str,
                 v_equation: str, F_rate: float | None, rtol: float, t_max: float | None,
                 max_steps: int) -> SegmentPlan:
    """The entry-independent inputs of one branch's segments, from arguments already validated (as
    :func:`reduced_segment` checks them: velocities on the branch and in the law's domain, known models)."""
    am = ALPHA_MODELS.index(alpha_model)
    s = _frozen_rate(params, v_in) if F_rate is None else F_rate
    fp_in = paper_fp(v_in, params.V) if law.inlined else law.df(v_in)
    q = model_block(params, K.N_Q, ALL_LAWS)
    q[K.Q_AM] = am
    q[K.Q_VE] = V_EQUATIONS.index(v_equation)
    d_lo, d_hi = law.domain
    x_lo = math.log(max(v_in, 1e-300)) - 60.0 if branch == "AB" else -np.inf  # v fell by e^60: v -> 0
    x_hi = math.log(1e3 * v_in) if branch == "CD" else np.inf
    # the law's domain: v leaves it only below v_in on AB or above v_in on CD (the exit v_f lies inside it)
    floor_law = branch == "AB" and d_lo > 0 and math.log(d_lo) > x_lo
    ceiling_law = branch == "CD" and math.isfinite(d_hi) and math.log(d_hi) < x_hi
    x_lo = math.log(d_lo) if floor_law else x_lo
    x_hi = math.log(d_hi) if ceiling_law else x_hi
    return SegmentPlan(params=params, law=law, branch=branch, alpha_model=am, v_equation=int(q[K.Q_VE]),
                       v_in=v_in, v_f=v_f, fp_in=fp_in, F_rate=s, x_f=math.log(v_f), x_lo=x_lo, x_hi=x_hi,
                       floor_law=floor_law, ceiling_law=ceiling_law, rtol=rtol, t_max=t_max,
                       max_steps=int(max_steps), q=q, drive=K.run(not law.inlined), law_arg=_LawAddress(law.arg))


def run_segment(plan: SegmentPlan, F_in: float, alpha_in: float | None, alphadot_in: float | None, *,
                amplitude: float | None = None, phase: float | None = None, atol: np.ndarray | None = None,
                mode: int = K.SAVE_NONE, t_eval: np.ndarray | None = None, cap: int = 1) -> SegmentRun:
    """One stay on ``plan``'s branch from the entry ``(F_in, α_in, α̇_in)`` (validated by the caller; the α
    model's inputs present), through the compiled driver.  A closed-form model's entry is its own: the sinusoid
    matched to ``(α_in, α̇_in)`` unless ``amplitude, phase`` are given, ``α̇_in = -α_in/τ`` for
    ``"exponential"``, 0 for ``"static"``."""
    p = plan.params
    am, s = plan.alpha_model, plan.F_rate
    tau = _damping_time(p.R, plan.fp_in, F_in)
    if am == K.AM_SIN:
        if amplitude is None or phase is None:
            amplitude, phase = _wkb_match(F_in, s, alpha_in, alphadot_in, p.R, p.I)
        alpha_in, alphadot_in = (float(x) for x in _sinusoid(0.0, amplitude, phase, F_in, s, p.R, p.I))
    elif am in (K.AM_EXP, K.AM_STATIC):
        alphadot_in = float(_decay(0.0, alpha_in, tau)[1]) if am == K.AM_EXP else 0.0
    assert alpha_in is not None and alphadot_in is not None  # the caller's checks
    q = K.segment_parameters(
        plan.q.copy(), alpha_model=am, v_equation=plan.v_equation, F_in=F_in, v_in=plan.v_in, fp_in=plan.fp_in,
        F_rate=s, amplitude=amplitude if amplitude is not None else 0.0, phase=phase if phase is not None else 0.0,
        alpha_in=alpha_in, alphadot_in=alphadot_in, tau=tau)
    Om = float(_omega(F_in, p.R, p.I))
    if atol is None:
        a_scale = max(abs(alpha_in), abs(alphadot_in) / Om, 1e-8)
        atol = plan.rtol * np.array([1e-3, 1.0, F_in, a_scale, Om * a_scale])
    t_max = plan.t_max
    if t_max is None:
        bs = plan.law.structure
        gap = (cast(float, bs.f_max) - cast(float, bs.f_min)) if bs.has_folds else F_in
        t_max = 20.0 * gap / (p.k * p.V) + 20.0 * 2.0 * math.pi / Om
    te = np.empty(0) if t_eval is None else np.ascontiguousarray(t_eval, dtype=float)
    y0 = np.array([0.0, math.log(plan.v_in), F_in, alpha_in, alphadot_in])
    while True:
        y = y0.copy()
        out = np.empty((cap, 5))
        cnt = np.zeros(5, dtype=np.int64)
        try:
            code = plan.drive(y, q, plan.law_arg, plan.law.coef, plan.rtol, atol, plan.x_f, plan.x_lo, plan.x_hi,
                              plan.branch == "AB", t_max, plan.max_steps, mode, te, out, cnt)
        except ZeroDivisionError:  # a closed form's ramp F_in + s t at exactly 0 (the sinusoid's F_in/F, s < 0 where
            code = NONFINITE  # v_in > V): what a step past it gives as NaN, the field's square roots of F < 0
        if code != OUT_FULL:
            return SegmentRun(int(code), y, out[:int(cnt[K.C_NOUT])], cnt, q, float(alpha_in), float(alphadot_in),
                              atol, float(t_max))
        cap *= 4


def segment_status(plan: SegmentPlan, code: int) -> int:
    """The status of a run that did not reach the exit: :data:`peelapprox._status.LAW_DOMAIN` when the floor
    (ceiling) it hit was the law's end rather than the e^60 fall (rise), else ``code``."""
    left = (code == V_FLOOR and plan.floor_law) or (code == V_CEILING and plan.ceiling_law)
    return LAW_DOMAIN if left else int(code)
