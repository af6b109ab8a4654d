"""``exact.simulate``: check the arguments, build the consistent start, and hand the run to its method."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

from peelapprox import PeelParams
from peelapprox.errors import SolverBudgetExceeded
from peelapprox.io import ProgressLine
from peelapprox.kernels import BuildExpired, caller_budget
from peelapprox.validate import duration, in_range
from peelapprox.validate import params as _params

from ._initial import initial_state
from ._method_contract import Method, method_option
from ._options import Budget, SaveAt, output_options
from ._trajectory import Trajectory

__all__ = ["simulate", "VP0_MAX"]

#: Largest initial pull speed ``Vp0`` [m/s] under a load: the model's velocities stay below 1e3 m/s (STATE_RANGES).
VP0_MAX = 1e3


def _progress_printer(label: str) -> Callable[[float, float], None]:
    """``progress=True``: :class:`peelapprox.io.ProgressLine` in per mille of ``t_end`` (a line per 5 %)."""
    line: list[ProgressLine] = []

    def report(t: float, t_end: float) -> None:
        if not line:
            line.append(ProgressLine(label, 1000, count=False))
        line[0].update(min(1000, max(0, int(1000 * t / t_end))), f"t = {t:.6g} / {t_end:.6g} s")

    return report


def simulate(
    params: PeelParams,
    t_end: float,
    *,
    alpha0: float = 0.0,
    omega0: float | None = None,
    F0: float | None = None,
    branch0: str | None = None,
    Vp0: float | None = None,
    method: str | Method | None = None,
    solver: str | None = None,
    rtol: float = 1e-8,
    atol: None | float | Sequence[float] = None,
    eps: float | None = None,
    t_transient: float = 0.0,
    t_eval: Sequence[float] | None = None,
    save: str = "steps",
    max_points: int = 5_000_000,
    max_steps: int | None = None,
    max_jumps: int = 20_000_000,
    max_wall: float | None = None,
    v_floor: float | None = None,
    progress: None | bool | Callable[[float, float], None] = None,
    saveat: SaveAt | None = None,
    budget: Budget | None = None,
) -> Trajectory:
    """Integrate the peeling model (FLOW1, FLOW2, flow3, CONSTR) from t = 0 to t_end.

    Parameters
    ----------
    params : PeelParams
        Physical parameters, the ``cos θ`` closure (``geometry``) and the law ``force``: any
        :class:`peelapprox.PeelForce` (the paper's fvV, a family, an expression, a table, a smoothed law).
    t_end : float
        Final time [s], in (0, TIME_MAX] = (0, 1e6].
    alpha0, omega0, F0, branch0 : optional
        Initial state; defaults ``α = 0``, ``ω = V/R``, ``F = 1.01 f(V, V)``,
        ``branch0=None`` meaning the lowest-velocity stable root of CONSTR
        (see :func:`initial_state`).  v is always the root of CONSTR on
        ``branch0``, so the start is consistent.
    Vp0 : float, optional
        Initial pull speed [m/s] under a load (``params.loading == "load"``), in
        [0, 1e3]; default ``params.V``.  A ValueError under velocity control.
    method : {"hybrid", "regularized", "smooth"} or Hybrid or Regularized or Smooth, optional
        ``"hybrid"`` (the default for the paper's model): the ε → 0 limit,
        event-driven, compiled DOP853 on the desingularised branch dynamics
        with exact fold jumps (see :mod:`exact._hybrid`).  ``"regularized"``:
        the paper's scheme, mass matrix ``diag(1, 1, 1, ε)``, integrated by
        scipy's stiff ``solver`` (the default for a massless tape under a load,
        ``params.loading == "load"``).  ``"smooth"`` (the default, and the only
        method, for the tape-mass model ``params.tape_mass``): its ODE on a
        scipy ``solver`` (docs/tape-mass.md).  None: the model's default.
        A method the model cannot use is a ValueError saying which it can.
        A method object (:class:`Hybrid`, :class:`Regularized`, :class:`Smooth`: a class of the table of
        methods, ``exact._options.METHODS``, whose names ``method`` takes) holds
        ``solver``, ``eps``, ``rtol``, ``atol`` and ``v_floor`` itself: those
        keywords must then stay at their defaults (ValueError naming both).
    solver : {"Radau", "BDF", "LSODA"}, optional
        scipy solver for ``method="regularized"`` (analytic Jacobian);
        default "Radau".  ``method="smooth"`` also takes "DOP853" and "RK45";
        its default is "LSODA", the fastest at every tape mass measured
        (docs/tape-mass.md, "Which integrator").
        Passing it with the hybrid method is an error.
    rtol, atol : float, float or 4 floats
        Local error control per step: RMS over components of
        ``err_i / (atol_i + rtol |y_i|) <= 1``.  Hybrid components are
        ``(τ, α, ω, ln v)`` (τ = time since the last jump), regularised ones are
        ``(α, ω, F, v)``.  ``rtol`` in ``RTOL_RANGE`` = [1e-14, 1e-2];
        ``atol`` (each component) in ``ATOL_RANGE`` = [1e-100, 1];
        ``atol=None`` uses ``rtol * ATOL_SCALE[method]``.
    eps : float, optional
        Regularisation ε (``method="regularized"`` only; an error with the
        hybrid method), in ``EPS_RANGE`` = [1e-15, 1e-2], default 1e-7 as in
        the paper.
    t_transient : float
        Integrate from 0 but store nothing (points or jumps) before this time.
    t_eval : array_like, optional
        Store the state exactly at these times (sorted, within
        ``[t_transient, t_end]``) instead of at every step.
    save : {"steps", "jumps"}
        Without ``t_eval``: ``"steps"`` stores every accepted step plus the
        states just before and after each jump; ``"jumps"`` stores only jumps
        (memory proportional to the number of jumps, not of steps).
    max_points, max_steps, max_jumps : int
        Budgets: stored points, accepted steps (all, from t = 0) and stored
        jumps (those at t >= t_transient: a memory budget, like max_points).
        Needing more than one raises :class:`SolverBudgetExceeded` (with the
        partial trajectory); nothing is truncated silently.  ``max_steps=None``
        scales the step budget with the horizon (:func:`default_max_steps`:
        1e6 steps per simulated second within [1e6, 2e7] for the hybrid
        method, ~35 s of work at most; 1e5/s within [1e5, 5e5] for the
        regularised one, ~80 s; 1e6/s within [1e5, 5e6] for the tape-mass
        model, ~60 s of its default LSODA).
    max_wall : float, optional
        Wall-clock budget [s] of the integration (checked between hybrid
        kernel calls, at most 250,000 steps (~0.4 s) apart, and at every step
        of the regularised scheme);
        exceeding it raises :class:`SolverBudgetExceeded` with
        ``budget="max_wall"``.  None (default): bounded by ``max_steps`` only.
    v_floor : float, optional
        None (default): the model's criterion.  On AB the level
        ``G = F(1 - cos θ)`` falling to ``f(0+, V)`` leaves CONSTR without a
        root (the peel front would have to stop): :class:`ModelBreakdown`
        with ``reason="no_root"`` once ``G - f(0+) <= 1e-10 max(|f(0+)|, 1 N)``,
        i.e. v below ``BranchStructure.v_breakdown`` (~1e-67 m/s; the hybrid
        method integrates ln v, so it follows v that far).  A number [m/s]:
        stop earlier, at that velocity, with ``reason="v_floor"`` (a
        threshold of the user's, not of the model).
    progress : bool or callable, optional
        ``True`` prints progress to stderr; a callable receives ``(t, t_end)``
        between chunks of work.
    saveat : SaveAt, optional
        ``save``, ``t_eval`` and ``t_transient`` as one object; those
        keywords must then stay at their defaults (a keyword at its default
        value counts as not given; otherwise ValueError naming both).
    budget : Budget, optional
        ``max_points``, ``max_steps``, ``max_jumps`` and ``max_wall`` as one
        object, on the same rule.

    Returns
    -------
    Trajectory
        Stored points, jumps, counters (``stats``), settings and the final
        state.

    Raises
    ------
    ValueError
        Bad arguments, naming the argument and its valid range.
    ModelBreakdown
        The model breaks down along the orbit (see the exception).
    SolverBudgetExceeded, SolverFailure
        Budget used up / the integrator cannot proceed.
    """
    _params("params", params)
    opts = method_option(method, solver=solver, eps=eps, rtol=rtol, atol=atol, v_floor=v_floor, params=params)
    t_end = duration("t_end", t_end)
    out, lim = output_options(opts, t_end, saveat, budget, save=save, t_eval=t_eval, t_transient=t_transient,
                              max_points=max_points, max_steps=max_steps, max_jumps=max_jumps, max_wall=max_wall)
    if progress is True:
        progress = _progress_printer(f"simulate V={params.V} I={params.I}")
    elif progress is False:
        progress = None
    elif progress is not None and not callable(progress):
        raise TypeError(f"progress must be None, a bool or a callable (t, t_end), got {type(progress).__name__}")

    st0 = None
    try:
        with caller_budget(lim.max_wall):  # an expression law compiled for this run is bounded by max_wall too
            st0 = initial_state(params, alpha0=alpha0, omega0=omega0, F0=F0, branch0=branch0)
            if Vp0 is not None:
                if params.loading != "load":
                    raise ValueError(f"Vp0 (the initial pull speed) applies only under loading='load'; got Vp0={Vp0!r} "
                                     "with loading='velocity' (the pull speed is params.V)")
                st0 = dataclasses.replace(st0, Vp=in_range("Vp0", Vp0, 0.0, VP0_MAX))
            return opts.run(params, t_end, st0, out, lim, progress)
    except BuildExpired:
        raise SolverBudgetExceeded(f"more than {lim.max_wall:g} s of wall time (max_wall) compiling the peel-force "
                                   f"law {params.force!r} before the run started; pass a larger max_wall, or None "
                                   "(a law is compiled once per machine, then loaded from the cache)",
                                   budget="max_wall", limit=float(lim.max_wall or 0.0), t=0.0 if st0 is None else st0.t,
                                   state={"t": 0.0} if st0 is None else dataclasses.asdict(st0)) from None

