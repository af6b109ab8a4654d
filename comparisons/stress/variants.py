"""The stress grid of the model variants (docs/tape-mass.md, docs/constant-load.md): the tape mass over
(m, V, I) and the constant load over (M, I, F_L), each run by :func:`exact.simulate` with the model's own method,
bounded in wall time.

    python -m comparisons.stress.variants [--quick] [--out DIR] [--t-end S] [--max-wall S] [--timeout S]

Every point must end in a result (``ok``), a documented :class:`~exact.ModelBreakdown` (``breakdown:<reason>``:
``arrest``, ``slack``, ``law_domain``, ``no_root``, ...) or a :class:`~exact.SolverBudgetExceeded`
(``budget:<which>``, ``max_wall`` among them) -- with a finite time and state in the exception, and no NaN or
infinity anywhere in the result, its jumps, its pull speed, the exception's state or the partial trajectory.
Anything else is a bug: ``nan``, ``unexpected:<Type>`` (any other exception), ``timeout`` (no answer within
the worker's timeout: a hang past ``max_wall``) or ``crash`` (the worker died).  Each point runs in the stress
suite's worker process (:class:`~comparisons.stress.runner.StressRunner`).

The grids (:func:`variant_grid`):

* tape mass: m ∈ :data:`TAPE_MASSES` × V ∈ :data:`TAPE_V` × I ∈ :data:`TAPE_I` (velocity control);
* constant load: M ∈ :data:`LOAD_MASSES` × I ∈ :data:`TAPE_I` × F_L below, inside and above the fold
  window [f_min, f_max] of f(v, V) at V = :data:`LOAD_V` (:func:`load_levels`), for the massless tape and
  for m = :data:`LOAD_TAPE_MASS`.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .._worker import message, write_line

__all__ = ["VARIANT_ALLOWED", "VARIANT_BUGS", "is_allowed", "is_bug", "LOAD_MASSES", "LOAD_TAPE_MASS", "LOAD_V",
           "TAPE_I", "TAPE_MASSES", "TAPE_V", "VARIANT_MAX_STEPS", "VARIANT_MAX_WALL", "VARIANT_T_END",
           "VariantPoint", "load_levels", "main", "run_variant_point", "run_variant_points", "variant_grid",
           "variant_markdown"]

#: Tape masses m [kg]: from far below the ε of the paper's scheme (1e-12) to a 10 kg ribbon.
TAPE_MASSES: tuple[float, ...] = (1e-12, 1e-8, 1e-5, 1e-3, 1e-1, 10.0)
#: Pull speeds V [m/s] of the tape-mass grid: below, inside and near the top of the stick-slip window.
TAPE_V: tuple[float, ...] = (0.1, 1.0, 4.0)
#: Roller inertias I [kg m²] of both grids.
TAPE_I: tuple[float, ...] = (1e-6, 1e-4, 1e-2)
#: Loading masses M [kg]: LOAD_MASS_RANGE's ends and between.
LOAD_MASSES: tuple[float, ...] = (1e-6, 1e-3, 1.0, 1e3, 1e6)
#: The speed V [m/s] of the load grid (where f is evaluated, V_p's start).
LOAD_V = 1.0
#: The tape mass [kg] of the load grid's massive half.
LOAD_TAPE_MASS = 1e-4
#: The endings a variant run may have (anything else is a bug): a result, a ModelBreakdown, a SolverBudgetExceeded.
#: A ``solver_failure`` (scipy gave up: the step size underflowed) is simulate's documented last resort, but
#: recorded here as a finding (reported to the solver's owner: it should be a breakdown or a budget).
VARIANT_ALLOWED: tuple[str, ...] = ("ok", "breakdown:", "budget:")
#: Outcomes that are bugs outright: a non-finite value, another exception, a hang, a dead worker.
VARIANT_BUGS: tuple[str, ...] = ("nan", "unexpected:", "timeout", "crash")


def is_allowed(outcome: str) -> bool:
    """True for :data:`VARIANT_ALLOWED` (a result, a documented breakdown, a budget)."""
    return any(outcome == p or (p.endswith(":") and outcome.startswith(p)) for p in VARIANT_ALLOWED)


def is_bug(outcome: str) -> bool:
    """True for :data:`VARIANT_BUGS` (NaN, an unrelated exception, a hang, a crash)."""
    return any(outcome == p or (p.endswith(":") and outcome.startswith(p)) for p in VARIANT_BUGS)


#: Simulated horizon of a point [s] (a few stick-slip cycles at V = 1, I = 1e-5), its wall-time budget [s] and
#: step budget: a point ends in ``budget:max_wall`` rather than running on.
VARIANT_T_END = 0.05
VARIANT_MAX_WALL = 5.0
VARIANT_MAX_STEPS = 1_000_000


@dataclass(frozen=True)
class VariantPoint:
    """One variant run: ``PeelParams(V, I, tape_mass, loading, load_mass, load)`` to ``t_end`` with ``max_wall``
    [s] and ``max_steps``; ``group`` (``"tape"`` or ``"load"``) and ``where`` (the load against the fold
    window: ``"below"``, ``"inside"``, ``"above"``; ``""`` for the tape grid) label it."""

    group: str
    V: float
    I: float
    tape_mass: float | None = None
    loading: str = "velocity"
    load_mass: float | None = None
    load: float | None = None
    where: str = ""
    t_end: float = VARIANT_T_END
    max_wall: float = VARIANT_MAX_WALL
    max_steps: int = VARIANT_MAX_STEPS

    def params(self) -> Any:
        from peelapprox import PeelParams

        return PeelParams(V=self.V, I=self.I, tape_mass=self.tape_mass, loading=self.loading,
                          load_mass=self.load_mass, load=self.load)

    def label(self) -> str:
        s = f"[{self.group}] V={self.V:g} I={self.I:g}"
        if self.tape_mass:
            s += f" m={self.tape_mass:g}"
        if self.loading == "load":
            s += f" M={self.load_mass:g} F_L={self.load:.4g} ({self.where})"
        return s


def load_levels(V: float = LOAD_V) -> dict[str, float]:
    """The loads F_L [N] of the load grid at ``V``: ``below`` = f_min/2, ``inside`` = (f_min + f_max)/2,
    ``above`` = 1.5 f_max, with f_min, f_max the folds of the paper's f(v, V)."""
    from peelapprox import branch_structure

    bs = branch_structure(V)
    if not bs.has_folds:
        raise ValueError(f"V must lie in the stick-slip window (f has folds), got {V}")
    return {"below": 0.5 * bs.f_min, "inside": 0.5 * (bs.f_min + bs.f_max), "above": 1.5 * bs.f_max}


