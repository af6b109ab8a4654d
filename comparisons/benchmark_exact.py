"""Work-precision benchmark of the exact solvers, timed in one run.

    python -m comparisons.benchmark_exact [--quick] [--csv out.csv]

Methodology (as the SciML work-precision benchmarks): one untimed warm-up per
configuration, then the minimum wall time over repeats.  Error = max absolute
error of the jump times over the jumps in the horizon, against the hybrid
solver at rtol 1e-13 (the ε → 0 reference), cross-checked against rtol 1e-12.
The regularised scheme carries its ε-bias (fold-passage delay) in this error.
Prints markdown tables (pasted into docs/performance.md) and optionally a CSV.
"""

from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from exact import SolverFailure, compile_kernels, simulate
from peelapprox import PeelParams


def _timed(fn, repeats):
    fn()  # warm-up, untimed
    best = np.inf
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _err(tr, ref):
    n = min(len(tr.jumps), len(ref.jumps))
    if n == 0 or len(tr.jumps) != len(ref.jumps):
        return float("nan"), n
    return float(np.max(np.abs(tr.jumps.t[:n] - ref.jumps.t[:n]))), n


def work_precision(params, horizon, rtols, reg_solvers, reg_rtols, repeats):
    ref = simulate(params, horizon, rtol=1e-13, save="jumps")
    chk = simulate(params, horizon, rtol=1e-12, save="jumps")
    rows = [dict(method="reference check (hybrid rtol 1e-12 vs 1e-13)", rtol=1e-12, error=_err(chk, ref)[0],
                 time=np.nan, steps=chk.stats.n_steps, jumps=len(chk.jumps))]
    for rt in rtols:
        t, tr = _timed(lambda: simulate(params, horizon, rtol=rt, save="jumps"), repeats)
        rows.append(dict(method="hybrid", rtol=rt, error=_err(tr, ref)[0], time=t, steps=tr.stats.n_steps,
                         jumps=len(tr.jumps)))
    for solver in reg_solvers:
        for rt in reg_rtols:
            rep = 1 if solver != "LSODA" else repeats
            name = f"regularized {solver} eps=1e-7"
            try:
                t, tr = _timed(lambda: simulate(params, horizon, method="regularized", solver=solver, rtol=rt,
                                                eps=1e-7, save="jumps"), rep)
            except SolverFailure as exc:
                rows.append(dict(method=f"{name} FAILED at t={exc.t:.4g} s", rtol=rt, error=np.nan, time=np.nan,
                                 steps=0, jumps=0))
                continue
            rows.append(dict(method=name, rtol=rt, error=_err(tr, ref)[0], time=t, steps=tr.stats.n_steps,
                             jumps=len(tr.jumps)))
    return rows


def compile_costs():
    """Cold compile and cached load of the kernels, each in a fresh process."""
    code = "import time; t=time.perf_counter(); import exact; exact.compile_kernels(); print(time.perf_counter()-t)"
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        cold = float(subprocess.check_output([sys.executable, "-c", code], env=env).decode().split()[-1])
        warm = float(subprocess.check_output([sys.executable, "-c", code], env=env).decode().split()[-1])
    return cold, warm


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer tolerances and no Radau/BDF sweep")
    ap.add_argument("--csv", help="write all rows to this CSV")
    args = ap.parse_args(argv)
    compile_kernels()
    repeats = 3 if args.quick else 5
    all_rows = []

    print("## Work-precision, V=1, I=1e-5, horizon 0.12 s (4 jumps)\n")
    rows = work_precision(PeelParams(V=1.0, I=1e-5), 0.12, [1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
                          ["LSODA"] if args.quick else ["Radau", "BDF", "LSODA"], [1e-6, 1e-9], repeats)
    all_rows += [dict(scene="V=1,I=1e-5", **r) for r in rows]
    print("| method | rtol | max jump-time error [s] | CPU time [s] | steps |\n|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['method']} | {r['rtol']:.0e} | {r['error']:.2e} | {r['time']:.4g} | {r['steps']} |")
    hyb = [r for r in rows if r["method"] == "hybrid"]
    print("\nSpeed-up of the hybrid solver at equal or better error (fastest hybrid run whose error <= the "
          "regularised run's error):\n")
    print("| regularised run | its error [s] | its time [s] | hybrid time [s] | ratio |\n|---|---|---|---|---|")
    for r in rows:
        if r["method"].startswith("regularized") and np.isfinite(r["error"]):
            ok = [h for h in hyb if h["error"] <= r["error"]]
            if ok:
                h = min(ok, key=lambda x: x["time"])
                print(f"| {r['method']} rtol {r['rtol']:.0e} | {r['error']:.2e} | {r['time']:.4g} | {h['time']:.3g} | "
                      f"{r['time'] / h['time']:.0f}x |")

    print("\n## Targets\n")
    print("| quantity | measured | target |\n|---|---|---|")
    p = PeelParams(V=1.0, I=1e-5)
    t1, tr1 = _timed(lambda: simulate(p, 1.0, rtol=1e-8, save="jumps"), repeats)
    print(f"| 1 s of V=1, I=1e-5 at rtol 1e-8 | {t1:.4f} s ({tr1.stats.n_steps} steps, {len(tr1.jumps)} jumps) | <= 0.05 s |")
    print(f"| time per accepted step (that run) | {1e6 * t1 / tr1.stats.n_steps:.2f} us "
          f"({tr1.stats.n_rhs / tr1.stats.n_steps:.1f} RHS/step, {tr1.stats.n_rejected} rejected) | <= 2 us |")
    p4 = PeelParams(V=4.0, I=1e-2)
    t4, tr4 = _timed(lambda: simulate(p4, 200.0, rtol=1e-8, save="jumps"), 1 if not args.quick else 1)
    print(f"| V=4, I=1e-2, 200 s, rtol 1e-8, jumps only | {t4:.2f} s ({len(tr4.jumps)} jumps, {tr4.stats.n_steps} steps,"
          f" {1e6 * t4 / tr4.stats.n_steps:.2f} us/step) | <= 10 s, > 100000 jumps |")
    cold, warm = compile_costs()
    print(f"| kernel compilation, cold (empty numba cache), fresh process | {cold:.1f} s | reported separately |")
    print(f"| kernel load from numba's on-disk cache, fresh process | {warm:.2f} s | |")
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=["scene", "method", "rtol", "error", "time", "steps", "jumps"])
            w.writeheader()
            w.writerows(all_rows)
        print(f"\nwrote {args.csv}", file=sys.stderr)


if __name__ == "__main__":
    main()
