"""Periodic orbits as objects, their continuation in V and a bifurcation diagram (docs/orbits.md).

1. peelapprox.periodic_orbit: the paper's period-8 orbit at V = 1 m/s, I = 1e-2 kg m², found by Newton on
   the return map from one AB -> CD jump to the next, with its period and Floquet multipliers (stable when
   both lie inside the unit circle).
2. peelapprox.continue_orbit: follow it in V, down and up, until it changes stability or ceases to exist;
   the branch reports its bifurcations (here a Neimark-Sacker one) and why it stopped (grazing, crest, ...).
3. exact.orbit_diagram: the brute-force picture, F at the AB -> CD jumps of long runs at 11 values of V,
   with the branch drawn over it (plot_bifurcation): solid where stable, dashed where unstable.

    python docs/examples/06_orbits_bifurcation.py [--out DIR]      # ~8 s
"""

import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa
from peelapprox.plotting import plot_bifurcation, save_figure


def main() -> None:
    out = output_dir(arguments(__doc__).parse_args().out)  # --out DIR (docs/examples/_gallery.py)
    p = pa.PeelParams(V=1.0, I=1e-2)

    # 1. The orbit: seeded from a 30 s run (its period n from the run's return map), then Newton to 1e-10.
    orbit = pa.periodic_orbit(p)
    mu = np.abs(orbit.multipliers)
    print(f"periodic orbit at V = {p.V:g}, I = {p.I:g}: period n = {orbit.n} slips, T = {orbit.period:.5f} s, "
          f"residual {orbit.residual:.1e}")
    print(f"Floquet multipliers |mu| = {mu[0]:.4f}, {mu[1]:.4f}: {'stable' if orbit.stable else 'unstable'}")
    print("F at its AB -> CD jumps [N]: " + ", ".join(f"{x:.2f}" for x in orbit.return_map_values))

    # 2. Continuation in V, each way; stop= is how far to go if nothing ends the branch first.
    branches = [pa.continue_orbit(orbit, "V", stop=stop) for stop in (0.9, 1.15)]
    for branch in branches:
        bif = ", ".join(f"{b.kind} at V = {b.value:.4f}" for b in branch.bifurcations) or "none"
        print(f"branch towards V = {branch.points[-1].value:.4f}: {len(branch.points)} points, "
              f"bifurcations: {bif}; ends: {branch.stopped} at V = {branch.end_value:.4f}")
    # Between the two ends the orbit is stable down to the Neimark-Sacker bifurcation (a complex pair of
    # multipliers leaves the unit circle) and exists up to the crest event (an earlier crest of F (1 + sin a)
    # reaches f_max: the orbit jumps one oscillation earlier and becomes another one).

    # 3. The brute-force diagram: from alpha0 = 0, 30 s of transient, then the jumps of a 10 s window.
    diagram = exact.orbit_diagram(p, "V", np.linspace(0.9, 1.15, 11), t_transient=30, window=10)
    for V, label in zip(diagram.values, diagram.labels):
        print(f"  long run at V = {V:.3f}: {label}")
    path = out / "orbits_bifurcation.png"
    # The title names the fixed parameters (params=), the legend every line style and marker.
    save_figure(plot_bifurcation(diagram, branches, params=p), path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
