"""Your own tape: run the model with a peel-force law of your choice instead of the paper's f(v, V).

Two ways to give a law (docs/your-own-tape.md has all four):

* an expression in v (and V) with named constants, here Hong & Yue's N-shaped cubic
  f(v) = a + b v - c v² + d v³ (its folds are known in closed form: v = (c ∓ sqrt(c² - 3bd)) / (3d));
* a measured curve, a CSV file of (v, f) points interpolated monotonically (PCHIP in ln v); here the
  "measurement" is the cubic sampled at 30 points per decade, written to DIR/my_tape.csv and read back.

Both run through the same exact solver.  At every AB -> CD jump the level F (1 + sin α) equals the law's
f_max, at every CD -> AB jump its f_min: the jumps happen at the law's folds, whatever the law.

    python docs/examples/04_your_own_tape.py [--out DIR]      # ~4 s (the expression compiles once, ~0.5 s)
"""

import matplotlib.pyplot as plt
import numpy as np
from _gallery import arguments, output_dir

import exact
import peelapprox as pa


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
        tr = exact.simulate(pa.PeelParams(V=V, I=1e-5, force=law), 3.0, t_transient=1.0, rtol=1e-10)
        level = tr.jumps.F * (1 + np.sin(tr.jumps.alpha))  # F (1 + sin α) at each jump
        up = tr.jumps.from_branch == 0
        print(f"{name}: F(1 + sin a) at AB->CD jumps {level[up].mean():.4f} N, at CD->AB jumps "
              f"{level[~up].mean():.4f} N")
        # The slip rhythm follows the fold levels; the orbit's fine structure (its period in slips) depends
        # on the shape of f between the folds too, which the table reproduces only to its spacing.
        per = pa.periodicity(tr)
        print(f"{name}: {int(up.sum())} slips in 2 s, every {np.mean(np.diff(tr.jumps.t[up])):.5f} s; "
              f"return map {per.kind}, period n = {per.period}")

        ax_law.semilogx(vv, law.f(vv, V), style, color=colour, lw=2, label=name)
        ax_law.plot([folds.v_max, folds.v_min], [folds.f_max, folds.f_min], "o", color=colour)
        window = tr.t <= tr.t[0] + 0.5
        ax_F.plot(tr.t[window], tr.F[window], color=colour, lw=0.9, label=name)
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
