"""The coexisting attractors of one parameter point, reached from a designed set of starts: :func:`attractor_set`.

Each start runs ``t_transient`` seconds (discarded) and ``t_window`` seconds (its jumps kept), the windowed run of
:func:`exact.attractor_observables`, serially, on a thread pool or on any :class:`concurrent.futures.Executor`
(:mod:`exact.dynamics._attractor_set_runs`).  The windows are then read in the order of the starts, so the result
does not depend on where or in which order they ran:

1. A window without jumps is steady peeling; a ``ModelBreakdown`` is a breakdown entry (per reason).
2. A window whose return map repeats with period n to ``period_rtol``, or nearly, to :data:`NEAR_RTOL`, is looked at
   as a period-n orbit: Newton on the section map (:func:`exact.solve_orbit`, seeded at the window's nearest
   recurrence) closes it and gives its Floquet multipliers.  A stable orbit is an attractor.  On an unstable one
   the run is a transient: the amplitude law ``A_k = A_k0 |μ|^(k - k0)`` (:mod:`exact.dynamics._escape`) predicts
   when it leaves, unless it is not sitting on it (a return of the window, or the fitted amplitude at its end, is
   beyond :data:`ESCAPE_DEVIATION` of the orbit's force), in which case the window is read as aperiodic.
3. The other windows are aperiodic attractors, grouped by their observables (slip interval and force drop within
   :data:`APERIODIC_RTOL`) and their return-map range; each group's largest Lyapunov exponent
   (:func:`exact.lyapunov`, ``"tangent"``, from a start that sets α0 only) tells chaos (at least
   :data:`CHAOS_BITS` bits/s and three standard errors above 0) from a quasi-periodic orbit (below
   :data:`CHAOS_BITS`); an exponent above it but within three standard errors of 0 decides neither (``"aperiodic"``).
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from typing import Any

import numpy as np

from peelapprox import WINDOW_DEFAULTS, PeelParams, StickSlipObservables, periodicity, return_map
from peelapprox.io import fmt_number
from peelapprox.validate import ArgumentTypeError, duration, flag, integer, optional, positive
from peelapprox.validate import params as _params
from peelapprox.validate import rtol as _rtol

from .._model import model_of
from .._shared import DEFAULT_MAX_WALL
from .._trajectory import Trajectory
from ..orbits._periodic import minimal_period, solve_orbit
from ..orbits._section import system_of
from ._attractor_set_result import AttractorSet, SetAttractor, SetOutcome, SetStart
from ._attractor_set_runs import Deadline, check_starts, default_starts, run_all
from ._escape import ESCAPE_DEVIATION, escape_index, predict_escape

__all__ = ["APERIODIC_RTOL", "CHAOS_BITS", "NEAR_RTOL", "ORBIT_MATCH", "WINDOW_MATCH", "attractor_set",
           "default_starts"]

#: A window's return map is looked at as a period-n orbit when it repeats to this (relative, twice
#: :data:`ESCAPE_DEVIATION`): a run on an unstable orbit, or slowly converging to a stable one, repeats to less.
NEAR_RTOL = 2 * ESCAPE_DEVIATION
#: Two periodic windows are one attractor when their periods agree and their sorted cycles (Newton's orbit
#: where it closed) agree to this, relative (a closed orbit's jump forces are reproduced to ~1e-10).
ORBIT_MATCH = 1e-6
#: A settled window (periodic to ``period_rtol``) is on an orbit Newton closed before when its sorted cycle agrees
#: with the orbit's to this, relative (a window settled to 1e-6 lies within ~1e-7 of its orbit).
WINDOW_MATCH = 1e-5
#: Two aperiodic windows are one attractor when their mean slip intervals and force drops agree to this, relative,
#: and their return-map extremes to a fifth of it (20 s windows of one chaotic attractor agree to ~1-3 %).
APERIODIC_RTOL = 0.05
#: An aperiodic attractor is chaotic when its exponent is at least this [bits/s] (and three standard errors above 0):
#: the chaotic orbits of fvV have 3-5.5 bits/s; its long-period and quasi-periodic ones measure 0-0.3 bits/s over
#: 20-50 s (docs/dynamics.md).
CHAOS_BITS = 1.0


def attractor_set(params: PeelParams, *, starts: str | Sequence[Any] = "default",
                  t_transient: float = WINDOW_DEFAULTS["t_transient"], t_window: float = WINDOW_DEFAULTS["window"],
                  rtol: float = WINDOW_DEFAULTS["rtol"], period_rtol: float = 1e-6, max_period: int = 32,
                  stability: bool = True, lyapunov_T: float = 10.0, max_exponents: int = 2, workers: int | None = None,
                  executor: Executor | None = None, progress: bool | Callable[[int, int, str], None] | None = None,
                  max_wall: float | None = DEFAULT_MAX_WALL) -> AttractorSet:
    """The coexisting attractors reached from a designed set of starts, each with its observables, class, share
    of the starts and stability; runs still on an unstable orbit are transients with their predicted escape.

    Parameters
    ----------
    params : PeelParams
        Any law; a model variant (a tape mass, a constant load) runs its own method and gets no multipliers or
        exponents (their tools need the hybrid solver's section).
    starts : "default", sequence or 1-D array
        ``"default"``: :func:`default_starts` (the solver's start, the relaxation cycle's foot at rest, α0 =
        ±0.15, ±0.3 and two states on the AB→CD section: 8 where f has folds at V).  A sequence: each item a
        real number (α0, the rest :func:`exact.initial_state`'s), an :class:`exact.State`, a mapping with keys
        among ``alpha0``, ``omega0``, ``F0``, ``branch0``, ``name``, or a ``SetStart``; at least one.  A 1-D
        numpy array: its values as α0.
    t_transient, t_window, rtol : float
        Of each start's run (:func:`exact.attractor_observables`'s defaults: 30 s, 20 s, 1e-10).
    period_rtol, max_period
        Of the period detection (:func:`peelapprox.periodicity`): 1e-6 and 32.
    stability : bool
        Compute the multipliers of periodic orbits (Newton) and the exponents of aperiodic attractors (True).
        False: the windows only (the cheapest set; no transient can then be told from an attractor).
    lyapunov_T : float
        Seconds over which an exponent is measured, in (0, 1e6] (10: a tangent estimate good to ~1 bit/s, which
        :data:`CHAOS_BITS` needs).
    max_exponents : int
        Exponents measured per call, in [0, 1000] (2): those of the aperiodic attractors with the largest shares
        (the first start's first among equals); the others stay ``"aperiodic"`` with a note.  An exponent costs
        about three windowed runs.
    workers : int, optional
        Without ``executor``: 0 runs the starts in this process, n > 0 on n workers of the local pool of
        :mod:`peelapprox.parallel` (``"auto"``: processes on more than two CPUs, threads on one or two); None one
        worker per CPU available, at most one per start.  The result does not depend on it.
    executor : concurrent.futures.Executor, optional
        Runs the starts (any executor: a process pool, a shared pool, dask's), left running.
    progress : bool or callable, optional
        A callable gets ``(done, total, message)`` after each start's run (done of total starts) and before each
        stability step (done = total); True writes those lines on stderr.
    max_wall : float or None
        Of the whole call [s] (:data:`exact.DEFAULT_MAX_WALL`; None: unbounded): a start it leaves out or cuts is
        an outcome ``"max_wall"``, a stability step (Newton orbit, exponent) it cuts a note on the attractor; either
        makes the set's status ``"max_wall"`` (a set of the starts read; classes unchecked where a step was cut).

    Returns
    -------
    AttractorSet

    Raises
    ------
    ValueError, TypeError
        A bad argument, named with its range: an empty start set, a start outside the model's domain (its field)
        or without a consistent state (``starts[i]``).  A breakdown, a solver failure, a spent budget: outcomes.
    """
    wall0 = time.perf_counter()
    params, t_transient, t_window = _params("params", params), duration("t_transient", t_transient, zero=True), \
        duration("t_window", t_window)
    rtol, period_rtol, max_period = _rtol("rtol", rtol), positive("period_rtol", period_rtol), \
        integer("max_period", max_period, 1, 1000)
    stability, lyapunov_T, max_exponents = flag("stability", stability), duration("lyapunov_T", lyapunov_T), \
        integer("max_exponents", max_exponents, 0, 1000)
    workers, executor = optional(integer, "workers", workers, 0), _executor(executor)
    say, deadline = _reporter(progress), Deadline(optional(positive, "max_wall", max_wall))
    _law_at_V(params)
    valid, invalid = check_starts(params, starts)
    say(0, len(valid), f"attractor_set V={params.V:g} I={params.I:g}: {len(valid)} starts")
    runs = run_all(params, valid, t_transient, t_window, rtol, deadline, workers, executor, say)
    reader = _Reader(params, t_transient, t_window, rtol, period_rtol, max_period, stability,
                     (lyapunov_T, max_exponents), deadline, say)
    outcomes = [*reader.read(valid, runs), *(SetOutcome(s, "invalid start", None, why) for s, why in invalid)]
    counters = dict(reader.counters, runs=float(sum(r.get("trajectory") is not None for r in runs)),
                    run_wall=float(sum(r.get("wall", 0.0) for r in runs)))
    status, message = _status(reader.attractors, outcomes, reader.cut)
    return AttractorSet(params=params, status=status, message=message, attractors=tuple(reader.attractors),
                        outcomes=tuple(outcomes), t_transient=t_transient, t_window=t_window, rtol=rtol,
                        counters=counters, wall_time=time.perf_counter() - wall0)


def _law_at_V(params: PeelParams) -> None:
    """A ValueError naming ``params.force`` where the law is not defined at the pull speed V (a table or smoothed law
    measured at other speeds), as :func:`exact.simulate` raises, before any start: every start would need it (it
    made each of them an ``"invalid start"``, or a given ``starts[0]`` the culprit)."""
    lo, hi = params.force.v_range
    try:
        params.force.f(min(max(params.V, lo), hi), params.V)
    except ValueError as exc:
        raise ValueError(f"params.force: {' '.join(str(exc).split())}") from None


def _executor(executor: Any) -> Executor | None:
    """``executor`` checked: None or anything with a ``submit`` (a :class:`concurrent.futures.Executor`)."""
    if executor is not None and not callable(getattr(executor, "submit", None)):
        raise ArgumentTypeError(f"executor must be None or a concurrent.futures.Executor, got {executor!r}")
    return executor


def _reporter(progress: Any) -> Callable[[int, int, str], None]:
    if progress is None or progress is False:
        return lambda done, total, message: None
    if progress is True:
        import sys

        return lambda done, total, message: print(f"[{done}/{total}] {message}", file=sys.stderr, flush=True)
    if callable(progress):
        return progress
    raise ArgumentTypeError(f"progress must be a bool, None or a callable (done, total, message), got {progress!r}")


def _status(attractors: list[SetAttractor], outcomes: list[SetOutcome], steps_cut: int = 0) -> tuple[str, str]:
    """The set's status and message; ``steps_cut`` stability steps (a Newton orbit, an exponent) the budget left out
    make it ``"max_wall"`` too: without its orbit a near-periodic window is read as aperiodic and a run on an
    unstable orbit as an attractor, so the classes may be wrong."""
    ran = [o for o in outcomes if o.outcome not in ("invalid start", "max_wall")]
    found = [a for a in attractors if a.kind != "breakdown"]
    cut = sum(o.outcome == "max_wall" for o in outcomes)
    names = ", ".join(f"{a.label} ({fmt_number(100 * a.share, 3)} %)" for a in attractors)
    if cut:
        return "max_wall", (f"max_wall spent: {cut} of {len(outcomes)} starts not read; the set is of the "
                            f"{len(ran)} read: {names or 'none'}")
    if steps_cut:
        return "max_wall", (f"max_wall spent before {steps_cut} stability step{'s' * (steps_cut > 1)} (Newton orbit or "
                            f"Lyapunov exponent): the classes may be wrong (a near-periodic window is then read as "
                            f"aperiodic, a run on an unstable orbit as an attractor); the set of the {len(ran)} starts "
                            f"read: {names or 'none'}")
    if found:
        tr = sum(o.outcome == "transient" for o in outcomes)
        return "ok", f"{len(found)} attractor{'s' * (len(found) > 1)} from {len(ran)} starts: {names}" + (
            f"; {tr} start{'s' * (tr > 1)} still in a transient" if tr else "")
    if any(o.outcome == "transient" for o in ran):
        return "transient only", ("every start that ran is still in a transient at t_transient; lengthen "
                                  "t_transient (the outcomes give the predicted escapes)")
    if attractors:
        return "breakdown only", f"every start that ran breaks down: {names}"
    return "no attractor", "no start ran to a window (every start invalid or failed; the outcomes say why)"


class _Reader:
    """Reads the finished runs into attractors, in the order of the starts (module docstring)."""

    def __init__(self, params: PeelParams, t_transient: float, t_window: float, rtol: float, period_rtol: float,
                 max_period: int, stability: bool, exponents: tuple[float, int], deadline: Deadline,
                 say: Callable[[int, int, str], None]):
        self.params, self.t_transient, self.t_window, self.rtol = params, t_transient, t_window, rtol
        self.period_rtol, self.max_period, self.stability = period_rtol, max_period, stability
        self.lyapunov_T, self.max_exponents = exponents
        self.deadline, self.say = deadline, say
        self.groups: list[dict[str, Any]] = []
        self.attractors: list[SetAttractor] = []
        self.counters: dict[str, float] = {"steps": 0.0, "rhs": 0.0, "orbits": 0.0, "lyapunov": 0.0}
        self.orbits: dict[tuple, Any] = {}
        self.n_starts = 0
        self.cut = 0  # stability steps the budget left out or stopped (the status says so: _status)

    # ------------------------------------------------------------------------------------------ per start
    def read(self, starts: list[SetStart], runs: list[dict[str, Any]]) -> list[SetOutcome]:
        self.n_starts = len(starts)
        pending: list[tuple[int, str, Any]] = []  # (start index, group key kind, payload)
        outcomes: list[SetOutcome | None] = [None] * len(starts)
        for i, (s, r) in enumerate(zip(starts, runs, strict=True)):
            tr: Trajectory | None = r.get("trajectory")
            if tr is None:
                if r["outcome"] == "breakdown":
                    g = self._group("breakdown", f"breakdown:{r['reason']}", i, None)
                    outcomes[i] = SetOutcome(s, "breakdown", g, r["message"], wall_time=r["wall"])
                else:
                    outcomes[i] = SetOutcome(s, r["outcome"], None, r["message"], wall_time=r["wall"])
                continue
            self.counters["steps"] += tr.stats.n_steps
            self.counters["rhs"] += tr.stats.n_rhs
            obs = StickSlipObservables.from_trajectory(tr, self.t_transient, period_rtol=self.period_rtol,
                                                       max_period=self.max_period, method=_how(tr, s, self))
            if obs.status == "steady":
                outcomes[i] = SetOutcome(s, "attractor", self._group("steady", "steady", i, obs), obs.reason, obs,
                                         wall_time=r["wall"])
            elif obs.status != "stick-slip":
                outcomes[i] = SetOutcome(s, "transient", None, f"{obs.status}: {obs.reason}", obs, wall_time=r["wall"])
            else:
                pending.append((i, "run", (tr, obs, r["wall"])))
        for i, _, (tr, obs, wall) in pending:
            outcomes[i] = self._periodic_or_not(starts[i], i, tr, obs, wall)
        done = self._renumber([o for o in outcomes if o is not None])
        self.build(starts, sum(o.outcome not in ("max_wall", "invalid start") for o in done))
        return done

    def _renumber(self, outcomes: list[SetOutcome]) -> list[SetOutcome]:
        """The groups numbered in the order of the starts that first reach them (so the first start's attractor,
        :attr:`AttractorSet.primary`, is the first), the outcomes' ids with them: the breakdowns and steady windows
        are grouped in a first pass and the stick-slip windows after, which numbered them out of that order."""
        self.groups.sort(key=lambda g: min(g["members"]))
        new = {g["id"]: k for k, g in enumerate(self.groups)}
        for g in self.groups:
            g["id"] = new[g["id"]]
        return [o if o.attractor is None else dataclasses.replace(o, attractor=new[o.attractor]) for o in outcomes]

    def _group(self, kind: str, label: str, i: int, obs: StickSlipObservables | None, **extra: Any) -> int:
        """The id of the group ``label`` (made if new), with start ``i`` added."""
        for g in self.groups:
            if g["kind"] == kind and g["label"] == label and kind in ("steady", "breakdown"):
                g["members"].append(i)
                return int(g["id"])
        self.groups.append(dict(id=len(self.groups), kind=kind, label=label, members=[i], obs=obs, **extra))
        return len(self.groups) - 1

    def _periodic_or_not(self, s: SetStart, i: int, tr: Trajectory, obs: StickSlipObservables,
                         wall: float) -> SetOutcome:
        x = return_map(tr)
        n = obs.period
        if n is None and x.size >= 3:
            near = periodicity(x, rtol=NEAR_RTOL, max_period=self.max_period)
            n = near.period
        if obs.period is not None:  # a settled window on a known orbit: no second Newton solve
            g = self._known(i, np.sort(x[-obs.period:]))
            if g is not None:
                return SetOutcome(s, "attractor", g, f"{self.groups[g]['label']} (the orbit Newton closed from an "
                                  "earlier start)", obs, wall_time=wall)
        if n is not None:
            orbit, note = self._orbit(tr, n) if self.stability and model_of(self.params).has_hybrid else (None, "")
            if orbit is not None and not orbit.stable:
                esc = self._escape(tr, orbit)
                sitting = escape_index(x, orbit.return_map_values) is None  # every return within 1 % of the orbit's
                if esc is not None and sitting and esc.deviation < ESCAPE_DEVIATION:
                    mu = max(abs(m) for m in orbit.multipliers)
                    pair = ", a complex pair" if abs(orbit.multipliers[0].imag) > 0 else ""
                    msg = (f"transient: {'weakly ' if mu < 1.01 else ''}unstable period-{orbit.n}, |μ|="
                           f"{mu:.5g}{pair}, predicted escape after ~{esc.returns:.0f} returns / at t = "
                           f"{fmt_number(esc.time, 4)} s (deviation {fmt_number(esc.deviation, 2)} of its force now)")
                    return SetOutcome(s, "transient", None, msg, obs, esc, wall)
            elif orbit is not None or obs.period is not None:
                cycle = (tuple(float(c) for c in np.sort(orbit.return_map_values)) if orbit is not None
                         else tuple(float(c) for c in np.sort(x[-n:])))
                g = self._periodic_group(i, obs, cycle, orbit, note, x)
                return SetOutcome(s, "attractor", g, f"{self.groups[g]['label']}" + (f" ({note})" if note else ""),
                                  obs, wall_time=wall)
        g = self._aperiodic_group(i, obs, x)
        return SetOutcome(s, "attractor", g, f"aperiodic: {obs.reason}", obs, wall_time=wall)

    def _known(self, i: int, cycle: np.ndarray) -> int | None:
        """The periodic group whose Newton orbit has this window's sorted cycle (to :data:`WINDOW_MATCH`), with
        start ``i`` added; None if none."""
        for g in self.groups:
            if g["kind"] == "periodic" and g.get("orbit") is not None and len(g["cycle"]) == cycle.size and \
                    np.allclose(g["cycle"], cycle, rtol=WINDOW_MATCH, atol=0.0):
                g["members"].append(i)
                return int(g["id"])
        return None

    def _periodic_group(self, i: int, obs: StickSlipObservables, cycle: tuple[float, ...], orbit: Any, note: str,
                        x: np.ndarray) -> int:
        for g in self.groups:
            if g["kind"] == "periodic" and len(g["cycle"]) == len(cycle) and \
                    np.allclose(g["cycle"], cycle, rtol=ORBIT_MATCH if orbit is not None else 1e-4, atol=0.0):
                g["members"].append(i)
                return int(g["id"])
        return self._group("periodic", f"period-{len(cycle)}", i, obs, cycle=cycle, orbit=orbit, note=note,
                           returns=x[-2000:])

    def _aperiodic_group(self, i: int, obs: StickSlipObservables, x: np.ndarray) -> int:
        def near(a: float | None, b: float | None, tol: float) -> bool:
            return a is not None and b is not None and abs(a - b) <= tol * max(abs(a), abs(b))

        for g in self.groups:
            o = g["obs"]
            if g["kind"] == "aperiodic" and near(o.slip_interval, obs.slip_interval, APERIODIC_RTOL) and \
                    near(o.force_drop, obs.force_drop, APERIODIC_RTOL) and \
                    near(o.F_max, obs.F_max, APERIODIC_RTOL / 5) and near(o.F_min, obs.F_min, APERIODIC_RTOL / 5):
                g["members"].append(i)
                return int(g["id"])
        return self._group("aperiodic", "aperiodic", i, obs, returns=x[-2000:],
                           cycle=(float(x.min()), float(x.max()), float(x.mean())))

    # ------------------------------------------------------------------------------------------ stability
    def _orbit(self, tr: Trajectory, n: int) -> tuple[Any, str]:
        """Newton's period-n orbit seeded at the window's nearest recurrence, or (None, why not)."""
        j = tr.jumps
        up = (j.from_branch == 0) & (j.t >= self.t_transient)
        a, w = j.alpha[up], j.omega[up]
        if a.size <= n:
            return None, f"no orbit: {a.size} returns for period {n}"
        z = np.column_stack([a, w * self.params.R / self.params.V])
        k = int(np.argmin(np.linalg.norm(z[n:] - z[:-n], axis=1)))
        key = (n, round(float(a[k]), 6), round(float(w[k]), 4))
        if key in self.orbits:
            return self.orbits[key]
        self.say(self.n_starts, self.n_starts, f"period-{n} orbit by Newton")
        try:
            left = self.deadline.left()
            if left is not None and left <= 0:
                self.cut += 1
                return None, "multipliers not computed: max_wall spent"
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                ts = system_of(self.params)
                o = solve_orbit(self.params, np.array([a[k], w[k]]), n, tol=1e-9, rtol=1e-11, max_iter=20,
                                system=ts, wall=self.deadline.budget())
                d = minimal_period(o)
                if d < n:
                    o = solve_orbit(self.params, o.section_states[0], d, tol=1e-9, rtol=1e-11, max_iter=20,
                                    system=ts, wall=self.deadline.budget())
            self.counters["orbits"] += 1
            self.counters["steps"] += o.steps
            note = "; ".join(str(c.message) for c in caught)[:200]
            res: tuple[Any, str] = (o, f"Newton residual {o.residual:.2g}" + (f"; {note}" if note else ""))
        except (ValueError, ArithmeticError, RuntimeError) as exc:  # no convergence, breakdown, budget, failure
            self.cut += _spent(exc, self.deadline)
            res = (None, f"multipliers not computed: {type(exc).__name__}: {' '.join(str(exc).split())[:160]}")
        self.orbits[key] = res
        return res

    def _escape(self, tr: Trajectory, orbit: Any) -> Any:
        """The amplitude law's escape of this run from the unstable ``orbit`` (None if it cannot say)."""
        j = tr.jumps
        up = (j.from_branch == 0) & (j.t >= self.t_transient)
        a, w, t = j.alpha[up], j.omega[up], j.t[up]
        n, s = orbit.n, np.array([1.0, self.params.V / self.params.R])
        zs = orbit.section_states / s
        z = np.column_stack([a, w]) / s
        phase = np.argmin(np.linalg.norm(z[:, None, :] - zs[None, :, :], axis=2), axis=1)
        first = np.flatnonzero(phase == 0)
        if first.size == 0:
            return None
        k0 = int(first[0])
        before = (tr.stats.n_jumps - j.t.size) // 2  # AB→CD jumps before the window (the jumps alternate)
        return predict_escape(self.params, orbit.monodromy, orbit.section_states[0],
                              float(orbit.return_map_values[0]), a[k0::n], w[k0::n], t[k0::n], orbit.period, n,
                              before + k0)

    def _lyapunov(self, g: dict[str, Any], starts: list[SetStart]) -> None:
        from ._lyapunov import lyapunov

        alpha = [starts[i] for i in g["members"] if starts[i].alpha_only]
        if not self.stability or not model_of(self.params).has_hybrid:
            g["note"] = "no exponent: stability=False" if not self.stability else "no exponent for a model variant"
            return
        if not alpha:
            g["note"] = "no exponent: reached only from starts that set more than α0 (exact.lyapunov starts from α0)"
            return
        left = self.deadline.left()
        if left is not None and left <= 0:
            self.cut += 1
            g["note"] = "no exponent: max_wall spent"
            return
        self.say(self.n_starts, self.n_starts, f"Lyapunov exponent from {alpha[0].name}")
        try:
            L = lyapunov(self.params, "tangent", t_transient=self.t_transient, alpha0=alpha[0].alpha0,
                         T=self.lyapunov_T, max_wall=left)
        except (ValueError, ArithmeticError, RuntimeError) as exc:
            self.cut += _spent(exc, self.deadline)
            g["note"] = f"no exponent: {type(exc).__name__}: {' '.join(str(exc).split())[:160]}"
            return
        self.counters["lyapunov"] += 1
        lam, err = float(L.bits_per_s), float(L.stderr_bits)
        g["note"] = f"tangent exponent over {fmt_number(self.lyapunov_T, 3)} s from {alpha[0].name}"
        if not math.isfinite(lam):  # never NaN in a result: no exponent, the class undecided
            g["note"] = f"no exponent: the {g['note']} is not finite"
            return
        g["lyapunov"], g["lyapunov_stderr"] = lam, err if math.isfinite(err) else None
        if lam >= CHAOS_BITS and lam > 3 * err:
            g["kind"] = g["label"] = "chaotic"
        elif lam < CHAOS_BITS:
            g["kind"] = g["label"] = "quasi-periodic"
        else:  # positive beyond the chaos threshold, yet within three standard errors of 0 (or without one)
            g["note"] += (f": {fmt_number(lam, 3)} bits/s, not three standard errors above 0, decides neither chaos "
                          "nor a torus (lengthen lyapunov_T)")

    def build(self, starts: list[SetStart], n_ran: int) -> None:
        """The :class:`SetAttractor` of each group (exponents measured here, after every start is read)."""
        aperiodic = sorted((g for g in self.groups if g["kind"] == "aperiodic"), key=lambda g: -len(g["members"]))
        for k, g in enumerate(aperiodic):
            if k < self.max_exponents:
                self._lyapunov(g, starts)
            else:
                g["note"] = f"no exponent: max_exponents={self.max_exponents} measured for larger shares"
        for g in self.groups:
            o = g.get("orbit")
            self.attractors.append(SetAttractor(
                id=g["id"], kind=g["kind"], label=g["label"] if g["kind"] != "periodic" or o is None
                else f"period-{o.n}", period=(o.n if o is not None else len(g["cycle"])) if g["kind"] == "periodic"
                else None,
                share=len(g["members"]) / max(1, n_ran), starts=tuple(starts[i].name for i in g["members"]),
                observables=g["obs"], cycle=tuple(g.get("cycle", ())),
                multipliers=None if o is None else tuple(complex(m) for m in o.multipliers),
                stable=None if o is None else bool(o.stable), lyapunov=g.get("lyapunov"),
                lyapunov_stderr=g.get("lyapunov_stderr"), note=g.get("note", ""),
                returns=np.asarray(g.get("returns", np.zeros(0)))))


def _spent(exc: BaseException, deadline: Deadline) -> int:
    """1 where a stability step stopped for the call's budget (a wall-time budget error, or the deadline passed),
    else 0 (no convergence, a breakdown: the step's own outcome)."""
    left = deadline.left()
    return int(getattr(exc, "budget", None) == "max_wall" or (left is not None and left <= 0))


def _how(tr: Trajectory, s: SetStart, r: _Reader) -> str:
    return (f"exact: {tr.method} ({tr.solver}), rtol {fmt_number(r.rtol, 3)}, start {s.name}, window "
            f"[{fmt_number(r.t_transient, 6)}, {fmt_number(r.t_transient + r.t_window, 6)}] s, period_rtol "
            f"{fmt_number(r.period_rtol, 3)}")
