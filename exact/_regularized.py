"""The scipy driver of a model's smooth field: the paper's ε-regularised scheme (Sec. III, XDAE) on scipy's stiff
solvers, and the model variants' smooth ODE (:class:`exact.Smooth`).

``M Ẋ = φ(X)``, ``X = (α, ω, F, v)``, ``M = diag(1, 1, 1, ε)``: the singular
mass matrix of the DAE is perturbed by ε (the paper used ε = 1e-7 and MATLAB's
ode15s).  With ε > 0 M is invertible, so we integrate the equivalent ODE
``v̇ = [F(1 - cos θ) - f(v, V)] / ε`` with scipy's Radau, BDF or LSODA and the
analytic Jacobian generated from the symbolic model.

A *jump* of the regularised orbit is recorded when v crosses the inflection
velocity ``v_infl`` of f (the minimiser of f', inside the unstable part): the
time of the crossing is located on the solver's dense output.  Its
``v_before`` and ``v_after`` both hold ``v_infl``; (α, ω, F) are the crossing
values.  ``branch`` at stored points is 0 where ``v <= v_infl`` and 1 above.
As ε → 0 these jump times converge to the hybrid ones with the fold-passage
delay ~ ε^(2/3) (see docs/theory.md).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from scipy import integrate
from scipy.optimize import brentq

from peelapprox import BRANCHES, BREAKDOWN_LEVEL
from peelapprox.errors import ModelBreakdown, SolverFailure, budget_exceeded
from peelapprox.kernels import regularized_field as _fun  # the compiled field, Jacobian and parameter vector
from peelapprox.kernels import regularized_field_jacobian as _jac
from peelapprox.kernels import regularized_parameters as param_vector

from ._trajectory import Jumps, SolverStats, State, Trajectory

if TYPE_CHECKING:
    from peelapprox import PeelParams

    from ._method_contract import Method
    from ._model import Model
    from ._options import Budget, SaveAt

_SOLVERS = {"Radau": integrate.Radau, "BDF": integrate.BDF, "LSODA": integrate.LSODA}
#: Explicit solvers (no Jacobian), offered for the tape-mass model at large masses (not stiff there).
_EXPLICIT = {"DOP853": integrate.DOP853, "RK45": integrate.RK45}


#: A model variant's front slower than this [m/s] (1 nm in 17 min) has stopped: ModelBreakdown("arrest") if the
#: field, with v put at this value, still decelerates it (else the step overshot: SolverFailure, tighten rtol).
#: Under a load below the peel force's floor, or with a heavy tape, v decays towards 0, where f' -> inf stiffens
#: the system until the step size underflows (measured: v ~ 1e-17 m/s); for the massless tape the test is
#: F(1 - cos θ) < f(V_ARREST) ≈ f(0+) + 1.8 N (fvV at V = 1).
V_ARREST = 1e-12

__all__ = ["V_ARREST", "run_regularized", "_fun", "_jac", "param_vector"]


class _ScipyRun:
    """One run of a model's smooth field on a scipy solver: its settings, its stored rows and jumps, the solver
    (``ode``), and the checks of the model's events after every accepted step (:data:`exact._model.EVENTS`)."""

    def __init__(self, model: Model, params: PeelParams, t_end: float, s0: State, method: Method, saveat: SaveAt,
                 budget: Budget):
        self.model, self.params, self.t_end, self.s0 = model, params, t_end, s0
        self.method, self.saveat = method, saveat
        self.solver, self.rtol, self.v_floor = cast(str, method.solver), method.rtol, method.v_floor
        self.eps = method.eps  # the regularised scheme's; None for the smooth ODE
        self.max_points, self.max_jumps, self.max_wall = budget.max_points, budget.max_jumps, budget.max_wall
        self.max_steps = int(cast(int, budget.max_steps))
        cl = model.law(params)  # the paper's law: fvV inlined in the field (the default)
        self.bs, (self.v_lo, self.v_hi) = cl.structure, cl.domain
        self.no_root_margin = BREAKDOWN_LEVEL * max(abs(self.bs.f_zero), 1.0)  # the hybrid's (v_breakdown)
        self.v_mid = self.bs.v_inflection
        self.fun, self.jac = model.field(params, cl, self.eps)
        self.atol = model.atol(method.atol_vector())
        self.y0 = model.y0(params, s0)
        self.wall0 = time.perf_counter()
        self.kw: dict[str, Any] = {"jac": self.jac} if self.solver in _SOLVERS else {}
        self.ode = self.new_solver()
        self.label = f"{method.name} {self.solver}"
        self.rows: list[tuple] = []
        self.brs: list[int] = []
        self.jumps: list[tuple] = []
        self.t_eval_i = self.n_steps = self.n_jumps = 0
        self.dense: Any = None  # the dense output of the current step, once asked for

    def new_solver(self) -> Any:
        return {**_SOLVERS, **_EXPLICIT}[self.solver](self.fun, self.s0.t, self.y0, self.t_end, rtol=self.rtol,
                                                      atol=self.atol, **self.kw)

    def fast_first_step(self) -> float | None:
        """The first step on the fast time scale, 1/|dv'/dv| at the start, for a retry: scipy's own first step
        (from the field's size, not its stiffness) can fail at once for a light tape (m ~ 1e-15 kg: a time
        scale m (1 + sin a)^2 / f' ~ 1e-17 s) or a small eps (docs/tape-mass.md, "The smallest masses")."""
        rate = abs(float(np.asarray(self.jac(self.s0.t, self.y0))[3, 3]))
        return min(1.0 / rate, self.t_end - self.s0.t) if math.isfinite(rate) and rate > 0.0 else None

    def side(self, v: float) -> int:
        return 0 if v <= self.v_mid else 1

    def store(self, t: float, y: np.ndarray) -> None:
        if len(self.rows) >= self.max_points:
            raise budget_exceeded("max_points", self.max_points, self.t_end, self.sdict(t, y), self.build(False))
        self.rows.append((t, *y))
        self.brs.append(self.side(y[3]))

    def decelerates(self, y: np.ndarray) -> bool:
        """Whether the front, put at rest (v = V_ARREST) in state y, still decelerates: the arrest is physical."""
        z = np.array(y, dtype=float)
        z[3] = V_ARREST
        return bool(self.fun(0.0, z)[3] <= 0.0)

    def level_gap(self, y: np.ndarray) -> float:
        """How far the level F (1 - cos θ) of state y lies above f(0+, V) [N] (the no_root criterion's measure)."""
        return y[2] * (1.0 + float(self.params.closure(y[0])[0])) - self.bs.f_zero

    def sdict(self, t: float, y: np.ndarray) -> dict:
        d = dict(t=float(t), alpha=float(y[0]), omega=float(y[1]), F=float(y[2]), v=float(y[3]),
                 branch=BRANCHES[self.side(y[3])])
        return d if self.model.n_states == 4 else {**d, "Vp": float(y[4])}

    def build(self, final: bool = True, last: tuple | None = None) -> Trajectory:
        """The trajectory so far; ``last = (t, y)``: the final state to report (default the solver's)."""
        ode, n_y = self.ode, self.model.n_states
        t_last, y_last = last if last is not None else (ode.t, ode.y)
        arr = np.array(self.rows, dtype=float).reshape(-1, 1 + n_y)
        stats = SolverStats(n_steps=self.n_steps, n_rejected=None, n_rhs=int(ode.nfev), n_jumps=self.n_jumps,
                            wall_time=time.perf_counter() - self.wall0, n_jac=int(getattr(ode, "njev", 0)),
                            n_lu=int(getattr(ode, "nlu", 0)))
        return Trajectory(
            t=arr[:, 0], alpha=arr[:, 1], omega=arr[:, 2], F=arr[:, 3], v=arr[:, 4],
            branch=np.array(self.brs, np.int8), Vp=arr[:, 5] if n_y == 5 else None,
            jumps=Jumps.from_buffer(np.array(self.jumps, dtype=float).reshape(-1, 8)), stats=stats, params=self.params,
            method=self.method.name, solver=self.solver, rtol=self.rtol, atol=self.atol, eps=self.eps,
            initial_state=self.s0, final_state=State(**self.sdict(t_last, y_last)), t_end=self.t_end,
            t_transient=self.saveat.t_transient, status=0 if final else 1,
            message="reached t_end" if final else "stopped early")

    def failure(self, text: str, t_old: float, y_old: np.ndarray) -> SolverFailure:
        """A SolverFailure at the last accepted state (t_old, y_old)."""
        return SolverFailure(text, t=float(t_old), state=self.sdict(t_old, y_old),
                             partial=self.build(False, (t_old, y_old)))

    def breakdown(self, text: str, t: float, y: np.ndarray, reason: str, last: tuple | None = None) -> ModelBreakdown:
        return ModelBreakdown(text, t=float(t), state=self.sdict(t, y), reason=reason, partial=self.build(False, last))

    def step(self) -> str | None:
        """One step of the solver (a failed first try retried once on the fast time scale); the solver's message."""
        first_try = self.n_steps == 0 and "first_step" not in self.kw
        with np.errstate(invalid="ignore", over="ignore"):  # explicit trial steps may overflow: rejected by scipy
            if not first_try:
                return self.ode.step()
            with warnings.catch_warnings(record=True) as caught:  # its warnings wait: a failed first try is retried
                warnings.simplefilter("always")  # recorded, not acted on: the filters act when re-issued below
                msg = self.ode.step()
        if self.ode.status == "failed":
            self.kw["first_step"] = self.fast_first_step()  # once more from the start, on the fast time scale
            if self.kw["first_step"] is not None:
                self.ode = self.new_solver()
                return self.step()
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return msg

    # ---- the events of the model (exact._model.EVENTS), each after an accepted step from (t_old, y_old) to ode.t
    def ev_arrest(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        """The front at (or through) rest: a physical arrest if it still decelerates there, else an overshoot."""
        if y[3] > V_ARREST:
            return
        at_t, at_y = (self.ode.t, y) if y[3] > 0.0 else (t_old, y_old)
        if not self.decelerates(at_y):  # at v = V_ARREST the field would turn v back up: the step overshot
            raise self.failure(
                f"{self.label}: v = {y[3]:.3g} m/s after t={t_old:.9g}, but at rest the front would accelerate "
                f"again (F(1 - cos theta) - f(0+, V) = {self.level_gap(y_old):.3g} N there): a numerical "
                "overshoot, not an arrest; tighten rtol", t_old, y_old)
        raise self.breakdown(
            f"model breakdown at t={at_t:.9g}: the peel velocity v fell to {max(y[3], 0.0):.3g} m/s and the "
            f"front still decelerates at v = {V_ARREST:g} m/s (F(1 - cos theta) - f(0+, V) = "
            f"{self.level_gap(at_y):.3g} N): the peel front stops, and the model (a front that only advances, f "
            "defined for v > 0) ends there", at_t, at_y, "arrest", (at_t, at_y) if y[3] <= 0.0 else None)

    def ev_slack(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        if not y[2] > 0.0:  # the tape went slack: F = k u > 0 is the tape's tension
            raise self.breakdown(
                f"model breakdown at t={t_old:.9g}: the pull force F fell to {y[2]:.3g} N <= 0: the tape goes "
                "slack, outside the model (a taut tape)", t_old, y_old, "slack", (t_old, y_old))

    def ev_v_positive(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        if not y[3] > 0.0:  # the scheme left the model's domain (f is defined for v > 0): numerical, not physical
            raise self.failure(f"{self.label}: v = {y[3]:.3g} <= 0 after t={t_old:.9g}: the regularised "
                               "scheme left the model's domain (F(1 - cos theta) - f(0+, V) = "
                               f"{self.level_gap(y_old):.3g} N there; near 0 the orbit is approaching the no_root "
                               "breakdown, else tighten rtol)", t_old, y_old)

    def ev_law_domain(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        if not self.v_lo <= y[3] <= self.v_hi:
            raise self.breakdown(
                f"model breakdown at t={self.ode.t:.9g}: v = {y[3]:.6g} m/s left the domain [{self.v_lo:.6g}, "
                f"{self.v_hi:.6g}] m/s of the peel-force law {self.params.force!r}: the law is not extrapolated "
                "(extend the table or the law's range)", self.ode.t, y, "law_domain")

    def ev_v_floor(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        if self.v_floor is not None and y[3] <= self.v_floor:
            raise self.breakdown(
                f"model breakdown at t={self.ode.t:.9g}: v fell to {y[3]:.3g} <= v_floor={self.v_floor} m/s "
                f"(F(1 - cos theta) -> f(0+, V)={self.bs.f_zero:.6g} N)", self.ode.t, y, "v_floor")

    def ev_no_root(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        if self.side(y[3]) == 0 and self.level_gap(y) <= self.no_root_margin:
            raise self.breakdown(
                f"model breakdown at t={self.ode.t:.9g}: F(1 - cos theta) fell to f(0+, V)={self.bs.f_zero:.6g} N "
                f"on AB (within {BREAKDOWN_LEVEL:g}): CONSTR has no root left, the peel front would have to stop",
                self.ode.t, y, "no_root")

    def ev_jump(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        """A crossing of v_mid within the step: a jump, located on the dense output (kept in ``self.dense``)."""
        ode, v_mid = self.ode, self.v_mid
        s_old, s_new = self.side(y_old[3]), self.side(y[3])
        if s_old == s_new:
            return
        dense = self.dense = ode.dense_output()
        cross = lambda tt: dense(tt)[3] - v_mid  # noqa: E731
        if cross(t_old) * cross(ode.t) <= 0.0:
            tj = brentq(cross, t_old, ode.t, xtol=1e-15, rtol=8.9e-16)
        else:  # the step's ends straddle v_mid but its interpolant does not (seen with LSODA at tape masses
            # of 1e-12 kg and below): the crossing of the chord, within the step as the jump is
            tj = t_old + (ode.t - t_old) * (v_mid - y_old[3]) / (y[3] - y_old[3])
        yj = dense(tj)
        self.n_jumps += 1
        if tj >= self.saveat.t_transient:
            self.jumps.append((tj, s_old, s_new, yj[0], yj[1], yj[2], v_mid, v_mid))
        if len(self.jumps) > self.max_jumps:  # stored jumps, as the hybrid driver counts them
            raise budget_exceeded("max_jumps", self.max_jumps, self.t_end, self.sdict(tj, yj), self.build(False))

    def output(self, t_old: float, y_old: np.ndarray, y: np.ndarray) -> None:
        """Store what the step brings: the states at the times of ``saveat.ts`` it passed, or its end."""
        te, ode = self.saveat.ts, self.ode
        if te is not None:
            while self.t_eval_i < te.size and te[self.t_eval_i] <= ode.t:
                self.dense = self.dense or ode.dense_output()
                ye = self.dense(te[self.t_eval_i])
                if not (np.all(np.isfinite(ye)) and ye[3] > 0.0):  # the interpolant left the domain
                    raise self.failure(f"{self.label}: the dense output at t={te[self.t_eval_i]:.9g} left the "
                                       "model's domain (v <= 0 or non-finite); tighten rtol", t_old, y_old)
                self.store(te[self.t_eval_i], ye)
                self.t_eval_i += 1
        elif self.saveat.steps and ode.t >= self.saveat.t_transient:
            self.store(ode.t, y)

    def check_budgets(self, y: np.ndarray) -> None:
        ode = self.ode
        if self.n_steps >= self.max_steps and ode.status == "running":
            raise budget_exceeded("max_steps", self.max_steps, self.t_end, self.sdict(ode.t, y), self.build(False))
        if self.max_wall is not None and time.perf_counter() - self.wall0 > self.max_wall and ode.status == "running":
            raise budget_exceeded("max_wall", self.max_wall, self.t_end, self.sdict(ode.t, y), self.build(False))


def run_regularized(model: Model, params: PeelParams, t_end: float, s0: State, method: Method, saveat: SaveAt,
                    budget: Budget, progress: Callable[[float, float], None] | None) -> Trajectory:
    """Integrate ``model``'s smooth field (:meth:`exact.Model.field`: the paper's XDAE with the method's ε for
    ``method="regularized"``, a variant's ODE for ``method="smooth"``) on the method's scipy solver from the
    consistent start ``s0``, checking the model's events after every accepted step (the options validated, the
    budget resolved); a stop raises its documented exception with the partial trajectory."""
    run = _ScipyRun(model, params, t_end, s0, method, saveat, budget)
    events = [getattr(run, "ev_" + name) for name in model.events]
    if saveat.steps and s0.t >= saveat.t_transient:
        run.store(s0.t, run.y0)
    last_report = time.perf_counter()
    while run.ode.status == "running":
        t_old, y_old = run.ode.t, run.ode.y.copy()
        msg = run.step()
        if run.ode.status == "failed":
            raise run.failure(f"{run.label} failed after t={t_old:.9g} (v = {y_old[3]:.3g} m/s, F(1 - cos theta) - "
                              f"f(0+, V) = {run.level_gap(y_old):.3g} N): {msg}{model.failure_hint(params)}",
                              t_old, y_old)
        run.n_steps += 1
        y = run.ode.y
        if not np.all(np.isfinite(y)):  # a numerical failure, reported at the last finite state
            raise run.failure(f"{run.label}: the state became non-finite after t={t_old:.9g}", t_old, y_old)
        run.dense = None
        for event in events:
            event(t_old, y_old, y)
        run.output(t_old, y_old, y)
        run.check_budgets(y)
        if progress and time.perf_counter() - last_report > 0.5:
            last_report = time.perf_counter()
            progress(float(run.ode.t), t_end)
    if progress:
        progress(t_end, t_end)
    if run.ode.t != t_end:
        raise SolverFailure(f"{run.label} stopped at t={run.ode.t} before t_end={t_end}", t=float(run.ode.t),
                            state=run.sdict(run.ode.t, run.ode.y), partial=run.build(False))
    return run.build()
