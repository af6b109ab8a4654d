"""The peel front's cost per step against N (issue 39's scaling target): ``python -m comparisons.benchmark.front``.

For N = 1e2, 1e3, 1e4 strips (a mixed front: V = 1, I = 1e-2, m = 1e-3 kg, γ = 0.05, κ = 0.1, δ₀ = 1e-2, free
ends; rtol 1e-8; output every 1e-4 s, no front stored) it runs a fixed number of accepted steps from the same
start (``max_steps``; the partial trajectory of the budget stop carries the counters) after one warm-up call that
loads the compiled loop, and prints steps, field evaluations, µs per step, µs per step and strip, the simulated
time reached and simulated seconds per wall hour, then the cost ratio N = 1e4 : N = 1e2 (target ≤ 150).
``--json PATH`` writes the rows.
"""

from __future__ import annotations

import argparse
import json
import sys

import exact
from peelapprox import FrontParams, PeelParams
from peelapprox.errors import SolverBudgetExceeded

__all__ = ["front_cost", "main"]

STEPS = {100: 4000, 1000: 1000, 10000: 200}


def front_cost(n: int, steps: int) -> dict:
    """One row: the cost of ``steps`` accepted steps of an N-strip mixed front (module docstring)."""
    fp = FrontParams(base=PeelParams(V=1.0, I=1e-2, tape_mass=1e-3), N=n, gamma=0.05, kappa=0.1, delta0=1e-2)
    try:
        tr = exact.simulate_front(fp, 1.0, rtol=1e-8, dt_save=1e-4, store_front=False, max_steps=steps,
                                  max_wall=None)
    except SolverBudgetExceeded as e:
        tr = e.partial
    s = tr.stats
    t_reached = e_time(tr)
    us = 1e6 * s.wall_time / max(s.n_steps, 1)
    return {"N": n, "steps": s.n_steps, "rhs": s.n_rhs, "rejected": s.n_rejected, "wall_s": s.wall_time,
            "us_per_step": us, "ns_per_step_and_strip": 1e3 * us / n, "t_reached": t_reached,
            "sim_s_per_wall_hour": 3600.0 * t_reached / s.wall_time if s.wall_time > 0 else float("nan")}


def e_time(tr) -> float:
    """The simulated time a (partial) run reached: its last stored grid point."""
    return float(tr.t[-1]) if len(tr.t) else 0.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.front", description=__doc__.splitlines()[0])
    ap.add_argument("--json", help="write the rows to this JSON file")
    ap.add_argument("--scale", type=float, default=1.0, help="multiply the step counts (default 1)")
    a = ap.parse_args(argv)
    front_cost(10, 10)  # load the compiled loop (not timed)
    rows = []
    print("| N | steps | field evals | us/step | ns/(step strip) | simulated s | simulated s per wall hour |")
    print("|---|---|---|---|---|---|---|")
    for n, steps in STEPS.items():
        r = front_cost(n, max(10, int(steps * a.scale)))
        rows.append(r)
        print(f"| {n} | {r['steps']} | {r['rhs']} | {r['us_per_step']:.1f} | {r['ns_per_step_and_strip']:.1f} | "
              f"{r['t_reached']:.3g} | {r['sim_s_per_wall_hour']:.3g} |", flush=True)
    ratio = rows[-1]["us_per_step"] / rows[0]["us_per_step"]
    print(f"\ncost per step, N = 1e4 : N = 1e2 = {ratio:.1f} (target <= 150)")
    if a.json:
        with open(a.json, "w", encoding="utf-8") as fh:
            json.dump({"rows": rows, "ratio_1e4_1e2": ratio}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
