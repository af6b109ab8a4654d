"""Cost per call of the compiled tabulated law against the paper's law, through the law argument.

    python -m comparisons.benchmark.table_cost [--n N] [--rounds R] [--json FILE]

One run prints ns per call of ``peelapprox.kernels.table_law`` (tables of 20, 100 and 1000 points of the
paper's law at V = 1 m/s over v in [1e-3, 30] m/s, two tables of 100 points at V = 1.5 between V = 1 and 2, and
``PeelForce.smoothed`` of 40 and 100 of those points, a C⁴ quintic spline: its own kernel, the same guide)
and of ``peelapprox.kernels.paper_law`` (V = 1), each called through a loop compiled once for the law's function
type ``FunctionType(LAW_SIG)`` (as the solvers' drivers take it, so the call is indirect and not specialised
away), over the same points of ln v in the common range:

* **sweep**: u increasing in small steps across the range (a trajectory's access pattern: the interval search
  is well predicted);
* **run**: the ln v of a stick-slip run of the paper's law (``exact.simulate``, V = 1 m/s, I = 1e-2, 5 s,
  every accepted step), 12 points per step evenly between one step's ln v and the next (an approximation of
  the 12 DOP853 stages: near each other within a step, a median 0.09 apart in ln v from step to step, far across
  a jump), the sequence repeated up to ``--n`` calls;
* **random**: u uniformly random in the range (every search starts cold: the worst case);

in the form ``LAW_LNV`` (the hybrid field's) and, on the sweep, ``LAW_FP`` and ``LAW_FPP``.  Each figure is
the best of ``--rounds`` alternating rounds of ``--n`` calls, minus nothing (the loop's own cost is the same
for every law and is included).  The ratio to the paper's law is per call; the target is per step
(≤ 1.5× the paper's), which the lead measures on runs: a DOP853 step makes ~12 field evaluations of ~25 ns, so
a per-call difference Δ changes a step of ~800 ns by about 12 Δ (docs/design-peel-force-laws.md).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from numba import njit, types

from peelapprox import PeelForce, peel_force
from peelapprox.io import fmt_number
from peelapprox.kernels import (
    LAW_FP,
    LAW_FPP,
    LAW_LNV,
    LAW_TYPE,
    compiled_law,
    paper_coefficients,
    paper_law,
    table_coefficients,
    table_law,
)

__all__ = ["law_costs", "main", "run_points"]

#: The tables' v range [m/s] (the paper's folds at V = 1, about 0.5 and 8.6 m/s, lie inside).
V_LO, V_HI = 1e-3, 30.0


@njit(types.float64(LAW_TYPE, types.float64[::1], types.float64[::1], types.int64))
def _loop(law, coef, xs, form):
    """Σ of the law's three outputs over the points xs (NaN of LAW_FP skipped), the law an indirect call."""
    s = 0.0
    for i in range(xs.size):
        a, b, c = law(xs[i], coef, form)
        s += a + b + (0.0 if form == LAW_FP else c)
    return s


def _tables(n: int, V: float) -> tuple:
    v = np.logspace(math.log10(V_LO), math.log10(V_HI), n)
    return (V, v, peel_force(v, V))


def run_points(n: int) -> np.ndarray:
    """``n`` values of ln v along a stick-slip run of the paper's law, 12 per accepted step (module docstring)."""
    import exact
    from peelapprox import PeelParams

    u = np.log(exact.simulate(PeelParams(V=1.0, I=1e-2), 5.0, save="steps").v)
    u = np.clip(u, math.log(V_LO), math.log(V_HI))
    stages = (u[:-1, None] + (np.arange(12) / 12.0)[None, :] * np.diff(u)[:, None]).ravel()
    return np.ascontiguousarray(np.resize(stages, n))


def law_costs(n: int = 50_000, rounds: int = 31, seed: int = 1) -> dict[str, dict[str, float]]:
    """ns per call of each law (rows) in each pattern and form (columns), the best of ``rounds``."""
    laws = {"paper (V=1)": (paper_law, paper_coefficients(1.0))}
    for m in (20, 100, 1000):
        tables = PeelForce.tabulated(*_tables(m, 1.0)[1:]).tables
        laws[f"table {m} pts"] = (table_law, table_coefficients(tables, 1.0))
    two = PeelForce.tabulated(tables=[_tables(100, 1.0), _tables(100, 2.0)]).tables
    laws["2 tables x 100 (V=1.5)"] = (table_law, table_coefficients(two, 1.5))
    for m in (40, 100):  # PeelForce.smoothed: a C4 quintic spline in ln v, its own kernel
        cl = compiled_law(PeelForce.smoothed(*_tables(m, 1.0)[1:]), 1.0)
        laws[f"smoothed {m} pts"] = (cl.fn, cl.coef)
    u_lo, u_hi = math.log(V_LO), math.log(V_HI)
    sweep = np.linspace(u_lo, u_hi, n)
    rand = np.random.default_rng(seed).uniform(u_lo, u_hi, n)
    run = run_points(n)
    cases = {"LNV sweep": (sweep, LAW_LNV), "LNV run": (run, LAW_LNV), "LNV random": (rand, LAW_LNV),
             "FP sweep": (np.exp(sweep), LAW_FP), "FPP sweep": (np.exp(sweep), LAW_FPP)}
    for law, coef in laws.values():  # warm (the loop is compiled at import, for the law type)
        _loop(law, coef, sweep[:10], LAW_LNV)
    res: dict[str, dict[str, float]] = {name: {} for name in laws}
    for _ in range(rounds):  # alternate the laws in every round, keep the best
        for case, (xs, form) in cases.items():
            for name, (law, coef) in laws.items():
                t0 = time.perf_counter()
                _loop(law, coef, xs, form)
                dt = 1e9 * (time.perf_counter() - t0) / n
                res[name][case] = min(res[name].get(case, math.inf), dt)
    return res


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.table_cost",
                                 description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=50_000, help="calls per timing (default 50000)")
    ap.add_argument("--rounds", type=int, default=31, help="alternating rounds, the best kept (default 31: short "
                    "timings, many of them, so that the best is one the other processes of the machine did not slow)")
    ap.add_argument("--json", type=Path, default=None, help="also write the figures as JSON")
    args = ap.parse_args(argv)
    res = law_costs(args.n, args.rounds)
    paper = res["paper (V=1)"]
    cases = list(paper)
    print("ns per call (ratio to the paper's law)" + "".join(f"{c:>20}" for c in cases))
    for name, row in res.items():
        cells = "".join(f"{fmt_number(row[c], 3):>10} ({fmt_number(row[c] / paper[c], 3):>5}x)" for c in cases)
        print(f"  {name:<36}{cells}")
    print()
    for case in ("LNV sweep", "LNV run"):
        d = max(row[case] - paper[case] for row in res.values())
        print(f"largest {case} excess over the paper's law: {fmt_number(d, 3)} ns per call, i.e. about "
              f"{fmt_number(12 * d, 3)} ns per DOP853 step (12 field evaluations) of ~800 ns")
    if args.json:
        args.json.write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
