"""Which integrator solves the tape-mass model (docs/tape-mass.md) fastest, across the mass range: work precision.

    python -m comparisons.benchmark.tape_mass [--json FILE] [--figure PNG] [--cap SECONDS] [--quick]

For each scene of :data:`SCENES` and each tape mass of :data:`MASSES`, ``exact.simulate(method="smooth")`` is run
with scipy's Radau, BDF, LSODA and DOP853 at the tolerances :data:`RTOLS` over the scene's horizon, and each run is
reported with its wall time, accepted steps, field and Jacobian evaluations, LU factorisations, the cost per step
and per field evaluation, and its **error**: the largest difference of the jump times from the reference's, in
seconds, ``max_j |t_j - t_j^ref|`` (``inf`` if the run has a different number of jumps: another orbit), and the
largest relative difference of F at the jumps.  **Reference**: LSODA at rtol 1e-12 (cross-checked once against
Radau at rtol 1e-11 on the two scenes at m = 1e-9 and 1e-3 kg: the jump times agree to the 9 digits printed,
and Radau at rtol 1e-9 is within ~1e-11 s of it in every row, docs/tape-mass.md).  Every run is bounded by a wall-time
cap (``max_wall``, default 5 s): a run over it is reported as ``capped`` with the time it reached, and the same
solver is not run at tighter tolerances for that mass (``skipped``).  The fields are compiled before any timing;
each configuration is timed once (the runs are 0.05-5 s; the machine's load is printed with the table).
The stiffness estimate of each mass is printed too: the fast time scale ``m (1 + sin α)² / max|f'|``
(:func:`fast_time`), against the slow scale (the jump interval, milliseconds).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

import exact
from peelapprox import PeelParams, branch_structure, peel_force_derivative
from peelapprox.plotting import save_figure

__all__ = ["MASSES", "RTOLS", "SCENES", "SOLVERS", "TMRow", "fast_time", "main", "plot_solvers", "step_rates",
           "tape_mass_benchmark"]

#: Tape masses [kg]: from far below any real tape (the stiff low-mass limit) to 0.1 kg (not stiff).
MASSES = (1e-9, 1e-7, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
#: The scipy solvers compared and their tolerances.
SOLVERS = ("Radau", "BDF", "LSODA", "DOP853")
RTOLS = (1e-5, 1e-7, 1e-9)
#: (name, V [m/s], I [kg m²], horizon [s]): the paper's period-2-like scene and a chaotic one (several jumps).
SCENES = (("V1 I1e-5", 1.0, 1e-5, 0.05), ("V2 I1e-4", 2.0, 1e-4, 0.05))
REF_RTOL = 1e-12


@dataclass
class TMRow:
    """One run: the scene, mass, solver and rtol; its status (``ok``, ``capped``, ``skipped``, ``failed``), wall
    time [s], counters, µs per step and per field evaluation, and its errors against the reference."""

    scene: str
    mass: float
    solver: str
    rtol: float
    status: str
    wall: float
    steps: int
    n_rhs: int
    n_jac: int
    n_lu: int
    us_per_step: float
    us_per_rhs: float
    err_t: float
    err_F: float
    t_reached: float
    steps_per_s: float


def fast_time(params: PeelParams, alpha: float = 0.0) -> float:
    """The tape-mass model's fast time scale [s] near the slow manifold: ``m (1 + sin α)² / max|f'|``, the
    steepest slope of the peel force over the orbit's velocity range (from AB's landing velocity to CD's)
    (the ε-scheme's with ``ε_eff = m (1 + sin α)²``, docs/tape-mass.md)."""
    bs = branch_structure(params.V)
    lo = bs.v_land_ab if bs.v_land_ab is not None else 1e-6
    hi = bs.v_land_cd if bs.has_folds else 10.0
    v = np.geomspace(lo, hi, 4001)
    fp = np.abs(peel_force_derivative(v, params.V))
    return float(params.tape_mass or 0.0) * (1.0 + math.sin(alpha)) ** 2 / float(np.max(fp))


def _run(params: PeelParams, horizon: float, solver: str, rtol: float, cap: float):
    t0 = time.perf_counter()
    try:
        tr = exact.simulate(params, horizon, method="smooth", solver=solver, rtol=rtol, save="jumps", max_wall=cap)
        return "ok", time.perf_counter() - t0, tr, horizon
    except exact.SolverBudgetExceeded as e:
        return "capped", time.perf_counter() - t0, e.partial, e.t
    except (exact.SolverFailure, exact.ModelBreakdown) as e:
        return "failed", time.perf_counter() - t0, e.partial, e.t


def tape_mass_benchmark(masses=MASSES, solvers=SOLVERS, rtols=RTOLS, scenes=SCENES, cap: float = 5.0,
                        say=print) -> tuple[list[TMRow], dict]:
    """The rows (module docstring) and the references' jump times per (scene, mass)."""
    exact.simulate(PeelParams(V=1.0, I=1e-5, tape_mass=1e-3), 1e-3, method="smooth", solver="LSODA")  # compile
    rows: list[TMRow] = []
    refs: dict = {}
    for name, V, I, horizon in scenes:
        for m in masses:
            p = PeelParams(V=V, I=I, tape_mass=m)
            ref = exact.simulate(p, horizon, method="smooth", solver="LSODA", rtol=REF_RTOL, save="jumps",
                                 max_wall=120.0)
            refs[f"{name} m={m:g}"] = dict(t=ref.jumps.t.tolist(), F=ref.jumps.F.tolist(),
                                           fast_time=fast_time(p), ref_wall=ref.stats.wall_time)
            for solver in solvers:
                dead = False
                for rtol in rtols:
                    if dead:
                        rows.append(TMRow(name, m, solver, rtol, "skipped", math.nan, 0, 0, 0, 0, math.nan, math.nan,
                                          math.inf, math.inf, 0.0, math.nan))
                        continue
                    status, wall, tr, t_reached = _run(p, horizon, solver, rtol, cap)
                    st = tr.stats
                    if status == "ok" and len(tr.jumps) == len(ref.jumps) and len(ref.jumps):
                        err_t = float(np.max(np.abs(tr.jumps.t - ref.jumps.t)))
                        err_F = float(np.max(np.abs(tr.jumps.F - ref.jumps.F) / ref.jumps.F))
                    elif status == "ok" and len(tr.jumps) == len(ref.jumps):
                        err_t = err_F = 0.0
                    else:
                        err_t = err_F = math.inf
                    n = max(st.n_steps, 1)
                    rows.append(TMRow(name, m, solver, rtol, status, wall, st.n_steps, st.n_rhs, st.n_jac, st.n_lu,
                                      1e6 * wall / n, 1e6 * wall / max(st.n_rhs, 1), err_t, err_F, float(t_reached),
                                      st.n_steps / max(float(t_reached), 1e-300)))
                    r = rows[-1]
                    say(f"{name:<9} m={m:<6.0e} {solver:<6} rtol={rtol:.0e} {status:<7} {wall:7.3f} s "
                        f"{r.steps:>7} steps {r.us_per_step:8.1f} us/step  err_t {err_t:.1e} s")
                    dead = status != "ok"
    return rows, refs


def step_rates(masses=MASSES, scenes=SCENES, horizon: float = 0.5, say=print) -> list[dict]:
    """Accepted steps per simulated second of the default solver at the default rtol (1e-8) over ``horizon``:
    what ``STEP_BUDGET["smooth"]`` must allow (``exact.simulate``'s default ``max_steps``)."""
    out = []
    for name, V, I, _ in scenes:
        for m in masses:
            status, t_end = "ok", horizon
            try:
                tr = exact.simulate(PeelParams(V=V, I=I, tape_mass=m), horizon, save="jumps", max_steps=10**7)
            except exact.ModelBreakdown as e:  # e.g. the front's arrest at large m: the rate up to there
                status, t_end, tr = f"breakdown ({e.reason})", float(e.t), e.partial
            st = tr.stats
            out.append(dict(scene=name, mass=m, solver=tr.solver, status=status, t_end=t_end,
                            steps_per_s=st.n_steps / t_end, us_per_step=1e6 * st.wall_time / max(st.n_steps, 1),
                            jumps=len(tr.jumps), wall=st.wall_time))
            say(f"steps/s {name} m={m:.0e} {tr.solver}: {st.n_steps / t_end:.3g} steps/s "
                f"{out[-1]['us_per_step']:.1f} us/step, {len(tr.jumps)} jumps in {t_end:.4g} s ({status})")
    return out


def plot_solvers(rows: list[dict], path: Path, scene: str = "V1 I1e-5", masses=(1e-7, 1e-3, 1e-1)) -> None:
    """Work precision (wall time against the jump-time error) of each solver at three masses of one scene."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(masses), figsize=(10.0, 3.4), dpi=110, sharey=True)
    for ax, m in zip(axes, masses):
        for solver, mk in zip(SOLVERS, "os^D"):
            ok = [r for r in rows if r["scene"] == scene and r["mass"] == m and r["solver"] == solver
                  and r["status"] == "ok" and math.isfinite(r["err_t"]) and r["err_t"] > 0]
            if ok:
                ax.loglog([r["err_t"] for r in ok], [r["wall"] for r in ok], mk + "-", label=solver)
            capped = [r for r in rows if r["scene"] == scene and r["mass"] == m and r["solver"] == solver
                      and r["status"] == "capped"]
            if capped:
                ax.axhline(capped[0]["wall"], ls=":", color="grey")
                ax.text(1e-12, capped[0]["wall"] * 0.7, f"{solver}: capped", fontsize=7, color="grey")
        ax.set_title(f"m = {m:g} kg ({scene})", fontsize=9)
        ax.set_xlabel("max |t_j − t_j(ref)| [s]")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("wall time [s] (0.05 s simulated)")
    axes[-1].legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=fig.dpi)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.tape_mass", description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, default=None, help="also write the rows and the references as JSON")
    ap.add_argument("--cap", type=float, default=5.0, help="wall-time cap of one run [s] (default 5)")
    ap.add_argument("--figure", type=Path, default=None, help="write the work-precision figure (PNG)")
    ap.add_argument("--quick", action="store_true", help="one scene, masses 1e-7, 1e-3, 1e-1, rtol 1e-7")
    args = ap.parse_args(argv)
    kw: dict = dict(cap=args.cap)
    if args.quick:
        kw.update(masses=(1e-7, 1e-3, 1e-1), rtols=(1e-7,), scenes=SCENES[:1])
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    rows, refs = tape_mass_benchmark(**kw)
    rates = step_rates(masses=kw.get("masses", MASSES), scenes=kw.get("scenes", SCENES))
    print(f"load average after: {os.getloadavg()[0]:.2f}\n")
    print(f"{'scene':<9} {'m [kg]':>7} {'fast time [s]':>13} | best solver at each rtol (wall s, err_t s)")
    for key, ref in refs.items():
        scene, m = key.split(" m=")
        best = []
        for rtol in kw.get("rtols", RTOLS):
            ok = [r for r in rows if r.scene == scene and f"{r.mass:g}" == m and r.rtol == rtol and r.status == "ok"]
            if ok:
                b = min(ok, key=lambda r: r.wall)
                best.append(f"{rtol:.0e}: {b.solver} {b.wall:.3f} ({b.err_t:.0e})")
        print(f"{scene:<9} {m:>7} {ref['fast_time']:13.1e} | " + "; ".join(best))
    if args.figure:
        plot_solvers([asdict(r) for r in rows], args.figure)
    if args.json:
        out = dict(rows=[asdict(r) for r in rows], references=refs, step_rates=rates)
        args.json.write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