def variant_grid(quick: bool = False, *, t_end: float = VARIANT_T_END, max_wall: float = VARIANT_MAX_WALL
                 ) -> list[VariantPoint]:
    """The points of the grid (module docstring): 54 tape-mass points and 90 load points; ``quick``: a corner
    subset (the extreme masses, the middle inertia, every load level) of 24 points."""
    ms, vs, is_, Ms = TAPE_MASSES, TAPE_V, TAPE_I, LOAD_MASSES
    if quick:
        ms, vs, is_, Ms = (ms[0], ms[3], ms[-1]), (1.0, 4.0), (1e-4,), (Ms[0], Ms[-1])
    kw = dict(t_end=t_end, max_wall=max_wall)
    pts = [VariantPoint("tape", V, I, tape_mass=m, **kw) for m in ms for V in vs for I in is_]  # type: ignore[arg-type]
    levels = load_levels(LOAD_V)
    for m in (None, LOAD_TAPE_MASS):
        pts += [VariantPoint("load", LOAD_V, I, tape_mass=m, loading="load", load_mass=M, load=F, where=w,
                             **kw)  # type: ignore[arg-type]
                for M in Ms for I in is_ for w, F in levels.items()]
    return pts


def _nonfinite(*xs: Any) -> bool:
    for x in xs:
        if x is None:
            continue
        a = np.asarray(x, dtype=float)
        if a.size and not np.all(np.isfinite(a)):
            return True
    return False


