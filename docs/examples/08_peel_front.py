"""The peel front: N strips across the tape, its space-time image, the acoustic emission and its bursts.

1. ``exact.simulate_front``: docs/peel-front.md's first example (V = 1 m/s, I = 1e-2 kg m², a 1 g tape, 64 strips,
   γ = 0.05, κ = 0.1, δ₀ = 0.01, seed 0), 30 ms stored every 2 µs: its pattern class, the works and the AE
   energy (a state of the integration, against the trapezoid integral of the stored AE power);
2. a longer, narrower front (16 strips, 0.3 s after 20 ms of transient, every 10 µs): its AE power R_AE, the
   burst catalogue (``tr.bursts``), one power law of the burst energies (``fit_power_law``, xmin by KS, a
   bootstrap interval) and the comparison with a lognormal (``compare_power_law``);
3. one figure: the space-time image (``plot_front``) beside the burst energies' CCDF with the fit
   (``plot_burst_distribution``).

    python docs/examples/08_peel_front.py [--out DIR]     # ~15 s
"""

import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa
from peelapprox.plotting import new_figure, plot_burst_distribution, plot_front, save_figure


def main() -> None:
    args = arguments(__doc__).parse_args()
    out = output_dir(args.out)  # --out DIR (docs/examples/_gallery.py)

    # 1. the front of docs/peel-front.md, "Use"
    base = pa.PeelParams(V=1.0, I=1e-2, tape_mass=1e-3)
    fp = pa.FrontParams(base=base, N=64, gamma=0.05, kappa=0.1, ends="free", delta0=0.01, seed=0)
    tr = exact.simulate_front(fp, 0.03, rtol=1e-8, dt_save=2e-6)
    pat = tr.pattern()
    print(f"N = 64: {len(tr.jumps)} mean-front jumps, {tr.n_local_switches} local switches, pattern {pat.label} "
          f"(<W> = {pat.roughness:.2f}, Phi_mix = {pat.mixed_fraction:.2f}, <n_dw> = {pat.walls:.1f})")
    print(f"the pull's work {tr.work_in[-1]:.6f} J, peel dissipation {tr.work_peel[-1]:.6f} J, AE energy "
          f"{tr.ae_energy[-1]:.6f} J (the AE power's trapezoid integral {np.trapezoid(tr.ae_power, tr.t):.6f} J)")

    # 2. bursts of a longer run
    fp16 = pa.FrontParams(base=base, N=16, gamma=0.05, kappa=0.05, delta0=0.05, seed=4)
    head = exact.simulate_front(fp16, 0.02, store_front=False)
    long = exact.simulate_front(fp16, 0.3, y0=head.final_y, dt_save=1e-5, store_front=False)
    cat = long.bursts()  # threshold 5 % of the largest AE power of the record
    energies = cat.sizes("energy")
    fit = pa.fit_power_law(energies, min_tail=10, n_bootstrap=200, seed=0)
    lo, hi = fit.alpha_interval or (float("nan"), float("nan"))
    lr = fit.compare("lognormal")
    print(f"N = 16 over 0.3 s: {len(long.jumps)} mean-front jumps, {len(cat)} bursts above "
          f"{cat.threshold:.4g} W, energies {energies.min():.3g}-{energies.max():.3g} J")
    print(f"power law of the burst energies: alpha = {fit.alpha:.3f}, 95 % in [{lo:.3f}, {hi:.3f}], "
          f"xmin = {fit.xmin:.3g} J, {fit.n_tail} of {fit.n} in the tail; against a lognormal: R = {lr.R:.3f}, "
          f"p = {lr.p_value:.3f} ({lr.favoured})")

    fig = new_figure(figsize=(12, 5))
    left, right = fig.subfigures(1, 2, width_ratios=(1.3, 1.0))
    plot_front(tr, fig=left)
    ax = right.subplots()
    plot_burst_distribution(fit, [fit], ax=ax, xlabel="burst energy [J]",
                            title=f"{len(cat)} AE bursts, N = 16, 0.3 s")
    path = out / "peel_front.png"
    save_figure(fig, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
