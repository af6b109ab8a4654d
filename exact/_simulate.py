"""``exact.simulate``: check the arguments, build the consistent start, and hand the run to its method."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import Any

from peelapprox import PeelParams
from peelapprox.errors import SolverBudgetExceeded
from peelapprox.io import ProgressLine
from peelapprox.kernels import BuildExpired, caller_budget
from peelapprox.validate import ArgumentTypeError, choice, duration
from peelapprox.validate import params as _params

from ._method_contract import Method, method_option
from ._model import MODELS, Model, model_of
from ._models import VP0_MAX
from ._options import Budget, SaveAt, output_options
from ._trajectory import State, Trajectory

__all__ = ["simulate", "model_option", "VP0_MAX"]


def _progress_printer(label: str) -> Callable[[float, float], None]:
    """``progress=True``: :class:`peelapprox.io.ProgressLine` in per mille of ``t_end`` (a line per 5 %)."""
    line: list[ProgressLine] = []

    def report(t: float, t_end: float) -> None:
        if not line:
            line.append(ProgressLine(label, 1000, count=False))
        line[0].update(min(1000, max(0, int(1000 * t / t_end))), f"t = {t:.6g} / {t_end:.6g} s")

    return report


def simulate(params: PeelParams, t_end: float, *, alpha0: float = 0.0, omega0: float | None = None,
             F0: float | None = None, branch0: str | None = None, Vp0: float | None = None,
             method: str | Method | None = None, solver: str | None = None, rtol: float = 1e-8,
             atol: None | float | Sequence[float] = None, eps: float | None = None, t_transient: float = 0.0,
             t_eval: Sequence[float] | None = None, save: str = "steps", max_points: int = 5_000_000,
             max_steps: int | None = None, max_jumps: int = 20_000_000, max_wall: float | None = None,
             v_floor: float | None = None, progress: None | bool | Callable[[float, float], None] = None,
             saveat: SaveAt | None = None, budget: Budget | None = None, model: str | Model | None = None,
) -> Trajectory:
    """Integrate the peeling model (FLOW1, FLOW2, flow3, CONSTR, or a variant) from t = 0 to t_end.

    Parameters
    ----------
    params : PeelParams
        Physical parameters, the ``cos θ`` closure (``geometry``), the law ``force`` (any
        :class:`peelapprox.PeelForce`: the paper's fvV, a family, an expression, a table, a smoothed law) and
        the variant fields (``tape_mass``, ``loading``), which pick the model (``exact.MODELS``) unless
        ``model`` is given.
    t_end : float
        Final time [s], in (0, TIME_MAX] = (0, 1e6].
    alpha0, omega0, F0, branch0 : optional
        Initial state (:func:`initial_state`: ``α = 0``, ``ω = V/R``, ``F = 1.01 f(V, V)``, v the lowest stable
        root of CONSTR); v is always the root of CONSTR on ``branch0``, so the start is consistent.
    Vp0 : float, optional
        Initial pull speed [m/s] under a load, in [0, 1e3]; default ``params.V``.  A ValueError under velocity
        control.
    method : {"hybrid", "regularized", "smooth"} or a method object, optional
        A name of ``exact.METHODS`` or an object (:class:`Hybrid`: the ε → 0 limit, event-driven, compiled DOP853
        with exact fold jumps; :class:`Regularized`: the paper's scheme, mass matrix ``diag(1, 1, 1, ε)``, on a
        scipy stiff solver; :class:`Smooth`: the tape-mass model's ODE on a scipy solver).  None: the model's
        default (hybrid for the paper's model, regularized for a massless tape under a load, smooth with a tape
        mass); a method the model cannot use is a ValueError saying which it can.  An object holds ``solver``,
        ``eps``, ``rtol``, ``atol`` and ``v_floor``: those keywords must then stay at their defaults.
    solver, eps, rtol, atol, v_floor
        The fields of the method of that name (documented there): the scipy solver, the regularisation ε, the
        error control per step (RMS over components of ``err_i / (atol_i + rtol |y_i|) <= 1``; ``atol=None``:
        ``rtol * ATOL_SCALE[method]``) and the caller's velocity floor (None: the model's no_root criterion).
        ``solver`` and ``eps`` given to a method without them are an error.
    t_transient, t_eval, save
        What is stored (:class:`SaveAt`'s ``t_transient``, ``ts`` and ``steps``/``jumps_only``): every step
        (``save="steps"``, with the states just before and after each jump), only the jumps (``"jumps"``) or the
        states at the times ``t_eval`` (within ``[t_transient, t_end]``); nothing before ``t_transient``.
    max_points, max_steps, max_jumps, max_wall
        The budgets (:class:`Budget`); needing more raises :class:`SolverBudgetExceeded` with the partial
        trajectory, nothing is truncated silently.  ``max_steps=None`` scales with the horizon
        (:func:`default_max_steps`).
    progress : bool or callable, optional
        ``True`` prints progress to stderr; a callable receives ``(t, t_end)`` between chunks of work.
    saveat, budget : SaveAt, Budget, optional
        The keywords they stand for as one object each, those keywords then left at their defaults.
    model : str or Model, optional
        The model to integrate (a name of ``exact.MODELS`` or a :class:`Model`); None: the one ``params``
        describe.

    Returns
    -------
    Trajectory
        Stored points, jumps, counters (``stats``), settings and the final state.

    Raises
    ------
    ValueError
        Bad arguments, naming the argument and its valid range.
    ModelBreakdown, SolverBudgetExceeded, SolverFailure
        The model breaks down along the orbit / a budget is used up / the integrator cannot proceed.
    """
    _params("params", params)
    mod = model_option(model, params)
    opts = method_option(method, solver=solver, eps=eps, rtol=rtol, atol=atol, v_floor=v_floor, params=params,
                         model=mod)
    t_end = duration("t_end", t_end)
    out, lim = output_options(opts, t_end, saveat, budget, save=save, t_eval=t_eval, t_transient=t_transient,
                              max_points=max_points, max_steps=max_steps, max_jumps=max_jumps, max_wall=max_wall)
    report = _progress_option(progress, f"simulate V={params.V} I={params.I}")
    start = dict(alpha0=alpha0, omega0=omega0, F0=F0, branch0=branch0, Vp0=Vp0)
    return _start_and_run(mod, opts, params, t_end, start, out, lim, report)


def _start_and_run(mod: Model, opts: Method, params: PeelParams, t_end: float, start: dict[str, Any], out: SaveAt,
                   lim: Budget, report: Callable[[float, float], None] | None) -> Trajectory:
    """``simulate``'s consistent start (``start``: its initial-state keywords) and the run of ``opts`` from it, both
    within ``max_wall``; a peel-force law whose compile outlasts it is :func:`_compile_expired`'s budget error."""
    st0 = None
    try:
        with caller_budget(lim.max_wall):  # an expression law compiled for this run is bounded by max_wall too
            st0 = mod.initial_state(params, **start)
            return opts.run(mod, params, t_end, st0, out, lim, report)
    except BuildExpired:
        raise _compile_expired(params, lim, st0) from None


def model_option(model: Any, params: PeelParams) -> Model:
    """The model of a ``simulate`` call: ``model`` itself, the ``exact.MODELS`` entry of that name, or (None) the
    model ``params`` describe; a model that does not accept ``params`` is a ValueError naming both."""
    if model is None:
        return model_of(params)
    if isinstance(model, str):
        model = MODELS[choice("model", model, tuple(MODELS))]
    if not isinstance(model, Model):
        raise ArgumentTypeError(f"model must be None, a name in exact.MODELS or an exact.Model, got "
                                f"{type(model).__name__}")
    if not model.accepts(params):
        raise ValueError(f"model={model.name!r} is {model.about}; params describe {model_of(params).about} "
                         f"({params!r:.200})")
    return model


def _progress_option(progress: Any, label: str) -> Callable[[float, float], None] | None:
    """``simulate``'s ``progress`` as a callable or None (``True``: :func:`_progress_printer`)."""
    if progress is True:
        return _progress_printer(label)
    if progress is False or progress is None:
        return None
    if not callable(progress):
        raise TypeError(f"progress must be None, a bool or a callable (t, t_end), got {type(progress).__name__}")
    return progress


def _compile_expired(params: PeelParams, lim: Budget, st0: State | None) -> SolverBudgetExceeded:
    """The budget error of a run whose peel-force law took more than ``max_wall`` to compile."""
    return SolverBudgetExceeded(f"more than {lim.max_wall:g} s of wall time (max_wall) compiling the peel-force "
                                f"law {params.force!r} before the run started; pass a larger max_wall, or None "
                                "(a law is compiled once per machine, then loaded from the cache)",
                                budget="max_wall", limit=float(lim.max_wall or 0.0), t=0.0 if st0 is None else st0.t,
                                state={"t": 0.0} if st0 is None else dataclasses.asdict(st0))
