"""The paper's three regimes of inertia at V = 1 m/s: I = 1e-5 (low), 1e-3 (intermediate), 1e-2 (high).

For each I: the closed-form regime estimate (no DAE), the exact solution over a 10 s window after a 30 s
transient, the period of its return map x_k -> x_(k+1) (x_k = F at the k-th AB -> CD jump), the force drops,
and the period of the peel angle's inertial oscillation on the slow branch AB, 2 pi sqrt(I / (F R)) at
F = f_min and f_max (the paper's Eq. approxalpha; 4.44 ms and 3.69 ms at I = 1e-5) against the exact one.

    python docs/examples/02_three_regimes.py [--out DIR]      # ~3 s after the first compilation
"""

import matplotlib.pyplot as plt
import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa
from comparisons import segments


def main() -> None:
    out = output_dir(arguments(__doc__).parse_args().out)  # --out DIR (docs/examples/_gallery.py)

    fig, axes = plt.subplots(2, 3, figsize=(13, 7), constrained_layout=True)
    for col, I in enumerate((1e-5, 1e-3, 1e-2)):
        p = pa.PeelParams(V=1.0, I=I)
        est = pa.estimate(p)  # folds, inertial periods, CD damping time, ... in milliseconds, no DAE
        tr = exact.simulate(p, 40.0, t_transient=30.0, rtol=1e-10)
        t_k, x_k = pa.return_map(tr, with_times=True)
        per = pa.periodicity(x_k)  # period-n when x_(k+n) = x_k to 1e-6 over the whole window
        drops = pa.force_drops(tr)

        print(f"I = {I:g} kg m^2 ({est.label}):")
        print(f"  return map: {per.kind}, period n = {per.period} ({per.n_returns} returns in 10 s)")
        print(f"  slips every {np.mean(np.diff(t_k)):.4f} s on average; force drop mean {drops.mean():.2f} N, "
              f"largest {drops.max():.2f} N")
        print(f"  F between {tr.F.min():.2f} and {tr.F.max():.2f} N (folds: f_min {est.f_min:.2f}, "
              f"f_max {est.f_max:.2f} N)")
        # The inertial period on AB, closed form at f_min and f_max, and measured on the exact solution: the
        # spacing of the upward zero crossings of alpha in the branch stays (comparisons.segments).
        stays = [s for s in segments(tr) if s.branch == "AB"]
        measured = [s.periods for s in stays if len(s.periods) >= 2]
        print(f"  alpha period on AB, 2 pi sqrt(I/FR): {est.period_at_f_min * 1e3:.3f} ms at f_min, "
              f"{est.period_at_f_max * 1e3:.3f} ms at f_max")
        if measured:
            first, last = np.mean([m[0] for m in measured]), np.mean([m[-1] for m in measured])
            print(f"  alpha period on AB, exact: {first * 1e3:.3f} ms at entry, {last * 1e3:.3f} ms at exit")
        else:
            print(f"  alpha period on AB, exact: not resolved (longest AB stay "
                  f"{max(s.t_out - s.t_in for s in stays):.4f} s, under two oscillations)")

        # Top: F(t) over the last 0.5 s.  Bottom: the return map, one dot per slip.
        last = tr.t >= tr.t[-1] - 0.5
        axes[0, col].plot(tr.t[last], tr.F[last], lw=0.8)
        axes[0, col].axhline(est.f_max, color="0.6", ls="--", lw=0.8)
        axes[0, col].axhline(est.f_min, color="0.6", ls="--", lw=0.8)
        axes[0, col].set(xlabel="t [s]", ylabel="F [N]", title=f"I = {I:g} kg m²: {est.inertia} inertia")
        axes[1, col].plot(x_k[:-1], x_k[1:], ".", ms=5)
        axes[1, col].set(xlabel="$x_k$ [N]", ylabel="$x_{k+1}$ [N]", title=f"return map: {per.kind} "
                         + (f"(period {per.period})" if per.period else ""))
    fig.suptitle("V = 1 m/s: the paper's low, intermediate and high inertia (dashed: f_min, f_max)")
    path = out / "three_regimes.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
