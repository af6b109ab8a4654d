"""Approximate vs exact on one branch stay: the paper's reduced equations (Sec. V) against the full DAE.

At V = 1 m/s, I = 1e-2 kg m² (the paper's Case II) the force climbs the slow branch AB in one long stay,
the stretch "ab" of the paper's Fig. 4, from its lowest value to above f_max.  We

1. take that stay from an exact solution (comparisons.segments: every stay with its entry and exit state);
2. solve the reduced equations approxalpha + approxvdot (and genalpha + fullvdot) from the same entry state
   to the same exit velocity (peelapprox.reduced_segment) and compare the branch time Δt and force rise ΔF;
3. let the harness do it for every reduced model (comparisons.compare);
4. repeat the paper's own computation, seeded with its quoted point a (α_in = 0.0599, α̇_in = 9.7,
   F_in = 186.95 N): the paper reports Δt = 0.117 s (approximate) and 0.114 s (exact).

    python docs/examples/03_approx_vs_exact.py [--out DIR]      # ~3 s after the first compilation
"""

from types import SimpleNamespace

import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa
from comparisons import compare, segments
from peelapprox.plotting import plot_segment


def main() -> None:
    out = output_dir(arguments(__doc__).parse_args().out)  # --out DIR (docs/examples/_gallery.py)

    p = pa.PeelParams(V=1.0, I=1e-2)
    tr = exact.simulate(p, 31.0, t_transient=30.0, rtol=1e-10)

    # 1. The longest AB stay of the window: the paper's stretch ab.
    stay = max((s for s in segments(tr) if s.branch == "AB"), key=lambda s: s.t_out - s.t_in)
    dt_exact, dF_exact = stay.t_out - stay.t_in, stay.F_out - stay.F_in
    print(f"exact AB stay: F_in = {stay.F_in:.2f} N, alpha_in = {stay.alpha_in:.4f} rad, "
          f"alphadot_in = {stay.alphadot_in:.3f} rad/s, v_in = {stay.v_in:.5f} m/s")
    print(f"exact:                    dt = {dt_exact:.5f} s, dF = {dF_exact:.2f} N")

    # 2. The reduced equations from the same entry, to the same exit velocity (the fold v_max).
    seed = dict(F_in=stay.F_in, alpha_in=stay.alpha_in, alphadot_in=stay.alphadot_in, v_in=stay.v_in,
                v_f=stay.v_out)
    approx = {}
    for alpha_model, v_equation in (("approxalpha", "approxvdot"), ("genalpha", "fullvdot")):
        approx[alpha_model] = seg = pa.reduced_segment(p, "AB", **seed, alpha_model=alpha_model,
                                                       v_equation=v_equation)
        print(f"{alpha_model + ' + ' + v_equation:25s} dt = {seg.dt:.5f} s, dF = {seg.dF:.2f} N "
              f"(errors {100 * (seg.dt / dt_exact - 1):+.2f} %, {100 * (seg.dF / dF_exact - 1):+.2f} %)")

    # 3. The harness: every reduced model of comparisons.DEFAULT_MODELS on this stay, one row each.
    rows = compare(tr, segs=[stay])
    worst = max(abs(r.dt_rel_error) for r in rows if r.status == "ok")
    print(f"harness: {len(rows)} reduced models on this stay, largest |dt error| {100 * worst:.2f} % "
          f"(the paper's claim: within 10 %)")

    # 4. The paper's point a, with the true landing velocity on AB (docs/paper-notes.md, note 1).
    paper = pa.reduced_segment(p, "AB", F_in=186.95, alpha_in=0.0599, alphadot_in=9.7, v_in=0.00188, v_f=0.4)
    print(f"paper's point a, approxalpha + approxvdot: dt = {paper.dt:.4f} s (paper: 0.117 s), "
          f"dF = {paper.dF:.1f} N (paper: 117 N)")

    # The figure: v, alpha, F of approxalpha + approxvdot at 400 instants (save="steps" keeps only its ~30
    # accepted steps), the exact stay dotted (the paper's Fig. 9).  plot_segment takes anything with t (from
    # the branch entry), v, alpha, F.
    t_eval = np.linspace(0.0, approx["approxalpha"].dt, 400)
    smooth = pa.reduced_segment(p, "AB", **seed, alpha_model="approxalpha", t_eval=t_eval)
    inside = (tr.t >= stay.t_in) & (tr.t <= stay.t_out) & (tr.branch == 0)  # 0 = AB: not the jumps' CD ends
    ex = SimpleNamespace(t=tr.t[inside] - stay.t_in, v=tr.v[inside], alpha=tr.alpha[inside], F=tr.F[inside])
    path = out / "approx_vs_exact.png"
    plot_segment(smooth, exact=ex).savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
