"""The paper's ε-regularised scheme (Sec. III, XDAE) on scipy's stiff solvers.

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
from peelapprox.kernels import ALL_LAWS, bound_variant_field, compiled_law, regularized_law_field, variant_parameters
from peelapprox.kernels import regularized_field as _fun  # the compiled field, Jacobian and parameter vector
from peelapprox.kernels import regularized_field_jacobian as _jac
from peelapprox.kernels import regularized_parameters as param_vector

from ._trajectory import Jumps, SolverStats, State, Trajectory

if TYPE_CHECKING:
    from peelapprox import PeelParams

    from ._method_contract import Method
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


def run_regularized(params: PeelParams, t_end: float, s0: State, method: Method, saveat: SaveAt,
                    budget: Budget, progress: Callable[[float, float], None] | None) -> Trajectory:
    """Driver for ``simulate(method="regularized")`` and, for the model variants (``params.variant``: the tape
    mass, the constant load), ``method="smooth"``: the options validated, the budget resolved."""
    solver, rtol, atol, v_floor = cast(str, method.solver), method.rtol, method.atol_vector(), method.v_floor
    eps = method.eps  # the regularised scheme's; None for the variants' smooth ODE
    t_store, te, max_wall = saveat.t_transient, saveat.ts, budget.max_wall
    max_points, max_jumps, max_steps = budget.max_points, budget.max_jumps, int(cast(int, budget.max_steps))
    cl = compiled_law(params.force, params.V)  # the paper's law: fvV inlined in the field (the default)
    bs, (v_lo, v_hi) = cl.structure, cl.domain
    no_root_margin = BREAKDOWN_LEVEL * max(abs(bs.f_zero), 1.0)  # the hybrid solver's criterion (v_breakdown)
    variant = params.variant
    massive = params.tape_mass is not None  # the tape-mass model: v <= 0 is the front's arrest, not a failure
    n_y = 4 if variant in (None, "tape") else 5  # (α, ω, F, v[, V_p])
    v_mid = bs.v_inflection
    if variant is not None:
        vfun, vjac = bound_variant_field(variant, cl.fn)  # the law bound in: ~1 us a call, not ~65 us
        q = variant_parameters(params, eps if eps is not None else cast(float, params.tape_mass),
                               params.load_mass or 1.0, params.load or 0.0)
        coef = cl.coef
        fun = lambda t, y: vfun(y, q, coef)  # noqa: E731
        jac = lambda t, y: vjac(y, q, coef)  # noqa: E731
        if n_y == 5:
            atol = np.append(atol, atol[3])  # V_p [m/s] on the scale of v
    elif cl.inlined:
        q = param_vector(params, cast(float, eps), ("paper",))
        fun = lambda t, y: _fun(y, q)  # noqa: E731
        jac = lambda t, y: _jac(y, q)  # noqa: E731
    else:
        q = param_vector(params, cast(float, eps), ALL_LAWS)
        lfun, ljac = regularized_law_field()
        law, coef = cl.fn, cl.coef
        fun = lambda t, y: lfun(y, q, law, coef)  # noqa: E731
        jac = lambda t, y: ljac(y, q, law, coef)  # noqa: E731
    y0 = np.array([s0.alpha, s0.omega, s0.F, s0.v] + ([params.V if s0.Vp is None else s0.Vp] if n_y == 5 else []))
    wall0 = time.perf_counter()
    kw: dict[str, Any] = {"jac": jac} if solver in _SOLVERS else {}
    ode = {**_SOLVERS, **_EXPLICIT}[solver](fun, s0.t, y0, t_end, rtol=rtol, atol=atol, **kw)

    def fast_first_step() -> float | None:
        """The first step on the fast time scale, 1/|dv'/dv| at the start, for a retry: scipy's own first step
        (from the field's size, not its stiffness) can fail at once for a light tape (m ~ 1e-15 kg: a time
        scale m (1 + sin a)^2 / f' ~ 1e-17 s) or a small eps (docs/tape-mass.md, "The smallest masses")."""
        rate = abs(float(np.asarray(jac(s0.t, y0))[3, 3]))
        return min(1.0 / rate, t_end - s0.t) if math.isfinite(rate) and rate > 0.0 else None

    label = f"{method.name} {solver}"

    rows: list[tuple] = []
    brs: list[int] = []
    jumps: list[tuple] = []
    t_eval_i = 0

    def side(v):
        return 0 if v <= v_mid else 1

    def store(t, y):
        if len(rows) >= max_points:
            raise budget_exceeded("max_points", max_points, t_end, sdict(t, y), build(False))
        rows.append((t, *y))
        brs.append(side(y[3]))

    def decelerates(y):
        """Whether the front, put at rest (v = V_ARREST) in state y, still decelerates: the arrest is physical."""
        z = np.array(y, dtype=float)
        z[3] = V_ARREST
        return bool(fun(0.0, z)[3] <= 0.0)

    def level_gap(y):
        """How far the level F (1 - cos θ) of state y lies above f(0+, V) [N] (the no_root criterion's measure)."""
        return y[2] * (1.0 + float(params.closure(y[0])[0])) - bs.f_zero

    def sdict(t, y):
        d = dict(t=float(t), alpha=float(y[0]), omega=float(y[1]), F=float(y[2]), v=float(y[3]),
                 branch=BRANCHES[side(y[3])])
        return d if n_y == 4 else {**d, "Vp": float(y[4])}

    def build(final=True, last=None):
        """The trajectory so far; ``last = (t, y)``: the final state to report (default the solver's)."""
        t_last, y_last = last if last is not None else (ode.t, ode.y)
        arr = np.array(rows, dtype=float).reshape(-1, 1 + n_y)
        njac = getattr(ode, "njev", 0)
        nlu = getattr(ode, "nlu", 0)
        stats = SolverStats(n_steps=n_steps, n_rejected=None, n_rhs=int(ode.nfev), n_jumps=n_jumps,
                            wall_time=time.perf_counter() - wall0, n_jac=int(njac), n_lu=int(nlu))
        return Trajectory(
            t=arr[:, 0], alpha=arr[:, 1], omega=arr[:, 2], F=arr[:, 3], v=arr[:, 4], branch=np.array(brs, np.int8),
            Vp=arr[:, 5] if n_y == 5 else None,
            jumps=Jumps.from_buffer(np.array(jumps, dtype=float).reshape(-1, 8)), stats=stats, params=params,
            method=method.name, solver=solver, rtol=rtol, atol=atol, eps=eps, initial_state=s0,
            final_state=State(**sdict(t_last, y_last)), t_end=t_end, t_transient=t_store, status=0 if final else 1,
            message="reached t_end" if final else "stopped early")

    n_steps = 0
    n_jumps = 0
    if saveat.steps and s0.t >= t_store:
        store(s0.t, y0)
    last_report = time.perf_counter()
    while ode.status == "running":
        t_old, y_old = ode.t, ode.y.copy()
        first_try = n_steps == 0 and "first_step" not in kw
        with np.errstate(invalid="ignore", over="ignore"):  # explicit trial steps may overflow: rejected by scipy
            if first_try:  # its warnings wait: a failed first try is retried below, and is not the run
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")  # recorded, not acted on: the filters act when re-issued below
                    msg = ode.step()
            else:
                msg = ode.step()
        if first_try:
            if ode.status == "failed":
                kw["first_step"] = fast_first_step()  # once more from the start, on the fast time scale
                if kw["first_step"] is not None:
                    ode = {**_SOLVERS, **_EXPLICIT}[solver](fun, s0.t, y0, t_end, rtol=rtol, atol=atol, **kw)
                    continue
            for w in caught:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if ode.status == "failed":
            hint = ("; at so small a tape mass the model is the massless one to ~m^(2/3) (docs/tape-mass.md): use "
                    "tape_mass=None" if massive and cast(float, params.tape_mass) < 1e-9 else "")
            raise SolverFailure(f"{label} failed after t={t_old:.9g} (v = {y_old[3]:.3g} m/s, "
                                f"F(1 - cos theta) - f(0+, V) = {level_gap(y_old):.3g} N): {msg}{hint}", t=float(t_old),
                                state=sdict(t_old, y_old), partial=build(False, (t_old, y_old)))
        n_steps += 1
        y = ode.y
        if not np.all(np.isfinite(y)):  # a numerical failure, reported at the last finite state
            raise SolverFailure(f"{label}: the state became non-finite after t={t_old:.9g}",
                                t=float(t_old), state=sdict(t_old, y_old), partial=build(False, (t_old, y_old)))
        if variant is not None and not y[3] > V_ARREST:  # a variant's front at (or through) rest
            at_t, at_y = (ode.t, y) if y[3] > 0.0 else (t_old, y_old)
            if not decelerates(at_y):  # at v = V_ARREST the field would turn v back up: the step overshot
                raise SolverFailure(
                    f"{label}: v = {y[3]:.3g} m/s after t={t_old:.9g}, but at rest the front would accelerate "
                    f"again (F(1 - cos theta) - f(0+, V) = {level_gap(y_old):.3g} N there): a numerical "
                    "overshoot, not an arrest; tighten rtol", t=float(t_old), state=sdict(t_old, y_old),
                    partial=build(False, (t_old, y_old)))
            raise ModelBreakdown(
                f"model breakdown at t={at_t:.9g}: the peel velocity v fell to {max(y[3], 0.0):.3g} m/s and the "
                f"front still decelerates at v = {V_ARREST:g} m/s (F(1 - cos theta) - f(0+, V) = "
                f"{level_gap(at_y):.3g} N): the peel front stops, and the model (a front that only advances, f "
                "defined for v > 0) ends there", t=float(at_t), state=sdict(at_t, at_y), reason="arrest",
                partial=build(False, (at_t, at_y)) if y[3] <= 0.0 else build(False))
        if not y[2] > 0.0:  # the tape went slack: F = k u > 0 is the tape's tension
            raise ModelBreakdown(
                f"model breakdown at t={t_old:.9g}: the pull force F fell to {y[2]:.3g} N <= 0: the tape goes "
                "slack, outside the model (a taut tape)", t=float(t_old), state=sdict(t_old, y_old),
                reason="slack", partial=build(False, (t_old, y_old)))
        if not y[3] > 0.0:  # the scheme left the model's domain (f is defined for v > 0): numerical, not physical
            raise SolverFailure(f"{label}: v = {y[3]:.3g} <= 0 after t={t_old:.9g}: the regularised "
                                "scheme left the model's domain (F(1 - cos theta) - f(0+, V) = "
                                f"{level_gap(y_old):.3g} N there; near 0 the orbit is approaching the no_root "
                                "breakdown, else tighten rtol)",
                                t=float(t_old), state=sdict(t_old, y_old), partial=build(False, (t_old, y_old)))
        if not v_lo <= y[3] <= v_hi:
            raise ModelBreakdown(
                f"model breakdown at t={ode.t:.9g}: v = {y[3]:.6g} m/s left the domain [{v_lo:.6g}, {v_hi:.6g}] m/s "
                f"of the peel-force law {params.force!r}: the law is not extrapolated (extend the table or the "
                "law's range)", t=float(ode.t), state=sdict(ode.t, y), reason="law_domain", partial=build(False))
        if v_floor is not None and y[3] <= v_floor:
            raise ModelBreakdown(
                f"model breakdown at t={ode.t:.9g}: v fell to {y[3]:.3g} <= v_floor={v_floor} m/s "
                f"(F(1 - cos theta) -> f(0+, V)={bs.f_zero:.6g} N)",
                t=float(ode.t), state=sdict(ode.t, y), reason="v_floor", partial=build(False))
        if not massive and side(y[3]) == 0 and level_gap(y) <= no_root_margin:
            raise ModelBreakdown(
                f"model breakdown at t={ode.t:.9g}: F(1 - cos theta) fell to f(0+, V)={bs.f_zero:.6g} N on AB "
                f"(within {BREAKDOWN_LEVEL:g}): CONSTR has no root left, the peel front would have to stop",
                t=float(ode.t), state=sdict(ode.t, y), reason="no_root", partial=build(False))
        dense = None
        s_old, s_new = side(y_old[3]), side(y[3])
        if s_old != s_new:
            dense = ode.dense_output()
            cross = lambda tt: dense(tt)[3] - v_mid  # noqa: E731
            if cross(t_old) * cross(ode.t) <= 0.0:
                tj = brentq(cross, t_old, ode.t, xtol=1e-15, rtol=8.9e-16)
            else:  # the step's ends straddle v_mid but its interpolant does not (seen with LSODA at tape masses
                # of 1e-12 kg and below): the crossing of the chord, within the step as the jump is
                tj = t_old + (ode.t - t_old) * (v_mid - y_old[3]) / (y[3] - y_old[3])
            yj = dense(tj)
            n_jumps += 1
            if tj >= t_store:
                jumps.append((tj, s_old, s_new, yj[0], yj[1], yj[2], v_mid, v_mid))
            if len(jumps) > max_jumps:  # stored jumps, as the hybrid driver counts them
                raise budget_exceeded("max_jumps", max_jumps, t_end, sdict(tj, yj), build(False))
        if te is not None:
            while t_eval_i < te.size and te[t_eval_i] <= ode.t:
                dense = dense or ode.dense_output()
                ye = dense(te[t_eval_i])
                if not (np.all(np.isfinite(ye)) and ye[3] > 0.0):  # the interpolant left the domain
                    raise SolverFailure(f"{label}: the dense output at t={te[t_eval_i]:.9g} left the "
                                        "model's domain (v <= 0 or non-finite); tighten rtol", t=float(t_old),
                                        state=sdict(t_old, y_old), partial=build(False, (t_old, y_old)))
                store(te[t_eval_i], ye)
                t_eval_i += 1
        elif saveat.steps and ode.t >= t_store:
            store(ode.t, y)
        if n_steps >= max_steps and ode.status == "running":
            raise budget_exceeded("max_steps", max_steps, t_end, sdict(ode.t, y), build(False))
        if max_wall is not None and time.perf_counter() - wall0 > max_wall and ode.status == "running":
            raise budget_exceeded("max_wall", max_wall, t_end, sdict(ode.t, y), build(False))
        if progress and time.perf_counter() - last_report > 0.5:
            last_report = time.perf_counter()
            progress(float(ode.t), t_end)
    if progress:
        progress(t_end, t_end)
    if ode.t != t_end:
        raise SolverFailure(f"{label} stopped at t={ode.t} before t_end={t_end}", t=float(ode.t),
                            state=sdict(ode.t, ode.y), partial=build(False))
    return build()