def _trajectory_nonfinite(tr: Any) -> bool:
    J = tr.jumps
    fs = tr.final_state
    return _nonfinite(tr.t, tr.alpha, tr.omega, tr.F, tr.v, tr.Vp, J.t, J.alpha, J.omega, J.F, J.v_before,
                      J.v_after, [fs.t, fs.alpha, fs.omega, fs.F, fs.v], fs.Vp)


def run_variant_point(point: VariantPoint) -> dict:
    """Run one point in this process; its record: the point's fields, ``outcome`` (module docstring),
    ``exception``, ``reason``, ``message``, ``t_reached`` [s], ``wall`` [s], ``method``, ``n_steps``,
    ``n_jumps``, ``n_points``, ``nonfinite``.  Never raises for a run's ending (that is the record)."""
    import exact
    from exact import ModelBreakdown, SolverBudgetExceeded, SolverFailure

    rec: dict[str, Any] = {**asdict(point), "outcome": "", "exception": "", "reason": "", "message": "",
                           "t_reached": float("nan"), "wall": float("nan"), "method": "", "n_steps": 0,
                           "n_jumps": 0, "n_points": 0, "nonfinite": False}
    t0 = time.perf_counter()
    tr = exc = None
    try:
        tr = exact.simulate(point.params(), point.t_end, max_wall=point.max_wall, max_steps=point.max_steps,
                            progress=False)
        rec.update(outcome="ok", t_reached=float(tr.final_state.t))
    except ModelBreakdown as e:
        rec.update(outcome=f"breakdown:{e.reason}", exception="ModelBreakdown", reason=str(e.reason), t_reached=e.t)
        tr, exc = e.partial, e
    except SolverBudgetExceeded as e:
        rec.update(outcome=f"budget:{e.budget}", exception="SolverBudgetExceeded", reason=str(e.budget),
                   t_reached=e.t)
        tr, exc = e.partial, e
    except SolverFailure as e:  # documented by simulate, but not one of the grid's endings: a finding
        rec.update(outcome="solver_failure", exception="SolverFailure", t_reached=e.t)
        tr, exc = e.partial, e
    except Exception as e:  # noqa: BLE001 - any other exception is a finding, recorded
        rec.update(outcome=f"unexpected:{type(e).__name__}", exception=type(e).__name__)
        exc = e
    rec["wall"] = time.perf_counter() - t0
    if exc is not None:
        rec["message"] = message(exc)
    if tr is not None:
        rec.update(method=tr.method, n_steps=int(tr.stats.n_steps), n_jumps=int(len(tr.jumps)),
                   n_points=int(len(tr.t)), nonfinite=_trajectory_nonfinite(tr))
    if isinstance(exc, (ModelBreakdown, SolverBudgetExceeded, SolverFailure)):  # finite t and state, no "nan"
        state = [v for v in exc.state.values() if isinstance(v, (int, float))]
        rec["nonfinite"] |= (_nonfinite([exc.t], state) or "nan" in str(exc).lower().split()
                             or " inf" in str(exc).lower())
    if rec["nonfinite"]:
        rec["outcome"] = "nan"
    return rec


def _run_task(point: VariantPoint) -> dict:
    return run_variant_point(point)


