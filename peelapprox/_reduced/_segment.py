"""The paper's reduced velocity equation on one branch, coupled to an α model.

Sec. V (Case b) estimates how long the orbit stays on a branch by integrating
the velocity equation from the landing velocity ``v_in`` until v reaches the
fold ``v_f`` (where ``f'(v_f, V) = 0`` and the orbit must jump):

* approxvdot: ``f'(v) v̇ = k(V - v) + F α̇``, ``Ḟ = k(V - v)``;
* fullvdot:   ``f'(v) v̇ = Ḟ (1 + α) + F α̇``, ``Ḟ = k(V - v + R α α̇)`` (FLOW3).

The paper writes the force as ``F ≃ F_in + k(V - v) t``; with v changing
along the branch we integrate ``Ḟ`` instead (the two agree when v is
constant, and the integral is what reproduces the paper's CD number
ΔF = 19.4 N; see ``docs/paper-notes.md``).

α comes from one of the models in :data:`ALPHA_MODELS`:

==================  ================================================================  ==========
model               α equation                                                        inputs
==================  ================================================================  ==========
``"sinusoid"``      WKB sinusoid ``A (F_in/F_lin)^¼ sin(∫√(F_lin R/I) + φ)``,          (A, φ) or
                    ``F_lin = F_in + s t`` (closed form)                                (α_in, α̇_in)
``"harmonic"``      approxalpha with F frozen at ``F_in`` (closed form)                (α_in, α̇_in)
``"approxalpha"``   approxalpha with the branch force: ``α̈ = -F R α/I`` (Airy when    (α_in, α̇_in)
                    v ≪ V)
``"airy2"``         Airy2: ``α̈ = -F R α/I - F α̇/(R f'(v))``                           (α_in, α̇_in)
``"airy2_frozen"``  Airy2 with F and f' frozen at entry (the paper's CD shortcut)      (α_in, α̇_in)
``"airy1"``         Airy1: ``α̈ = -F R α/I - (Ḟ + F α̇)/(R f'(v))``                     (α_in, α̇_in)
``"genalpha"``      genalpha: ``α̈ = -F R α/I - v̇/R`` with v̇ from the v equation       (α_in, α̇_in)
                    (Case III, high I and V)
``"exponential"``   CD limit ``α = α_in exp(-t/τ)``, ``τ = R f'(v_in)/F_in`` (closed)  α_in
``"static"``        ``α = α_in``, ``α̇ = 0``: the quasi-static (inertia-free) limit      α_in
==================  ================================================================  ==========

``genalpha`` with ``fullvdot`` is the full model FLOW1–FLOW3 + CONSTR
linearised in α (``sin α → α``), so it reproduces the exact branch dynamics
up to O(α²) relative (the closure slope ``cos α`` vs 1; tested).

Formulation and solver
----------------------
v̇ is singular at the fold (``f' → 0``), the very point we integrate to.  As in
the hybrid solver, time is desingularised, ``dt/ds = v f'(v)``, on the state
``y = (t, ln v, F, α, α̇)``::

    dt/ds = v f',   d ln v/ds = N,   dF/ds = v f' Ḟ,   dα/ds = v f' α̇,
    dα̇/ds = v f' (-F R α/I) - [damping terms × v f']

with ``N`` the numerator of the v equation; every ``1/f'`` cancels, so the
field is smooth through the fold and the exit is the transversal event
``ln v = ln v_f``.  Closed-form α models are evaluated at the current t.

The integrator is the package's one compiled DOP853 (:mod:`peelapprox._compiled._dop853`),
driven by :mod:`peelapprox._reduced._segment_kernel` (the field, its parameter layout and
the exit event), with scipy's tolerance semantics: a step is accepted when the RMS of
``err_i / (atol_i + rtol·|y_i|)`` is below 1 over ``y = (t, ln v, F, α, α̇)``.
The default ``atol = rtol × (1 ms, 1, F_in, α_scale, Ω_in α_scale)`` with
``α_scale = max(|α_in|, |α̇_in|/Ω_in, 1e-8)``, ``Ω_in = sqrt(F_in R/I)``.

One branch's plan (the entry-independent inputs) and the driver's run from one entry, without the per-call
checks, are :mod:`peelapprox._reduced._segment_plan` (the lean path a chain of segments takes).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from .._params import PeelParams
from .._ranges import TIME_MAX
from .._status import DONE, MAX_STEPS, T_MAX, status_error
from ..law import BRANCHES
from ..law._compiled import CompiledLaw, compiled_law
from ..validate import choice, duration, integer, optional, optional_finite, reals, times
from ..validate import params as _params
from ..validate import rtol as _rtol
from ..validate import state as _state
from . import _segment_kernel as K
from ._segment_kernel import ALPHA_MODELS, V_EQUATIONS
from ._segment_plan import SegmentPlan, SegmentRun, run_segment, segment_plan, segment_status

__all__ = ["ALPHA_MODELS", "V_EQUATIONS", "ReducedSegment", "reduced_segment"]

#: Valid ``atol`` components: below 1e-100 the squared scaled errors of the step-size control underflow
#: (``atol = 1e-200`` divided by zero); above 1e3 the error test accepts any step (every component's
#: natural scale on a branch is smaller, except F in N, whose default atol is ``rtol F_in``).
ATOL_RANGE = (1e-100, 1e3)


@dataclass(frozen=True)
class ReducedSegment:
    """One branch integrated with a reduced equation (:func:`reduced_segment`).

    Attributes
    ----------
    branch, alpha_model, v_equation : str
        What was integrated.
    dt : float
        Time to reach ``v_f`` [s] (the branch stay, Δt).
    F_in, F_exit, dF : float
        Pull force at entry and exit and ``ΔF = F_exit - F_in`` [N].
    v_in, v_f : float
        Entry and exit velocities [m/s].
    alpha_in, alphadot_in, alpha_exit, alphadot_exit : float
        α [rad] and α̇ [rad/s] at entry and exit (closed-form models: their value).
    t, v, F, alpha, alphadot : ndarray
        The curves at the accepted steps (``save="steps"``) or at ``t_eval``;
        empty for ``save="none"``.  t is measured from the branch entry.
    n_steps, n_rejected, n_rhs : int
        Solver counters; ``wall_time`` [s] of the call.
    rtol : float
    atol : ndarray
        Tolerances on ``(t, ln v, F, α, α̇)``.
    """

    branch: str
    alpha_model: str
    v_equation: str
    dt: float
    F_in: float
    F_exit: float
    dF: float
    v_in: float
    v_f: float
    alpha_in: float
    alphadot_in: float
    alpha_exit: float
    alphadot_exit: float
    t: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)
    alpha: np.ndarray = field(repr=False)
    alphadot: np.ndarray = field(repr=False)
    n_steps: int = 0
    n_rejected: int = 0
    n_rhs: int = 0
    wall_time: float = 0.0
    rtol: float = 0.0
    atol: np.ndarray | None = field(default=None, repr=False)

    def as_dict(self) -> dict:
        """Scalars only (no curves), for tables and JSON."""
        keys = ("branch", "alpha_model", "v_equation", "dt", "F_in", "F_exit", "dF", "v_in", "v_f", "alpha_in",
                "alphadot_in", "alpha_exit", "alphadot_exit", "n_steps", "n_rejected", "n_rhs", "wall_time", "rtol")
        return {k: getattr(self, k) for k in keys}


def reduced_segment(params: PeelParams, branch: str, *, F_in: float, alpha_in: float | None = None,
                    alphadot_in: float | None = None, amplitude: float | None = None, phase: float | None = None,
                    v_in: float | None = None, v_f: float | None = None, alpha_model: str = "approxalpha",
                    v_equation: str = "approxvdot", F_rate: float | None = None, rtol: float = 1e-10, atol=None,
                    t_max: float | None = None, save: str = "steps", t_eval=None,
                    max_steps: int = 1_000_000) -> ReducedSegment:
    """Time and force change on one branch from the paper's reduced equations.

    Integrates approxvdot or fullvdot (module docstring) coupled to an α model from ``v_in`` until v reaches
    ``v_f`` and returns Δt, ΔF, the exit state and the v(t), α(t) curves (the paper's Figs. 8 and 9).

    Parameters
    ----------
    params : PeelParams
        V, I, k, R and the law ``params.force`` (one with a compiled kernel, :func:`peelapprox.kernels.compiled_law`:
        its folds, landings, ``f'(v_in)`` and the domain v may not leave).  The reduced equations are linear in α
        (the paper's ``sin α ≈ α``), whatever ``params.geometry``.
    branch : {"AB", "CD"}
        AB: v rises from ``v_in`` to ``v_f`` (default ``v_max``); CD: v falls to ``v_f`` (default ``v_min``).
    F_in, alpha_in, alphadot_in : float
        Pull force [N], α [rad] and α̇ [rad/s] at entry.  ``"exponential"`` and ``"static"`` use ``alpha_in``
        only; ``"sinusoid"`` accepts ``amplitude, phase`` instead.
    amplitude, phase : float, optional
        The paper's ``(α_in, φ)`` of the sinusoid (``"sinusoid"`` only).
    v_in, v_f : float, optional
        Entry and exit velocities [m/s]; default the landing velocity of a jump onto the branch
        (``branch_structure(V, force=params.force).v_land_ab`` / ``v_land_cd``) and the branch's fold.
    alpha_model, v_equation : str
        One of :data:`ALPHA_MODELS` (default ``"approxalpha"``); ``"approxvdot"`` (default) or ``"fullvdot"``.
    F_rate : float, optional
        Slope ``s`` of ``F_lin = F_in + s t`` used by ``"sinusoid"``; default ``k (V - v_in)``.
    rtol : float, default 1e-10
        In [1e-14, 1e-2] (:data:`RTOL_RANGE`).
    atol : float or array_like of 5, optional
        Tolerances, each in [1e-100, 1e3] (:data:`ATOL_RANGE`; the module docstring: semantics, default).
    t_max : float, optional
        Horizon [s] in (0, 1e6]; default ``20 (f_max - f_min)/(k V) + 20 × 2π/Ω_in``.
    save : {"steps", "none"}, and t_eval : array_like, optional
        Store the curves at accepted steps, or only entry and exit; or, when ``t_eval`` is given, at those
        increasing times [s, from entry] (dense output; times after the exit are not filled).
    max_steps : int
        Step budget, an integer in [1, 1e15] (a float such as ``1e6`` is refused: write ``10**6``).

    Entry states must lie in :data:`peelapprox.STATE_RANGES` (``F_in`` in [1e-3, 1e7] N, ``alpha_in`` and
    ``amplitude`` in [-π, π], ``alphadot_in`` in [-1e9, 1e9] rad/s, ``v_in``, ``v_f`` in (1e-150, 1e3] m/s,
    ``F_rate`` in [-1e12, 1e12] N/s).

    Returns
    -------
    ReducedSegment

    Raises
    ------
    TypeError
        (``ArgumentTypeError``, also a ValueError) For an argument of the wrong kind: a string, bool or None for a
        number, a float for ``max_steps``, anything but a PeelParams for ``params``.
    ValueError
        For an unknown model, a value out of its range, a velocity off the branch or outside the law's domain,
        missing inputs, or a law without a compiled kernel; the message names the argument.
    ModelBreakdown
        If v → 0 on AB, v runs away on CD, F reaches 0, or v leaves the law's domain (a table's range: reason
        ``"law_domain"``); the reason is in the exception, with the time and state.
    SolverBudgetExceeded
        If v does not reach ``v_f`` before ``t_max`` or within ``max_steps``.
    """
    t_wall = time.perf_counter()
    a = _checked_arguments(params, branch, F_in, alpha_in, alphadot_in, amplitude, phase, v_in, v_f, alpha_model,
                           v_equation, F_rate, rtol, atol, t_max, save, t_eval, max_steps)
    law = compiled_law(a.params.force, a.params.V)  # ValueError naming params.force for a law without a kernel
    v_in, v_f = _branch_velocities(a.params, law, a.branch, a.v_in, a.v_f)
    plan = segment_plan(a.params, law, a.branch, v_in=v_in, v_f=v_f, alpha_model=a.alpha_model,
                        v_equation=a.v_equation, F_rate=a.F_rate, rtol=a.rtol, t_max=a.t_max, max_steps=a.max_steps)
    _check_alpha_inputs(plan.alpha_model, a)
    run = run_segment(plan, a.F_in, a.alpha_in, a.alphadot_in, amplitude=a.amplitude, phase=a.phase, atol=a.atol,
                      **_save_mode(a.save, a.t_eval))
    res = _segment_result(a, run, v_in, v_f, t_wall)
    if run.code != DONE:
        raise _segment_error(plan, a, run, res, law)
    return res


class _Arguments(NamedTuple):
    """:func:`reduced_segment`'s arguments, checked (``atol`` of 5, ``t_eval`` an array, or None)."""

    params: PeelParams
    branch: str
    F_in: float
    alpha_in: float | None
    alphadot_in: float | None
    amplitude: float | None
    phase: float | None
    v_in: float | None
    v_f: float | None
    alpha_model: str
    v_equation: str
    F_rate: float | None
    rtol: float
    atol: np.ndarray | None
    t_max: float | None
    save: str
    t_eval: np.ndarray | None
    max_steps: int


def _checked_arguments(params, branch, F_in, alpha_in, alphadot_in, amplitude, phase, v_in, v_f, alpha_model,
                       v_equation, F_rate, rtol, atol, t_max, save, t_eval, max_steps) -> _Arguments:
    """:func:`reduced_segment`'s arguments, each checked against its type and range (in this order: the first
    bad one is named)."""
    params = _params("params", params, where="reduced_segment", variants=False)
    branch = choice("branch", branch, BRANCHES)
    alpha_model = choice("alpha_model", alpha_model, ALPHA_MODELS)
    v_equation = choice("v_equation", v_equation, V_EQUATIONS)
    save = choice("save", save, ("steps", "none"))
    rtol = _rtol("rtol", rtol)
    max_steps = integer("max_steps", max_steps)
    F_in = _state("F_in", F_in, "F")
    v_in, v_f = optional(_state, "v_in", v_in, "v"), optional(_state, "v_f", v_f, "v")
    alpha_in = optional(_state, "alpha_in", alpha_in, "alpha")
    alphadot_in = optional(_state, "alphadot_in", alphadot_in, "omega")
    amplitude = optional(_state, "amplitude", amplitude, "alpha")
    phase = optional_finite("phase", phase)
    F_rate = optional(_state, "F_rate", F_rate, "F_rate")
    atol_v = None
    if atol is not None:
        atol_v = reals("atol", atol, *ATOL_RANGE)
        if atol_v.shape not in ((), (5,)):
            raise ValueError(f"atol must be a scalar or one value per (t, ln v, F, alpha, alphadot), got shape "
                             f"{atol_v.shape}")
        atol_v = np.broadcast_to(atol_v, (5,)).copy()
    t_max = optional(duration, "t_max", t_max)
    te = None if t_eval is None else times("t_eval", t_eval, hi=TIME_MAX)
    return _Arguments(params, branch, F_in, alpha_in, alphadot_in, amplitude, phase, v_in, v_f, alpha_model,
                      v_equation, F_rate, rtol, atol_v, t_max, save, te, max_steps)


def _branch_velocities(params: PeelParams, law: CompiledLaw, branch: str, v_in: float | None,
                       v_f: float | None) -> tuple[float, float]:
    """The entry and exit velocities on ``branch`` (the defaults: the landing and the fold), checked to lie on
    the branch and in the law's domain."""
    bs = law.structure
    d_lo, d_hi = law.domain
    if branch == "CD" and not bs.has_folds:
        raise ValueError(f"branch 'CD' does not exist for V={params.V}: f(v, V) has no folds")
    if v_in is None:
        v_in = bs.v_land_ab if branch == "AB" else bs.v_land_cd
        if v_in is None:
            raise ValueError(f"no AB landing velocity for V={params.V} (f_min <= f(0+)); give v_in explicitly")
    lo, hi = bs.branch_range(branch)
    if not (lo < v_in < hi):
        raise ValueError(f"v_in must be on branch {branch}, i.e. in ({lo}, {hi}) for V={params.V}; got {v_in}")
    if v_f is None:
        if not bs.has_folds:
            raise ValueError(f"V={params.V} has no fold; give v_f explicitly")
        assert bs.v_max is not None and bs.v_min is not None  # has_folds
        v_f = bs.v_max if branch == "AB" else bs.v_min
    if branch == "AB" and not (v_in < v_f <= hi):
        raise ValueError(f"v_f must be in (v_in, v_max] = ({v_in}, {hi}] on AB, got {v_f}")
    if branch == "CD" and not (lo <= v_f < v_in):
        raise ValueError(f"v_f must be in [v_min, v_in) = [{lo}, {v_in}) on CD, got {v_f}")
    for name, x in (("v_in", v_in), ("v_f", v_f)):
        if not d_lo <= x <= d_hi:
            raise ValueError(f"{name} must lie in the domain [{d_lo}, {d_hi}] m/s of the peel-force law "
                             f"{params.force!r}, got {x}")
    return v_in, v_f


def _check_alpha_inputs(am: int, a: _Arguments) -> None:
    """ValueError when the α model ``am`` (its code) lacks its entry inputs."""
    if am == K.AM_SIN:
        if a.amplitude is not None or a.phase is not None:
            if a.amplitude is None or a.phase is None:
                raise ValueError("alpha_model='sinusoid' needs both amplitude and phase (or alpha_in and alphadot_in)")
        elif a.alpha_in is None or a.alphadot_in is None:
            raise ValueError("alpha_model='sinusoid' needs (amplitude, phase) or (alpha_in, alphadot_in)")
    elif am in (K.AM_EXP, K.AM_STATIC):
        if a.alpha_in is None:
            raise ValueError(f"alpha_model={a.alpha_model!r} needs alpha_in")
    elif a.alpha_in is None or a.alphadot_in is None:
        raise ValueError(f"alpha_model={a.alpha_model!r} needs alpha_in and alphadot_in")


def _save_mode(save: str, t_eval: np.ndarray | None) -> dict[str, Any]:
    """The driver's storage arguments (``mode``, ``t_eval``, ``cap``) for ``save`` or ``t_eval``."""
    if t_eval is not None:
        return {"mode": K.SAVE_TEVAL, "t_eval": t_eval, "cap": t_eval.size}
    mode, cap = (K.SAVE_STEPS, 4096) if save == "steps" else (K.SAVE_NONE, 1)
    return {"mode": mode, "t_eval": np.empty(0), "cap": cap}


def _segment_result(a: _Arguments, run: SegmentRun, v_in: float, v_f: float, t_wall: float) -> ReducedSegment:
    """The :class:`ReducedSegment` of a run (``t_wall``: the call's start on ``time.perf_counter``)."""
    y, cnt, rows = run.y, run.cnt, run.rows
    al_e, ad_e = K.alpha_at(y, run.q)
    return ReducedSegment(
        branch=a.branch, alpha_model=a.alpha_model, v_equation=a.v_equation, dt=float(y[0]), F_in=a.F_in,
        F_exit=float(y[2]), dF=float(y[2] - a.F_in), v_in=v_in, v_f=v_f, alpha_in=float(run.alpha_in),
        alphadot_in=float(run.alphadot_in), alpha_exit=al_e, alphadot_exit=ad_e,
        t=rows[:, 0].copy(), v=rows[:, 1].copy(), F=rows[:, 2].copy(), alpha=rows[:, 3].copy(),
        alphadot=rows[:, 4].copy(), n_steps=int(cnt[K.C_STEPS]), n_rejected=int(cnt[K.C_REJ]),
        n_rhs=int(cnt[K.C_RHS]),
        wall_time=time.perf_counter() - t_wall, rtol=a.rtol, atol=run.atol,
    )


def _segment_error(plan: SegmentPlan, a: _Arguments, run: SegmentRun, res: ReducedSegment,
                   law: CompiledLaw) -> Exception:
    """The exception of a run that stopped before the exit (``res``: its partial result)."""
    y, branch = run.y, a.branch
    state = {"t": float(y[0]), "v": float(np.exp(y[1])), "F": float(y[2]), "alpha": res.alpha_exit,
             "alphadot": res.alphadot_exit}
    d_lo, d_hi = law.domain
    status = segment_status(plan, run.code)
    what = f"v = {state['v']:.6g} m/s {'fell below the start' if branch == 'AB' else 'rose above the end'} of the law"
    limit = {T_MAX: run.t_max, MAX_STEPS: int(a.max_steps)}.get(status)
    return status_error(status, t=state["t"], state=state, partial=res,
                        prefix=f"{a.alpha_model}+{a.v_equation} on {branch}: ",
                        where=f"at t={state['t']:.6g} s after entry (v={state['v']:.6g}, F={state['F']:.6g})",
                        limit=limit, v_f=plan.v_f, v_floor=math.exp(plan.x_lo) if branch == "AB" else 0.0,
                        why="fell by a factor e^60 below v_in: v -> 0", v_ceiling=1e3 * plan.v_in, v=state["v"],
                        lo=d_lo, hi=d_hi, law=repr(a.params.force), what=what)
