"""Your own tape: run the model with a peel-force law of your choice instead of the paper's f(v, V).

Two ways to give a law (docs/your-own-tape.md has all four):

* an expression in v (and V) with named constants, here Hong & Yue's N-shaped cubic
  f(v) = a + b v - c v² + d v³ (its folds are known in closed form: v = (c ∓ sqrt(c² - 3bd)) / (3d));
* a measured curve, a CSV file of (v, f) points interpolated monotonically (PCHIP in ln v); here the
  "measurement" is the cubic sampled at 30 points per decade, written to DIR/my_tape.csv and read back.

Both run through the same exact solver.  At every AB -> CD jump the level F (1 + sin α) equals the law's
f_max, at every CD -> AB jump its f_min: the jumps happen at the law's folds, whatever the law.

The slip rhythm agrees (every 0.1204 s and 0.1207 s), but the expression's orbit has period 5 and the table's
period 1.  Not an error of either run: this cubic at V = 1.2 m/s, I = 1e-5 kg m² sits next to a change of
period.  The expression's period-5 orbit is nearly period 1 (its slip intervals spread by 2.7 ms, 2 % of the
interval), and the same cubic raised by 0.05 N everywhere (a = 150.05) already settles on period 1.  The table
differs from the cubic by up to 0.38 N on the orbit's range of v (near fold D, where its f_min, a data point,
is 0.21 N high), past that margin; sampled at 120 points per decade (0.016 N) it gives period 5 back.  The
last lines print these measurements.

    python docs/examples/04_your_own_tape.py [--out DIR]      # ~4 s (the expression compiles once, ~0.5 s)
"""

import matplotlib.pyplot as plt
import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa


def slips(law: pa.PeelForce, V: float) -> tuple:
    """The run of the example at pull speed V: the trajectory, the AB -> CD jumps' mask, the period of its
    return map, the intervals between the AB -> CD jumps [s]."""
    tr = exact.simulate(pa.PeelParams(V=V, I=1e-5, force=law), 3.0, t_transient=1.0, rtol=1e-10)
    up = tr.jumps.from_branch == 0
    return tr, up, pa.periodicity(tr), np.diff(tr.jumps.t[up])


def main() -> None:
    out = output_dir(arguments(__doc__).parse_args().out)  # --out DIR (docs/examples/_gallery.py)
    V = 1.2  # pull speed [m/s]

    # 1. A law as an expression: f', f'' come from sympy; the law is probed for v in [1e-6, 1e3] m/s.
    cubic = pa.PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150, b=300, c=300, d=80)
    # 2. A law as a table, here written to a CSV file and loaded as you would load your measurement.
    v = np.logspace(-3, 1, 121)
    np.savetxt(out / "my_tape.csv", np.c_[v, cubic.f(v, V)], delimiter=",", header="v,f", comments="")
    v_data, f_data = np.loadtxt(out / "my_tape.csv", delimiter=",", skiprows=1, unpack=True)
    table = pa.PeelForce.tabulated(v_data, f_data)  # checked: v increasing, one maximum then one minimum

    fig, (ax_law, ax_F) = plt.subplots(1, 2, figsize=(12, 4.8), constrained_layout=True)
    vv = np.logspace(-3, 1, 400)
    for name, law, colour, style in (("expression", cubic, "C0", "-"), ("table", table, "C1", "--")):
        folds = law.folds(V)  # the stick-slip window: B = (v_max, f_max), D = (v_min, f_min)
        print(f"{name}: fold B at v_max = {folds.v_max:.6f} m/s (f_max = {folds.f_max:.4f} N), "
              f"fold D at v_min = {folds.v_min:.6f} m/s (f_min = {folds.f_min:.4f} N)")

        # Every consumer takes the law through PeelParams(force=...): the solver, reductions, sweeps, ...
        tr, up, per, intervals = slips(law, V)
        level = tr.jumps.F * (1 + np.sin(tr.jumps.alpha))  # F (1 + sin α) at each jump
        print(f"{name}: F(1 + sin a) at AB->CD jumps {level[up].mean():.4f} N, at CD->AB jumps "
              f"{level[~up].mean():.4f} N")
        # The slip rhythm follows the fold levels; the orbit's fine structure (its period in slips) depends
        # on the shape of f between the folds too, which the table reproduces only to its spacing.
        print(f"{name}: {int(up.sum())} slips in 2 s, every {np.mean(intervals):.5f} s; "
              f"return map {per.kind}, period n = {per.period}; the intervals spread by "
              f"{np.ptp(intervals):.2g} s")
        if name == "expression":
            v_orbit = np.geomspace(tr.v.min(), tr.v.max(), 2001)  # the v the expression's orbit visits

        ax_law.semilogx(vv, law.f(vv, V), style, color=colour, lw=2, label=name)
        ax_law.plot([folds.v_max, folds.v_min], [folds.f_max, folds.f_min], "o", color=colour)
        window = tr.t <= tr.t[0] + 0.5
        ax_F.plot(tr.t[window], tr.F[window], color=colour, lw=0.9, label=name)
    # Why period 5 and period 1: the cubic sits 0.05 N from a change of period, the table is further off.
    gap = np.abs(table.f(v_orbit, V) - cubic.f(v_orbit, V))
    print(f"why the periods differ: over the orbit's v = {v_orbit[0]:.3f}-{v_orbit[-1]:.3f} m/s the table "
          f"differs from the expression by up to {gap.max():.3f} N (at v = {v_orbit[gap.argmax()]:.2f} m/s; its "
          f"f_min is {table.folds(V).f_min - cubic.folds(V).f_min:+.3f} N off)")
    v_fine = np.logspace(-3, 1, 481)  # 120 points per decade
    for label, law in (("the cubic raised by 0.05 N (a = 150.05)",
                        pa.PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150.05, b=300, c=300, d=80)),
                       ("a 120-points-per-decade table",
                        pa.PeelForce.tabulated(v_fine, cubic.f(v_fine, V)))):
        _, _, per, intervals = slips(law, V)
        extra = "" if law.kind == "expression" else \
            f" (it differs by up to {np.max(np.abs(law.f(v_orbit, V) - cubic.f(v_orbit, V))):.4f} N)"
        print(f"  {label}: period n = {per.period}, every {np.mean(intervals):.5f} s, the intervals spread by "
              f"{np.ptp(intervals):.2g} s{extra}")
    ax_law.plot(v_data, f_data, "k.", ms=3, label="my_tape.csv")
    ax_law.set(xlabel="v [m/s]", ylabel="f(v) [N]", ylim=(100, 400), title=f"the laws at V = {V} m/s (o: folds)")
    ax_F.set(xlabel="t [s]", ylabel="F [N]", title="pull force, I = 1e-5 kg m²")
    ax_law.legend()
    ax_F.legend()
    path = out / "your_own_tape.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
