"""Your data: a force trace from a tensile machine, read with the model's own statistics, and the parameters back.

A synthetic experiment stands in for yours, so that every answer can be checked against the truth: the exact
model at V = 1 m/s, I = 1e-2 kg m², k = 1000 N/m (the paper's Fig. 4 case, a period-8 orbit), 20 s of its pull
force sampled at 10 kHz with 0.5 N of white noise and a 5 N drift, written to DIR/my_trace.csv in ms and kN as a
machine might, then read back as you would read your file:

1. ``ForceSeries.from_csv``: the trace, units converted from the header;
2. ``slips()`` and ``observables()``: the slips found (none missed, none false), the slip interval, force drop,
   stick and slip times, the return map's period;
3. ``lyapunov()``: the largest Lyapunov exponent from the data, ~0 for this periodic orbit;
4. ``infer``: k from the trace (I known; ``--full`` fits I and k together, 1-3 min).

    python docs/examples/07_your_data.py [--out DIR] [--full]     # ~20 s; --full ~2 min
"""

import matplotlib.pyplot as plt
import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--full", action="store_true", help="fit I and k together (~2 min) instead of k alone")
    args = ap.parse_args()
    out = output_dir(args.out)  # --out DIR (docs/examples/_gallery.py)

    # the experiment: 30 s of transient, then 20 s sampled at 10 kHz; noise and drift as a machine adds them
    truth = pa.PeelParams(V=1.0, I=1e-2, k=1000.0)
    run = exact.simulate(truth, 50.0, t_eval=30.0 + np.arange(200_000) / 1e4)
    made = run.as_series(1e4, noise=0.5, drift=5.0, seed=1)
    path = out / "my_trace.csv"
    np.savetxt(path, np.c_[(made.t - made.t[0]) * 1e3, made.F / 1e3], delimiter=",", header="t [ms],F [kN]",
               comments="", fmt="%.10g")

    # 1. read it back as your own file
    series = pa.ForceSeries.from_csv(str(path), V=1.0)
    print(series)
    # 2. the slips and the attractor's observables
    slips = series.slips()
    obs = series.observables()
    exact_obs = pa.StickSlipObservables.from_trajectory(run, 30.0)
    print(f"{len(slips)} slips found (the run has {exact_obs.n_slips}); noise {slips.noise:.3f} N, "
          f"threshold {slips.threshold:.2f} N")
    print(f"slip interval {obs.slip_interval:.5f} s (exact {exact_obs.slip_interval:.5f} s), force drop "
          f"{obs.force_drop:.3f} N (exact {exact_obs.force_drop:.3f} N), {obs.period_label} "
          f"(exact {exact_obs.period_label})")
    slips.write(str(out / "my_slips.csv"))
    # 3. chaos or not: the largest Lyapunov exponent from the data, with a surrogate-data test
    lyap = series.lyapunov(surrogates=9)
    print(f"Lyapunov exponent {lyap.lambda_bits_per_s:.3f} bits/s; surrogates reject linear noise: "
          f"{lyap.surrogate.rejects_noise}")
    # 4. the parameters back
    free = ("I", "k") if args.full else ("k",)
    start = pa.PeelParams(V=1.0, I=1.3e-2 if args.full else 1e-2, k=900.0)
    res = pa.infer(series, start, free, search=3.0 if args.full else 1.5, max_wall=600)
    print(res.report().splitlines()[0])
    for name in free:
        lo, hi = res.intervals[name]
        print(f"{name} = {res.values[name]:.5g} (truth {getattr(truth, name):.5g}), 95 % in [{lo:.5g}, {hi:.5g}]: "
              f"{res.verdicts[name]}")

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    series.plot(axes[0], window=(0.0, 0.3))
    series.plot_return_map(axes[1])
    res.plot(axes[2])
    fig.savefig(out / "your_data.png", dpi=110)
    print(f"wrote {out / 'your_data.png'}")


if __name__ == "__main__":
    main()
