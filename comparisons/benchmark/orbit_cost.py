"""Cost of a periodic orbit with its Floquet multipliers (docs/orbits.md): Newton on the AB→CD section map.

    python -m comparisons.benchmark.orbit_cost [--json FILE]

For each scene: a run past its transient seeds ``exact.periodic_orbit`` (its jumps give the period n and the
start); the orbit is then found again from that run, timed (the best of 3, the seed run excluded), with the
Newton iterations, the closing residual, the multipliers' moduli and the integration steps; then a
200-point continuation (:data:`CONTINUATIONS`), timed.  The targets: one orbit with multipliers for
n <= 10 in <= 50 ms; a 200-point continuation in <= 10 s.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import exact
from peelapprox import PeelForce, PeelParams
from peelapprox.io import fmt_number

__all__ = ["ADAPTIVE", "CONTINUATIONS", "SCENES", "continuation_costs", "main", "orbit_costs"]

#: (name, params, transient [s], n or None): stable orbits of the cubic and of fvV, and an unstable one.
SCENES = (
    ("cubic V1.2 I3e-5", PeelParams(V=1.2, I=3e-5, force=PeelForce.cubic()), 30.0, None),
    ("cubic V1.2 I1e-5", PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic()), 30.0, None),
    ("fvV V1 I1e-5", PeelParams(V=1.0, I=1e-5), 40.0, None),
    ("fvV V1 I1e-2", PeelParams(V=1.0, I=1e-2), 60.0, None),
    ("fvV V2 I1e-4 (chaotic)", PeelParams(V=2.0, I=1e-4), 30.0, 2),
)


#: (name, params, parameter, stop): 200 equal steps from the orbit at params to stop.
CONTINUATIONS = (
    ("cubic period 1 in I", PeelParams(V=1.2, I=3e-5, force=PeelForce.cubic()), "I", 2.2e-5),
    ("fvV period 8 in V (I = 1e-2)", PeelParams(V=1.0, I=1e-2), "V", 1.1),
)


#: (name, params, parameter, stop): adaptive steps (the defaults) from the orbit at params towards stop, through
#: bifurcations and the pseudo-arclength steps round a fold, to the branch's end.
ADAPTIVE = (
    ("fvV period 5 in V (I = 1e-3): 2 PD, NS, fold, grazing", PeelParams(V=1.0, I=1e-3), "V", 0.5),
    ("fvV period 3 in V (I = 1e-5): crest", PeelParams(V=1.0, I=1e-5), "V", 1.5),
)


def continuation_costs() -> list[dict]:
    """Seconds of a 200-point continuation (:data:`CONTINUATIONS`) and of the adaptive ones (:data:`ADAPTIVE`),
    the start orbit excluded."""
    rows = []
    for name, p, par, stop in CONTINUATIONS:
        o = exact.periodic_orbit(p)
        h = abs(stop - float(getattr(p, par))) / 199
        t0 = time.perf_counter()
        b = exact.continue_orbit(o, par, stop=stop, step=h, max_step=h, max_points=200)
        rows.append(dict(branch=name, points=len(b.points), stopped=b.stopped, s=time.perf_counter() - t0))
    for name, p, par, stop in ADAPTIVE:
        o = exact.periodic_orbit(p, t_transient=40.0)
        t0 = time.perf_counter()
        b = exact.continue_orbit(o, par, stop=stop, max_points=300)
        rows.append(dict(branch=name, points=len(b.points), stopped=b.stopped, s=time.perf_counter() - t0))
    return rows


def orbit_costs(rounds: int = 3) -> list[dict]:
    """One row per scene of :data:`SCENES` (module docstring)."""
    rows = []
    for name, p, t_tr, n in SCENES:
        seed = exact.simulate(p, t_tr + 20.0, rtol=1e-10, save="jumps", t_transient=t_tr)
        exact.periodic_orbit(p, start=seed, n=n)  # compiles (or loads) the drivers
        best, o = float("inf"), None
        for _ in range(rounds):
            t0 = time.perf_counter()
            o = exact.periodic_orbit(p, start=seed, n=n)
            best = min(best, time.perf_counter() - t0)
        assert o is not None
        rows.append(dict(scene=name, n=o.n, newton_iterations=len(o.newton), residual=o.residual,
                         multiplier_moduli=[float(x) for x in np.abs(o.multipliers)], stable=o.stable,
                         period=o.period, steps=o.steps, ms=1e3 * best))
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.orbit_cost", description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, default=None, help="also write the rows as JSON")
    args = ap.parse_args(argv)
    rows = orbit_costs()
    print(f"{'scene':<26} {'n':>3} {'Newton':>6} {'residual':>9} {'|mu|':>18} {'stable':>6} {'steps':>7} {'ms':>7}")
    for r in rows:
        mu = ", ".join(fmt_number(x, 4) for x in r["multiplier_moduli"])
        print(f"{r['scene']:<26} {r['n']:>3} {r['newton_iterations']:>6} {r['residual']:>9.1e} {mu:>18} "
              f"{str(r['stable']):>6} {r['steps']:>7} {fmt_number(r['ms'], 3):>7}")
    cont = continuation_costs()
    print(f"\n{'continuation':<54} {'points':>6} {'stopped':>10} {'s':>7}")
    for r in cont:
        print(f"{r['branch']:<54} {r['points']:>6} {r['stopped']:>10} {fmt_number(r['s'], 3):>7}")
    if args.json:
        args.json.write_text(json.dumps(dict(orbits=rows, continuations=cont), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
