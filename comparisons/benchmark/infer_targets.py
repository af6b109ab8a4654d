"""How often :func:`exact.infer` recovers I and k from synthetic measured traces at seeded random points.

    python -m comparisons.benchmark.infer_targets --traces N --seed S [--seconds 20] [--max-wall 900]
        [--attractors 1] [--replicates 1] [--jobs 1] [--json FILE] [--csv FILE]

The target (the goal for ``infer``): I and k within 10 % (k within 5 % at a periodic low-inertia point), reported
identified, on multistable, quasi-periodic and chaotic traces drawn over the plane, not at chosen points.

* **Points** (``numpy.random.default_rng(seed)``): V uniform in [0.3, 4.8] m/s, I log-uniform in [2e-6, 8e-2]
  kg m^2 (the range of the reduced map's benchmarks), k log-uniform in [600, 1600] N/m; the paper's law, R at its
  default.
* **Trace**: the exact model from the solver's start, 30 s of transient, then ``--seconds`` at 10 kHz with 0.5 N
  of white noise and a 5 N linear drift over the trace (``Trajectory.as_series``, seed per trace): what a tensile
  machine records.
* **Class** (:func:`exact.attractor_set` at the truth, its defaults): ``multistable`` where two stick-slip
  attractors or more, one of them periodic, each hold at least 10 % of the starts (two aperiodic groups alone may
  be one attractor whose 20 s windows differ by more than the set's grouping tolerance: at V = 2.603 m/s,
  I = 0.0473 the set splits into six aperiodic groups); otherwise the kind of the attractor the solver's start
  reaches: ``periodic-low`` (periodic, I <= 1e-4), ``periodic`` (periodic, higher inertia), ``quasi-periodic``,
  ``chaotic``, ``aperiodic`` (no exponent); a point whose trace does not stick-slip is skipped (``no-stick-slip``).
* **Start**: I times a factor log-uniform in [1/2, 2], k times one in [1/1.25, 1.25] (seeded), both free;
  ``infer(series, start, ("I", "k"), max_wall=..., attractors=..., replicates=...)`` with its other defaults,
  its grid serial in the trace's own process.
* **Measures** per class and overall: *recovered* (both within the tolerances above), *identified* (both verdicts),
  *hit* (both: the target), and the verdict's calibration: the share of identified fits that are recovered (an
  identified verdict should be right) and of recovered fits that are identified.  Each row also carries the 95 %
  intervals (``I_lo``, ``I_hi``, ``k_lo``, ``k_hi``) and ``inside``: whether both hold the truth.

``--jobs`` runs that many traces at once in separate processes (each trace's runs are serial): the rows do not
depend on it.  Every trace's line goes to stderr as it ends; the summary to stdout.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

import numpy as np

from peelapprox.io import fmt_number

from ._rows import add_row_files, write_row_files

__all__ = ["CLASSES", "LOW_INERTIA", "classify", "draw", "main", "run_trace", "summarise"]

#: The classes of a trace, in the summary's order.
CLASSES = ("periodic-low", "periodic", "multistable", "quasi-periodic", "chaotic", "aperiodic")
#: The inertia [kg m^2] at or below which a periodic point is "low-inertia" (its k target is 5 %).
LOW_INERTIA = 1e-4
#: A second attractor counts for ``multistable`` from this share of the set's starts.
MIN_SHARE = 0.1


def draw(n: int, seed: int) -> list[dict[str, float]]:
    """``n`` seeded truths and starts: V, I, k and the start's I0, k0 (module docstring)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        V = float(f"{rng.uniform(0.3, 4.8):.4g}")
        I = float(f"{10 ** rng.uniform(math.log10(2e-6), math.log10(8e-2)):.4g}")
        k = float(f"{10 ** rng.uniform(math.log10(600.0), math.log10(1600.0)):.4g}")
        fI, fk = math.exp(rng.uniform(-math.log(2.0), math.log(2.0))), math.exp(rng.uniform(-math.log(1.25),
                                                                                              math.log(1.25)))
        out.append({"V": V, "I": I, "k": k, "I0": I * fI, "k0": k * fk})
    return out