def run_variant_points(points: Sequence[VariantPoint], *, timeout: float = 60.0, progress: bool = True
                       ) -> list[dict]:
    """Every point in the stress suite's worker process (:class:`~comparisons.stress.runner.StressRunner`,
    ``timeout`` [s] a point, past its ``max_wall``: a ``timeout`` is a hang), one record each, in order."""
    from .runner import StressRunner

    recs = []
    with StressRunner(timeout=timeout, func=_run_task, warm=False) as runner:
        for i, p in enumerate(points, 1):
            rec = runner.run(p)
            if rec.get("outcome") in ("timeout", "crash"):
                rec = {**asdict(p), **{k: v for k, v in rec.items() if k != "task"}}
            recs.append(rec)
            if progress:
                o = rec["outcome"]
                flag = "   <-- BUG" if is_bug(o) else "" if is_allowed(o) else "   <-- finding"
                write_line(f"{i:4d}/{len(points)} {p.label()} -> {rec['outcome']} ({rec['wall']:.3g} s, "
                           f"{rec.get('n_jumps', 0)} jumps){flag}")
    return recs


def variant_markdown(records: Sequence[dict]) -> str:
    """The outcome counts per group (tape mass; load, massless and massive) as a markdown table."""
    groups = {"tape mass (m, V, I)": [r for r in records if r["group"] == "tape"],
              "load, massless (M, I, F_L)": [r for r in records if r["group"] == "load" and not r["tape_mass"]],
              f"load, m = {LOAD_TAPE_MASS:g} kg (M, I, F_L)": [r for r in records
                                                            if r["group"] == "load" and r["tape_mass"]]}
    outcomes = sorted({r["outcome"] for r in records}, key=lambda o: (not o.startswith("ok"), o))
    lines = ["| grid | " + " | ".join(f"`{o}`" for o in outcomes) + " | total | bugs |",
             "|---|" + "---:|" * (len(outcomes) + 2)]
    for name, rs in groups.items():
        c = Counter(r["outcome"] for r in rs)
        bugs = sum(is_bug(r["outcome"]) for r in rs)
        lines.append(f"| {name} | " + " | ".join(str(c.get(o, 0)) for o in outcomes) + f" | {len(rs)} | {bugs} |")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the grid, write ``variants.csv``/``.json`` and the markdown counts to ``--out``; 0 if no bug, 1 else."""
    from peelapprox.io import write_rows

    ap = argparse.ArgumentParser(prog="python -m comparisons.stress.variants", description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the corner subset (24 points)")
    ap.add_argument("--out", default="stress_variants", help="output directory")
    ap.add_argument("--t-end", type=float, default=VARIANT_T_END, help="simulated horizon of a point [s]")
    ap.add_argument("--max-wall", type=float, default=VARIANT_MAX_WALL, help="wall-time budget of a run [s]")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds before a point counts as a hang")
    ap.add_argument("--no-progress", action="store_true", help="no per-point lines on stderr")
    a = ap.parse_args(argv)
    for name in ("t_end", "max_wall", "timeout"):
        x = getattr(a, name)
        if not (math.isfinite(x) and x > 0):
            ap.error(f"--{name.replace('_', '-')} must be in (0, inf), got {x}")
    t0 = time.perf_counter()
    recs = run_variant_points(variant_grid(a.quick, t_end=a.t_end, max_wall=a.max_wall), timeout=a.timeout,
                              progress=not a.no_progress)
    os.makedirs(a.out, exist_ok=True)
    for ext in ("csv", "json"):
        write_rows(os.path.join(a.out, f"variants.{ext}"), recs)
    md = variant_markdown(recs)
    with open(os.path.join(a.out, "variants.md"), "w") as fh:
        fh.write(md + "\n")
    nbug = sum(is_bug(r["outcome"]) for r in recs)
    nfind = sum(not is_allowed(r["outcome"]) and not is_bug(r["outcome"]) for r in recs)
    sys.stdout.write(md + f"\n\nbugs (nan, unexpected, timeout, crash): {nbug}; findings (solver_failure): "
                     f"{nfind}; wall time {time.perf_counter() - t0:.1f} s; wrote {a.out}\n")
    return 1 if nbug else 0


if __name__ == "__main__":
    sys.exit(main())
