"""How the tape mass changes the stick-slip dynamics at realistic masses (docs/tape-mass-dynamics.md).

``python -m comparisons.benchmark.tape_mass_dynamics [--out DIR] [--quick] [--no-lyapunov] [--no-diagram]``
measures, for the paper's three regimes (:data:`REGIMES`) and the tape masses :data:`MASSES` (0: the massless
model on the hybrid method; m > 0: the tape-mass model on ``method="smooth"`` with scipy's LSODA), over one
window after a transient:

* the attractor's period (``peelapprox.classify`` of the AB→CD jump forces, ``period_rtol`` 1e-5) or aperiodicity,
* the force drops (F at an AB→CD jump minus F at the next CD→AB jump), F at the slips (min, max) and at the
  sticks (min), the slips per second,
* the largest Lyapunov exponent by the two-trajectory method (``exact.lyapunov``, short: its standard error
  from batch means is in the table),

and the brute-force orbit diagram over m at one (V, I) (``exact.orbit_diagram(params, "tape_mass", ...)``), and
the F(t) windows of the figure.  It reports progress on stderr and writes ``measures.csv``/``.json``,
``diagram.csv``/``.json`` and ``windows.json`` to ``--out`` (default ``tape_mass_dynamics``);
``python -m comparisons.benchmark.tape_mass_dynamics --figures DIR`` draws the two figures from them.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

import exact
from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded, classify, force_drops, return_map
from peelapprox.errors import SolverFailure
from peelapprox.plotting import save_figure

__all__ = ["REGIMES", "MASSES", "measure_point", "measure_lyapunov", "main"]

#: (name, V [m/s], I [kg m²]): the paper's aperiodic case, the period-1 inertia case, a chaotic case.
REGIMES = (("aperiodic", 1.0, 1e-5), ("inertial", 1.0, 1e-2), ("chaotic", 2.0, 1e-4))
#: Tape masses [kg]; 0 is the massless model (hybrid method).  A 2 cm ribbon of 1 m weighs ~1e-3 kg.
MASSES = (0.0, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2)
#: The orbit diagram's point and masses.
DIAGRAM_POINT = (1.0, 1e-2)
DIAGRAM_MASSES = (0.0, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2)
RTOL = 1e-8
#: Masses whose Lyapunov exponent the study skips: m = 1e-6 kg costs ~100 s of wall time per simulated second of
#: the two-trajectory method (the stiff solver restarted every tau), and sits on the hybrid limit (its windows).
LYAPUNOV_SKIP = (1e-6,)
SOLVER = "LSODA"


def _params(V: float, I: float, m: float) -> PeelParams:
    return PeelParams(V=V, I=I, tape_mass=m if m > 0 else None)


def _solver(params: PeelParams) -> str | None:
    """The scipy solver of the study for a model without the hybrid method (the tape mass), else None."""
    return None if exact.model_of(params).has_hybrid else SOLVER


def measure_point(V: float, I: float, m: float, *, t_transient: float, window: float,
                  max_wall: float = 600.0) -> dict:
    """The row of one (V, I, m): period, force drops, slip rate over the window (module docstring)."""
    p = _params(V, I, m)
    solver = _solver(p)
    row: dict = {"V": V, "I": I, "m": m, "method": " ".join(filter(None, [exact.model_of(p).methods[0], solver])),
                 "t_transient": t_transient, "window": window}
    t0 = time.perf_counter()
    try:
        # simulate, not window_run: the small masses need more steps than the smooth method's default budget
        tr = exact.simulate(p, t_transient + window, t_transient=t_transient, rtol=RTOL, solver=solver,
                            save="jumps", max_steps=10**7, max_wall=max_wall)
    except (ModelBreakdown, SolverFailure, SolverBudgetExceeded) as exc:
        return {**row, "status": f"{type(exc).__name__}: {str(exc)[:100]}"}
    x = return_map(tr)
    per = classify(tr, period_rtol=1e-5)
    drops = force_drops(tr)
    J = tr.jumps
    F_stick = np.asarray(J.F)[np.asarray(J.from_branch) == 1]
    row.update(status="ok", label=per.label, period=per.period, n_slips=int(x.size),
               slips_per_s=x.size / window,
               F_slip_min=float(x.min()) if x.size else None, F_slip_max=float(x.max()) if x.size else None,
               F_stick_min=float(F_stick.min()) if F_stick.size else None,
               drop_mean=float(drops.mean()) if drops.size else None,
               drop_max=float(drops.max()) if drops.size else None,
               window_wall=time.perf_counter() - t0)
    return row


#: The two-trajectory settings of the study: short (the smooth method restarts the stiff solver every ``tau``).
LYAPUNOV = dict(t_transient=1.0, tau=0.05, n_discard=4, d0=1e-4, rtol=1e-9)


def measure_lyapunov(V: float, I: float, m: float, T: float, max_wall: float = 600.0) -> dict:
    """The two-trajectory exponent at (V, I, m) over ``T`` s (:data:`LYAPUNOV`), with its standard error."""
    t1 = time.perf_counter()
    try:
        p = _params(V, I, m)
        kw = {} if _solver(p) is None else {"solver": _solver(p)}
        r = exact.lyapunov(p, T=T, max_wall=max_wall, **LYAPUNOV, **kw)  # type: ignore[arg-type]
        return dict(lyapunov_bits=r.bits_per_s, lyapunov_stderr=r.stderr_bits, lyapunov_T=T,
                    lyapunov_wall=time.perf_counter() - t1)
    except (ModelBreakdown, SolverFailure, SolverBudgetExceeded, RuntimeError, ValueError) as exc:
        return dict(lyapunov_bits=None, lyapunov_status=f"{type(exc).__name__}: {str(exc)[:100]}")


def _write_table(rows: list[dict], out: Path, stem: str) -> None:
    keys: list[str] = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(out / f"{stem}.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    (out / f"{stem}.json").write_text(json.dumps(rows, indent=1))


def _windows(out: Path, span: float) -> None:
    """F(t) over ``span`` s after 1 s, at the aperiodic point, for a few masses (the figure's data)."""
    data = {}
    for m in (0.0, 1e-5, 1e-3, 1e-2):
        V, I = REGIMES[0][1:]
        tr = exact.simulate(_params(V, I, m), 1.0 + span, rtol=RTOL, t_transient=1.0, solver=_solver(m),
                            max_steps=10**7, max_wall=600.0)
        k = max(1, tr.t.size // 4000)
        data[str(m)] = {"t": tr.t[::k].tolist(), "F": tr.F[::k].tolist()}
        print(f"window F(t) m={m:g}: {tr.t.size} points", file=sys.stderr, flush=True)
    (out / "windows.json").write_text(json.dumps({"V": REGIMES[0][1], "I": REGIMES[0][2], "windows": data}))


def figures(src: Path, dest: Path) -> None:
    """docs/figures/tape_mass_dyn_windows.png and tape_mass_dyn_diagram.png from the written data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w = json.loads((src / "windows.json").read_text())
    fig, axes = plt.subplots(len(w["windows"]), 1, figsize=(7, 1.6 * len(w["windows"])), sharex=True)
    for ax, (m, d) in zip(axes, w["windows"].items()):
        ax.plot(d["t"], d["F"], lw=0.7)
        ax.set_ylabel("F [N]")
        ax.set_title(f"m = {float(m):g} kg" + (" (massless, hybrid)" if float(m) == 0 else ""), fontsize=9)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(f"V = {w['V']:g} m/s, I = {w['I']:g} kg m²", fontsize=10)
    fig.tight_layout()
    save_figure(fig, dest / "tape_mass_dyn_windows.png", dpi=90)
    rows = json.loads((src / "diagram.json").read_text())
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ms = np.array([r["tape_mass"] for r in rows if r["F"] is not None])
    Fs = np.array([r["F"] for r in rows if r["F"] is not None])
    x = np.where(ms > 0, ms, 3e-7)
    ax.semilogx(x, Fs, ".", ms=3)
    ax.set_xlabel("tape mass m [kg] (leftmost: m = 0, hybrid)")
    ax.set_ylabel("F at AB→CD jumps [N]")
    ax.set_title(f"orbit diagram over m, V = {DIAGRAM_POINT[0]:g} m/s, I = {DIAGRAM_POINT[1]:g} kg m²", fontsize=9)
    fig.tight_layout()
    save_figure(fig, dest / "tape_mass_dyn_diagram.png", dpi=90)


def _diagram(out: Path, t_transient: float, window: float) -> None:
    """The orbit diagram over the tape mass at :data:`DIAGRAM_POINT`, written to ``diagram.csv|json``."""
    V, I = DIAGRAM_POINT
    d = exact.orbit_diagram(PeelParams(V=V, I=I), "tape_mass", DIAGRAM_MASSES, t_transient=t_transient,
                            window=window, rtol=RTOL, solver=SOLVER, progress=True,
                            max_wall=None)  # a study run to the end (its stiff small masses take long)
    _write_table(d.rows(), out, "diagram")


def _lyapunov_only(out: Path, T: float) -> int:
    """The exponents of every (regime, m) but :data:`LYAPUNOV_SKIP`, written to ``lyapunov.csv|json``."""
    rows: list[dict] = []
    for name, V, I in REGIMES:
        for m in MASSES:
            if m in LYAPUNOV_SKIP:
                continue
            t0 = time.perf_counter()
            rows.append({"regime": name, "V": V, "I": I, "m": m, **measure_lyapunov(V, I, m, T)})
            _write_table(rows, out, "lyapunov")
            lam, err = rows[-1].get("lyapunov_bits"), rows[-1].get("lyapunov_stderr")
            value = rows[-1].get("lyapunov_status", "") if lam is None else f"{lam:.3g} +- {err:.2g} bits/s"
            print(f"[lyapunov {len(rows)}] {name} m={m:g}: {value} ({time.perf_counter() - t0:.1f} s)",
                  file=sys.stderr, flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.tape_mass_dynamics", description=__doc__)
    ap.add_argument("--out", default="tape_mass_dynamics")
    ap.add_argument("--quick", action="store_true", help="0.3 s transient and window (a smoke test)")
    ap.add_argument("--t-transient", type=float, default=2.0)
    ap.add_argument("--window", type=float, default=4.0)
    ap.add_argument("--lyapunov-time", type=float, default=1.0)
    ap.add_argument("--no-lyapunov", action="store_true")
    ap.add_argument("--no-diagram", action="store_true")
    ap.add_argument("--figures", metavar="DIR", help="only draw the figures from --out's data into DIR")
    ap.add_argument("--only-lyapunov", action="store_true",
                    help="only the Lyapunov exponents, into lyapunov.csv|json (a second process beside --no-lyapunov)")
    ap.add_argument("--only-diagram", action="store_true",
                    help="only the orbit diagram and the F(t) windows (a third process beside --no-diagram)")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if a.figures:
        figures(out, Path(a.figures))
        return 0
    out.mkdir(parents=True, exist_ok=True)
    if a.only_lyapunov:
        return _lyapunov_only(out, 0.2 if a.quick else a.lyapunov_time)
    tt, win = (0.3, 0.3) if a.quick else (a.t_transient, a.window)
    if a.only_diagram:
        if not a.no_diagram:  # --only-diagram --no-diagram: the F(t) windows alone
            _diagram(out, tt, win)
        _windows(out, 0.3 if a.quick else 0.5)
        return 0
    lyap_T = None if a.no_lyapunov else (0.2 if a.quick else a.lyapunov_time)
    if a.quick:
        LYAPUNOV["t_transient"] = 0.1
    rows = []
    total = len(REGIMES) * len(MASSES)
    for name, V, I in REGIMES:
        for m in MASSES:
            t0 = time.perf_counter()
            row = {"regime": name, **measure_point(V, I, m, t_transient=tt, window=win)}
            rows.append(row)
            _write_table(rows, out, "measures")
            print(f"[{len(rows)}/{total}] {name} V={V:g} I={I:g} m={m:g}: {row.get('label', row['status'])}, "
                  f"{row.get('slips_per_s', math.nan):.4g} slips/s ({time.perf_counter() - t0:.1f} s)",
                  file=sys.stderr, flush=True)
    if not a.no_diagram:
        _diagram(out, tt, win)
        _windows(out, 0.3 if a.quick else 0.5)
    if lyap_T is not None:
        for k, row in enumerate(rows):
            if row["m"] in LYAPUNOV_SKIP:
                continue
            t0 = time.perf_counter()
            row.update(measure_lyapunov(row["V"], row["I"], row["m"], lyap_T))
            _write_table(rows, out, "measures")
            lam, err = row.get("lyapunov_bits"), row.get("lyapunov_stderr")
            value = row.get("lyapunov_status", "") if lam is None else f"{lam:.3g} +- {err:.2g} bits/s"
            print(f"[lyapunov {k + 1}/{len(rows)}] {row['regime']} m={row['m']:g}: {value} "
                  f"({time.perf_counter() - t0:.1f} s)", file=sys.stderr, flush=True)
    print(f"wrote {out}/measures.csv|json, diagram.csv|json, windows.json", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