def classify(aset: Any, I: float) -> str:
    """The trace's class from the attractor set at the truth (module docstring)."""
    ss = [a for a in aset.attractors if a.is_stick_slip and a.share >= MIN_SHARE]
    if len(ss) >= 2 and any(a.kind == "periodic" for a in ss):
        return "multistable"
    solver = next((a for a in aset.attractors if "solver" in a.starts), None)
    if solver is None or not solver.is_stick_slip:
        return "no-stick-slip"
    if solver.kind == "periodic":
        return "periodic-low" if I <= LOW_INERTIA else "periodic"
    return str(solver.kind)


def run_trace(i: int, truth: dict[str, float], seed: int, seconds: float, max_wall: float, attractors: int,
              replicates: int = 1) -> dict[str, Any]:
    """One trace's row: its truth, start, class, the fit's values and verdicts, and the measures."""
    import exact
    from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded, infer

    V, I, k = truth["V"], truth["I"], truth["k"]
    p = PeelParams(V=V, I=I, k=k)
    row: dict[str, Any] = {"trace": i, **truth}
    t0 = time.perf_counter()
    aset = exact.attractor_set(p, workers=0)
    row["class"] = classify(aset, I)
    row["set"] = "; ".join(f"{a.label} {100 * a.share:.0f}%" for a in aset.attractors)
    row["set_s"] = time.perf_counter() - t0
    if row["class"] == "no-stick-slip":
        return row
    try:
        tr = exact.simulate(p, 30.0 + seconds, t_eval=(30.0 + np.arange(int(round(seconds * 1e4))) / 1e4).tolist())
        series = tr.as_series(1e4, noise=0.5, drift=5.0, seed=seed * 1000 + i)
        t0 = time.perf_counter()
        res = infer(series, PeelParams(V=V, I=truth["I0"], k=truth["k0"]), ("I", "k"), max_wall=max_wall,
                    attractors=attractors, replicates=replicates, progress=False, executor="serial")
    except (ModelBreakdown, SolverBudgetExceeded, ValueError) as exc:  # a trace infer refuses: recorded
        row.update({"status": f"refused: {type(exc).__name__}: {exc}"[:300], "recovered": False, "identified": False,
                    "hit": False})
        return row
    k_tol = 0.05 if row["class"] == "periodic-low" else 0.10
    eI, ek = res.values["I"] / I - 1.0, res.values["k"] / k - 1.0
    recovered = abs(eI) <= 0.10 and abs(ek) <= k_tol
    identified = all(res.identified.values())
    row.update({"status": res.status, "I_fit": res.values["I"], "k_fit": res.values["k"], "I_err": eI, "k_err": ek,
                "k_tol": k_tol, "chi2": res.chi2, "dof": res.dof, "identified_I": res.identified["I"],
                "identified_k": res.identified["k"], "recovered": recovered, "identified": identified,
                "hit": recovered and identified, "runs": res.n_evaluations, "infer_s": time.perf_counter() - t0,
                "attractor": "; ".join(res.attractors), "verdict_I": res.verdicts["I"][:200]})
    for name in ("I", "k"):  # the 95 % intervals, and whether both hold the truth
        lo, hi = res.intervals[name] or (math.nan, math.nan)
        row.update({f"{name}_lo": lo, f"{name}_hi": hi})
    row["inside"] = bool(row["I_lo"] <= I <= row["I_hi"] and row["k_lo"] <= k <= row["k_hi"])
    return row


def _share(rows: Sequence[dict[str, Any]], key: str, given: str | None = None) -> str:
    pool = [r for r in rows if given is None or r.get(given)]
    if not pool:
        return "-"
    n = sum(bool(r.get(key)) for r in pool)
    return f"{n}/{len(pool)} ({100 * n / len(pool):.0f} %)"


