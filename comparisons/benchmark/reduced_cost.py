"""Cost of the reduced equations: one branch segment and one regime estimate.

    python -m comparisons.benchmark.reduced_cost [--repeats N] [--csv out.csv]

Targets (issue "reduced branch-wise equations"): one reduced segment <= 1 ms,
``peelapprox.estimate`` <= 5 ms per call after the first.  Methodology: one
untimed warm-up per case (compilation and first-call costs are reported
separately), then the median and minimum wall time over repeats, all in one
run.  Cases are the paper's Sec. V seeds (with the corrected v_in = 0.00188
and α_in = -0.239, see docs/paper-notes.md) and a low-inertia AB segment with
~20 inertial oscillations, the most step-hungry case.
"""

from __future__ import annotations

import argparse
import csv
import statistics
import subprocess
import sys
import time

from peelapprox import PeelParams, estimate, reduced_segment

__all__ = ["CASES", "first_call_cost", "main"]

P2 = PeelParams(V=1.0, I=1e-2)
P5 = PeelParams(V=1.0, I=1e-5)
P4 = PeelParams(V=4.0, I=1e-2)

CASES = [
    ("I=1e-2 AB point a, approxalpha+approxvdot", P2, "AB",
     dict(F_in=186.95, alpha_in=0.0599, alphadot_in=9.7, v_in=0.00188, v_f=0.4)),
    ("I=1e-2 AB point a, sinusoid+approxvdot", P2, "AB",
     dict(F_in=186.95, alpha_in=0.0599, alphadot_in=9.7, v_in=0.00188, v_f=0.4, alpha_model="sinusoid")),
    ("I=1e-2 AB point e, genalpha+fullvdot", P2, "AB",
     dict(F_in=276.53, alpha_in=-0.239, alphadot_in=11.9, v_in=0.00188, v_f=0.4, alpha_model="genalpha",
          v_equation="fullvdot")),
    ("I=1e-2 CD cascade, airy2+approxvdot", P2, "CD",
     dict(F_in=295.6, alpha_in=-0.0304, alphadot_in=-160.0, v_in=15.54, v_f=8.7, alpha_model="airy2")),
    ("I=1e-5 AB to the fold, approxalpha+approxvdot", P5, "AB",
     dict(F_in=190.69, alpha_in=0.0458, alphadot_in=67.56)),
    ("I=1e-5 AB to the fold, genalpha+fullvdot", P5, "AB",
     dict(F_in=190.69, alpha_in=0.0458, alphadot_in=67.56, alpha_model="genalpha", v_equation="fullvdot")),
]


def _time(fn, repeats):
    fn()  # warm-up, untimed
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), min(ts), out


def first_call_cost() -> float:
    """Seconds for a fresh process to import peelapprox and run one segment (numba cache warm)."""
    code = ("import time; t=time.perf_counter(); from peelapprox import PeelParams, reduced_segment; "
            "reduced_segment(PeelParams(V=1, I=1e-2), 'AB', F_in=186.95, alpha_in=0.06, alphadot_in=9.7); "
            "print(time.perf_counter()-t)")
    return float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=50)
    ap.add_argument("--csv", help="write the rows to this CSV")
    args = ap.parse_args(argv)
    rows = []
    for name, p, br, kw in CASES:
        med, best, seg = _time(lambda: reduced_segment(p, br, save="none", **kw), args.repeats)
        rows.append(dict(case=name, median_ms=med * 1e3, min_ms=best * 1e3, steps=seg.n_steps, rhs=seg.n_rhs,
                         dt=seg.dt, dF=seg.dF))
    for p in (P2, P5, P4):
        med, best, e = _time(lambda: estimate(p), args.repeats)
        rows.append(dict(case=f"estimate(V={p.V:g}, I={p.I:g}) [{e.label}]", median_ms=med * 1e3,
                         min_ms=best * 1e3, steps="", rhs="", dt="", dF=""))
    print("| case | median [ms] | min [ms] | steps | RHS evals | Δt [s] | ΔF [N] |\n|---|---|---|---|---|---|---|")
    for r in rows:
        dt = f"{r['dt']:.5g}" if r["dt"] != "" else ""
        dF = f"{r['dF']:.4g}" if r["dF"] != "" else ""
        print(f"| {r['case']} | {r['median_ms']:.3f} | {r['min_ms']:.3f} | {r['steps']} | {r['rhs']} | {dt} | {dF} |")
    seg_worst = max(r["median_ms"] for r in rows if r["steps"] != "")
    est_worst = max(r["median_ms"] for r in rows if r["steps"] == "")
    fc = first_call_cost()
    print("\n| quantity | measured | target |\n|---|---|---|")
    print(f"| slowest reduced segment (median) | {seg_worst:.3f} ms | <= 1 ms |")
    print(f"| slowest estimate() after the first call (median) | {est_worst:.3f} ms | <= 5 ms |")
    print(f"| fresh process: import + first segment (numba cache warm) | {fc:.2f} s | - |")
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        print(f"wrote {args.csv}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
