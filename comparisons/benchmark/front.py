"""The peel front's cost per step against N: ``python -m comparisons.benchmark.front``.

The goal: a step at N = 1e4 costs at most 150 times one at N = 100.

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
import math
import sys

import numpy as np

import exact
from peelapprox import FrontParams, PeelParams
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded

__all__ = ["front_cost", "convergence", "gamma_sweep", "main"]

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


def convergence(ns: tuple[int, ...] = (16, 48, 144, 432, 1296), t_star: float = 1e-3, width: float = 0.02,
                K: float = 1e-2, G: float = 1e-5, delta: float = 0.05, rtol: float = 1e-11) -> list[dict]:
    """The spatial convergence order of the front towards its continuum limit ``K b u_yy + G b u̇_yy``.

    Continuum scaling ``k_c = K N/b``, ``Γ = G N/b`` (b = ``width`` [m]); free ends; the strips at the cell
    centres ``y_j = (j + 1/2) b/N``; the start is the tape-mass model's (V = 1, I = 1e-2, m = 1e-3 kg, F0 = 250 N)
    with the stretches ``F_j = F0 (1 + δ cos(π y_j / b))`` (smooth: the first Neumann mode, every strip on AB).
    At ``t_star`` (before the first jump)
    each N's v_j is compared with the next finer run's (3N strips: the centre of coarse cell j is the centre of
    fine cell 3j + 1, so no interpolation enters; strips without bonds would give e_N = 0 exactly):
    ``e_N = max_j |v_N,j - v_3N,3j+1|``, and ``order = log3(e_N / e_3N)``.  rtol 1e-11 keeps the time error
    below the smallest e_N."""
    base = PeelParams(V=1.0, I=1e-2, tape_mass=1e-3)
    vs = {}
    for n in ns:
        fp = FrontParams(base=base, N=n, k_c=K * n / width, Gamma=G * n / width)
        s0 = exact.initial_state(base, F0=250.0)
        y = (np.arange(n) + 0.5) / n
        y0 = np.concatenate([[s0.alpha, s0.omega, 0.0], s0.F * (1 + delta * np.cos(np.pi * y)), np.full(n, s0.v),
                             [0.0, 0.0]])
        tr = exact.simulate_front(fp, t_star, rtol=rtol, y0=y0, dt_save=t_star, max_wall=None)
        vs[n] = tr.front_v[-1]
    rows = []
    for n in ns[:-1]:
        fine = vs.get(3 * n)
        if fine is None:
            continue
        e = float(np.max(np.abs(vs[n] - fine[1::3])))
        rows.append({"N": n, "error": e, "v_range": float(np.ptp(vs[n]))})
    for a, b in zip(rows, rows[1:]):
        a["order"] = math.log(a["error"] / b["error"], 3)
    return rows


def gamma_sweep(gammas: tuple[float, ...] = (1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0), seeds: tuple[int, ...] = (0, 1),
                n: int = 32, t_end: float = 0.06, t_transient: float = 0.01) -> list[dict]:
    """The front's pattern against the AE dissipation γ (V = 1, I = 1e-2, m = 1e-3 kg, κ = 0.1, δ₀ = 1e-2, free ends,
    N = 32, rtol 1e-8, points every 1e-5 s from ``t_transient``): per (γ, seed) the pattern class and its
    averages (``FrontTrajectory.pattern``), the mean jumps, local switches per strip and second, AE energy; a run
    that ends in a ModelBreakdown (a strip at rest) is summarised up to its end, with ``stop`` saying so."""
    base = PeelParams(V=1.0, I=1e-2, tape_mass=1e-3)
    rows = []
    for g in gammas:
        for seed in seeds:
            fp = FrontParams(base=base, N=n, gamma=g, kappa=0.1, delta0=1e-2, seed=seed)
            stop = ""
            try:
                tr = exact.simulate_front(fp, t_end, dt_save=1e-5, t_transient=t_transient, store_front=False,
                                          max_wall=None)
            except ModelBreakdown as e:  # a strip at rest (weak coupling): the run's end, recorded
                tr, stop = e.partial, f"{e.reason} at t={e.t:.4g} s, strip {e.state.get('strip')}"
            if len(tr.t) < 2:
                rows.append({"gamma": g, "seed": seed, "pattern": "-", "W": math.nan, "mixed": math.nan,
                             "walls": math.nan, "jumps": len(tr.jumps), "switches_per_strip_s": math.nan,
                             "ae_energy": math.nan, "steps": tr.stats.n_steps, "wall_s": tr.stats.wall_time,
                             "stop": stop})
                continue
            p = tr.pattern()
            span = float(tr.t[-1] - tr.t[0])
            rows.append({"stop": stop, "gamma": g, "seed": seed, "pattern": p.label, "W": p.roughness,
                         "mixed": p.mixed_fraction,
                         "walls": p.walls, "jumps": len(tr.jumps), "switches_per_strip_s": len(tr.local_switches)
                         / (n * span), "ae_energy": float(tr.ae_energy[-1] - tr.ae_energy[0]),
                         "steps": tr.stats.n_steps, "wall_s": tr.stats.wall_time})
    return rows


def e_time(tr) -> float:
    """The simulated time a (partial) run reached: its last stored grid point."""
    return float(tr.t[-1]) if len(tr.t) else 0.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.front", description=__doc__.splitlines()[0])
    ap.add_argument("--json", help="write the rows to this JSON file")
    ap.add_argument("--scale", type=float, default=1.0, help="multiply the step counts (default 1)")
    ap.add_argument("--convergence", action="store_true", help="measure the spatial convergence order instead")
    ap.add_argument("--gamma-sweep", action="store_true", help="the pattern against gamma instead")
    a = ap.parse_args(argv)
    if a.gamma_sweep:
        print("| gamma | seed | pattern | <W> | Phi_mix | <n_dw> | mean jumps | switches/(strip s) | E_AE [J] "
              "| steps |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for r in gamma_sweep():
            print(f"| {r['gamma']:g} | {r['seed']} | {r['pattern']} | {r['W']:.3g} | {r['mixed']:.3g} | "
                  f"{r['walls']:.3g} | {r['jumps']} | {r['switches_per_strip_s']:.3g} | {r['ae_energy']:.3g} | "
                  f"{r['steps']} | {r['stop']} |", flush=True)
        return 0
    if a.convergence:
        print("| N | max|v_N - v_3N| [m/s] | spread of v_N [m/s] | order |\n|---|---|---|---|")
        for r in convergence():
            print(f"| {r['N']} | {r['error']:.3e} | {r['v_range']:.3e} | {r.get('order', float('nan')):.3f} |")
        return 0
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