def summarise(rows: Sequence[dict[str, Any]]) -> str:
    """The summary table: per class and overall, hits, recovered, identified and the verdict's calibration."""
    fitted = [r for r in rows if "recovered" in r]
    lines = [f"{'class':<15} {'n':>3}  {'hit (target)':<14} {'recovered':<14} {'identified':<14} "
             f"{'recovered | identified':<23} {'identified | recovered':<23}"]
    for c in (*CLASSES, "all"):
        sub = fitted if c == "all" else [r for r in fitted if r["class"] == c]
        if not sub:
            continue
        lines.append(f"{c:<15} {len(sub):>3}  {_share(sub, 'hit'):<14} {_share(sub, 'recovered'):<14} "
                     f"{_share(sub, 'identified'):<14} {_share(sub, 'recovered', 'identified'):<23} "
                     f"{_share(sub, 'identified', 'recovered'):<23}")
    skipped = len(rows) - len(fitted)
    if skipped:
        lines.append(f"skipped (no stick-slip at the truth): {skipped}")
    walls = [r["infer_s"] for r in fitted if "infer_s" in r]
    if walls:
        runs = int(np.median([r["runs"] for r in fitted if "runs" in r]))
        lines.append(f"infer wall: median {fmt_number(float(np.median(walls)), 3)} s, max "
                     f"{fmt_number(max(walls), 3)} s; runs median {runs}")
    return "\n".join(lines)


def _line(r: dict[str, Any]) -> str:
    head = f"[trace {r['trace']}] V={r['V']:g} I={r['I']:.4g} k={r['k']:.4g} ({r['class']}; {r['set']})"
    if "I_fit" not in r:
        return head + (f": {r['status']}" if "status" in r else ": skipped")
    return (head + f": start I0={r['I0']:.4g} k0={r['k0']:.4g} -> I {100 * r['I_err']:+.1f} %, "
            f"k {100 * r['k_err']:+.1f} %"
            f", identified I {r['identified_I']} k {r['identified_k']}, chi2 {fmt_number(r['chi2'], 3)} on {r['dof']}, "
            f"{r['status']}, {r['runs']} runs, {fmt_number(r['infer_s'], 3)} s")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.infer_targets", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--traces", type=int, default=8, help="random traces (8)")
    ap.add_argument("--seed", type=int, default=35, help="the points' seed (35)")
    ap.add_argument("--seconds", type=float, default=20.0, help="each trace's duration at 10 kHz (20)")
    ap.add_argument("--max-wall", type=float, default=900.0, help="each infer call's budget [s] (900)")
    ap.add_argument("--attractors", type=int, default=1, help="infer's attractors= (1)")
    ap.add_argument("--replicates", type=int, default=1, help="infer's replicates= (1)")
    ap.add_argument("--jobs", type=int, default=1, help="traces at once, in processes (1)")
    add_row_files(ap)
    a = ap.parse_args(argv)
    if (a.traces < 1 or a.jobs < 1 or not 1 <= a.attractors <= 8 or not 1 <= a.replicates <= 8
            or not 0.5 <= a.seconds <= 200 or a.max_wall <= 0):
        ap.error("--traces and --jobs must be >= 1, --attractors and --replicates in [1, 8], --seconds in "
                 "[0.5, 200], --max-wall > 0")
    truths = draw(a.traces, a.seed)
    args = [(i, t, a.seed, a.seconds, a.max_wall, a.attractors, a.replicates) for i, t in enumerate(truths)]
    rows: list[dict[str, Any]] = []
    t0 = time.perf_counter()
    if a.jobs == 1:
        for x in args:
            rows.append(run_trace(*x))
            print(_line(rows[-1]), file=sys.stderr, flush=True)
    else:
        with ProcessPoolExecutor(a.jobs) as pool:
            for fut in as_completed([pool.submit(run_trace, *x) for x in args]):
                rows.append(fut.result())
                print(_line(rows[-1]), file=sys.stderr, flush=True)
    rows.sort(key=lambda r: r["trace"])
    print(f"infer_targets: {a.traces} traces (seed {a.seed}), {a.seconds:g} s each, attractors={a.attractors}, "
          f"replicates={a.replicates}, "
          f"max_wall {a.max_wall:g} s; {fmt_number(time.perf_counter() - t0, 3)} s in all")
    print(summarise(rows))
    write_row_files(a, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
