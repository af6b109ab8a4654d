"""A sweep over the (I, V) plane and its phase diagram: where is the stick-slip periodic, and of which period?

peelapprox.sweep evaluates named measures at every grid point: here "regime" (the closed-form estimate),
"period" (the period of the return map of the exact solution over t = 30-50 s) and "jumps" (slip statistics
over the same window).  Each finished point is appended to DIR/sweep/results.jsonl at once, so a killed
sweep resumes where it stopped when called again with the same arguments.  4 x 4 points, ~5 s in this
process; --workers N runs them on N processes (or pass executor=Client(...).get_executor() for dask).

The paper: chaos at low inertia and small V, odd periods without the period-doubling cascade
(docs/dynamics.md has this grid on a finer mesh: aperiodic at I = 1e-4, V = 1 and 2, chaotic there).

    python docs/examples/05_sweep_phase_diagram.py [--out DIR] [--workers N]      # ~6 s, 16 exact runs of 50 s
"""

import numpy as np
from _gallery import arguments, output_dir

import peelapprox as pa
from peelapprox.plotting import plot_phase_diagram


def main() -> None:
    ap = arguments(__doc__)  # --out DIR (docs/examples/_gallery.py)
    ap.add_argument("--workers", type=int, default=0, help="worker processes (default 0: this process)")
    args = ap.parse_args()
    out = output_dir(args.out)

    I_values = [1e-5, 1e-4, 1e-3, 1e-2]  # roller inertia [kg m²]
    V_values = [1.0, 2.0, 3.0, 4.0]      # pull speed [m/s]
    # resume=True (the default) picks up a sweep already in out/sweep with the same grid and measures.
    result = pa.sweep(I_values, V_values, "regime,period,jumps", out=out / "sweep", max_workers=args.workers,
                      progress=False)

    # values(key) is the key over the grid, shape (len(I_values), len(V_values)); result.keys() lists the keys.
    labels = result.values("period_label")  # "period-n", "aperiodic", or a breakdown
    drops = result.values("jumps_mean_force_drop")
    print("period of the return map (rows I, columns V):")
    print("I \\ V [m/s]  " + "".join(f"{V:>12g}" for V in V_values))
    for i, I in enumerate(I_values):
        print(f"{I:<12g} " + "".join(f"{labels[i, j]:>12}" for j in range(len(V_values))))
    print("mean force drop per slip [N]:")
    for i, I in enumerate(I_values):
        print(f"{I:<12g} " + "".join(f"{drops[i, j]:>12.2f}" for j in range(len(V_values))))
    n_aperiodic = int(np.sum(labels == "aperiodic"))
    print(f"{result.shape[0] * result.shape[1]} points, {n_aperiodic} aperiodic, statuses: "
          f"{sorted(set(result.values('status').ravel()))}")

    # The phase diagram: one cell per grid point, coloured by the period (blank: aperiodic, no period).
    fig = plot_phase_diagram(result, "period", title="period of the return map (blank: aperiodic)")
    for i, I in enumerate(I_values):  # write each cell's label in it
        for j, V in enumerate(V_values):
            fig.axes[0].text(V, I, labels[i, j], ha="center", va="center", fontsize=9,
                             bbox={"facecolor": "white", "alpha": 0.7, "linewidth": 0})
    path = out / "sweep_phase_diagram.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":  # the guard matters: worker processes import this file
    main()
