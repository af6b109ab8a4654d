"""The paper's reduced equations on laws other than fvV: approximate vs exact (do they hold for your tape?).

    python -m comparisons.benchmark.law_reduced [--json FILE]

The paper claims its branch-wise reductions reproduce the exact branch times and force changes "within 10 %"
(Sec. V) and that its conclusions do not depend on the form of f.  This measures the first claim on other laws:
for each run of :data:`LAW_RUNS` (the N-shaped cubic ``PeelForce.cubic()`` at V = 1.2 m/s, low and intermediate
inertia, and the same cubic sampled into a 40-point table, PCHIP in ln v), every complete segment of the exact
hybrid run of that law seeds every reduction of :data:`comparisons.DEFAULT_MODELS` integrated with the same law
(:func:`comparisons.statistics`), and one table prints the median and largest |relative error| of Δt and ΔF
per branch and reduction, with the failures; then the cost per accepted step of one AB reduction
(approxalpha + approxvdot) with fvV inlined and with the cubic through the law argument (best of 5, one process).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from peelapprox import PeelForce, PeelParams, reduced_segment
from peelapprox.io import fmt_number

from .. import RunSpec, statistics

__all__ = ["LAW_RUNS", "cubic_table", "main", "segment_cost"]


def cubic_table(n: int = 40, lo: float = 0.05, hi: float = 3.0) -> PeelForce:
    """``PeelForce.cubic()`` sampled at ``n`` log-spaced speeds in ``[lo, hi]`` m/s: a tabulated law whose exact
    reference is the cubic itself."""
    v = np.exp(np.linspace(np.log(lo), np.log(hi), n))
    return PeelForce.tabulated(v, PeelForce.cubic().f(v, 1.0))


#: The runs measured: the cubic (folds at 0.691 and 1.809 m/s; period-5 jump pattern from t ≈ 3 s at I = 1e-5),
#: at two inertias, and the tabulated cubic.
LAW_RUNS = (
    RunSpec("cubic V1.2 I1e-5", V=1.2, I=1e-5, t_transient=4.0, window=2.0, force=PeelForce.cubic(),
            regime="cubic, low inertia"),
    RunSpec("cubic V1.2 I1e-3", V=1.2, I=1e-3, t_transient=6.0, window=3.0, force=PeelForce.cubic(),
            regime="cubic, intermediate inertia"),
    RunSpec("table(cubic) V1.2 I1e-5", V=1.2, I=1e-5, t_transient=4.0, window=2.0, force=cubic_table(),
            regime="tabulated cubic, low inertia"),
)


def segment_cost(force: PeelForce, repeats: int = 5) -> tuple[float, int]:
    """``(µs per accepted step, steps)`` of one ``reduced_segment(..., "AB", approxalpha + approxvdot)`` (the whole
    call's wall time over its steps) at V = 1.2 (fvV: V = 1), I = 1e-5 from ``F_in = 0.99 f_min``, ``α_in = 0.01``
    (the best of ``repeats``; compiled before timing)."""
    from peelapprox import branch_structure

    p = PeelParams(V=1.2 if force.kind != "paper" else 1.0, I=1e-5, force=force)
    F_in = 0.99 * float(branch_structure(p.V, force=force).f_min)  # type: ignore[arg-type]
    call = lambda: reduced_segment(p, "AB", F_in=F_in, alpha_in=0.01, alphadot_in=0.0, rtol=1e-10, save="none")  # noqa: E731
    call()
    best, steps = np.inf, 0
    for _ in range(repeats):
        t0 = time.perf_counter()
        r = call()
        best, steps = min(best, (time.perf_counter() - t0) / max(r.n_steps, 1)), r.n_steps
    return 1e6 * best, steps


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.law_reduced", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", type=Path, help="also write the numbers as JSON")
    args = ap.parse_args(argv)
    res: dict = {"runs": {}, "us_per_step": {}}
    print("|relative error| of the reductions seeded from the exact segments of the same law: median / max "
          "(failed of n)")
    print(f"{'run':<24} {'branch':<6} {'reduction':<26} {'dt median':>10} {'dt max':>9} {'dF median':>10} "
          f"{'dF max':>9} {'failed':>7}")
    for spec in LAW_RUNS:
        rows = [r for r in statistics([spec]) if r.quantity in ("dt", "dF")]
        res["runs"][spec.name] = [r.as_dict() for r in rows]
        for r_dt, r_dF in zip(rows[0::2], rows[1::2]):
            print(f"{spec.name:<24} {r_dt.branch:<6} {r_dt.method:<26} {fmt_number(r_dt.median, 3):>10} "
                  f"{fmt_number(r_dt.max, 3):>9} {fmt_number(r_dF.median, 3):>10} {fmt_number(r_dF.max, 3):>9} "
                  f"{r_dt.n_failed:>3}/{r_dt.n:<3}")
    for name, law in (("paper (inlined)", PeelForce.paper()), ("cubic (law argument)", PeelForce.cubic()),
                      ("table(cubic) (law argument)", cubic_table())):
        res["us_per_step"][name] = segment_cost(law)
    print("\nAB reduction (approxalpha + approxvdot), us per accepted step (whole call / steps), best of 5: "
          + ", ".join(f"{k} {fmt_number(v, 3)} ({n} steps)" for k, (v, n) in res["us_per_step"].items()))
    if args.json:
        args.json.write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
