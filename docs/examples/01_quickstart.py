"""Quick start: simulate the paper's Fig. 4 case, count its jumps and force drops, draw it.

The tape is pulled at V = 1 m/s off a roller of inertia I = 1e-2 kg m² (high inertia; k = 1000 N/m,
R = 0.1 m, l = 1 m, the paper's values, are the defaults).  The exact (ε → 0) solution is integrated for
32 s; the first 30 s are the transient and are not stored.  The paper reports a period-8 pull force for
this case, with F overshooting the fold f_max and undershooting f_min.

    python docs/examples/01_quickstart.py [--out DIR]      # ~3 s after the first compilation
"""

import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa
from peelapprox.plotting import plot_trajectory, save_figure, trajectory_window


def main() -> None:
    out = output_dir(arguments(__doc__).parse_args().out)  # --out DIR (docs/examples/_gallery.py)

    # The parameters: every argument is checked (a ValueError names a bad one and its valid range).
    p = pa.PeelParams(V=1.0, I=1e-2)

    # The peel-force law f(v, V) is N-shaped: the stable branches AB (slow) and CD (fast) meet the unstable
    # one at the folds B = (v_max, f_max) and D = (v_min, f_min).  The jumps between the branches happen there.
    bs = pa.branch_structure(p.V)
    print(f"fold B: v_max = {bs.v_max:.4f} m/s, f_max = {bs.f_max:.2f} N")
    print(f"fold D: v_min = {bs.v_min:.4f} m/s, f_min = {bs.f_min:.2f} N")

    # The exact solution: an event-driven DOP853 solver with exact jumps at the folds.  save="steps" keeps
    # every accepted step of the stored window [30, 32] s (save="jumps" would keep the jumps only).
    tr = exact.simulate(p, 32.0, t_transient=30.0, rtol=1e-10)
    print(f"simulated 32 s in {tr.stats.wall_time:.2f} s: {tr.stats.n_steps} steps, {tr.stats.n_jumps} jumps")
    print(f"constraint residual |F(1 + sin a) - f(v)| / f <= {np.max(tr.constraint_residual(relative=True)):.1e}")

    # The jumps of the window: Jumps holds arrays (t, from_branch, to_branch, F, ...); 0 = AB, 1 = CD.
    j = tr.jumps
    n_slips = int(np.sum(j.from_branch == 0))
    print(f"window 30-32 s: {len(j.t)} jumps, {n_slips} slips (AB -> CD)")

    # The return map x_k = F at the k-th AB -> CD jump; its period n is the period of the orbit in slips.
    t_k, x_k = pa.return_map(tr, with_times=True)
    per = pa.periodicity(x_k)
    print(f"return map: {per.kind}, period n = {per.period}")
    if per.period:
        print(f"one cycle of the orbit lasts {t_k[per.period] - t_k[0]:.4f} s")

    # The force drop of each slip: F at the AB -> CD jump minus F at the next CD -> AB jump.
    drops = pa.force_drops(tr)
    print(f"force drops: mean {drops.mean():.2f} N, smallest {drops.min():.2f} N, largest {drops.max():.2f} N")

    # At high inertia F overshoots f_max and undershoots f_min (the paper's Fig. 4a).
    print(f"F over the window: max {tr.F.max():.2f} N (f_max {bs.f_max:.2f}), min {tr.F.min():.2f} N "
          f"(f_min {bs.f_min:.2f})")

    # F(t), alpha(t), v(t) and the v-F phase plane with f(v, V): the paper's Fig. 4.  cycles= is how many of
    # the last slips to draw at least (default 5, rounded up to whole periods of a periodic return map;
    # cycles=None draws the whole window): here two periods of the orbit.  The stored steps are long where
    # the orbit is smooth, so the same run sampled densely over the window (t_eval: the solver's own dense
    # output, the same steps) is drawn with them: smooth curves.
    cycles = 2 * (per.period or 8)
    w = trajectory_window(tr, cycles)
    dense = exact.simulate(p, w.end, t_transient=30.0, rtol=1e-10, t_eval=np.linspace(w.start, w.end, 4000))
    path = out / "quickstart.png"
    save_figure(plot_trajectory(tr, cycles=cycles, dense=dense), path, dpi=110)  # reproducible bytes
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
