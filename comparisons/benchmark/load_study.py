"""The constant-load study (docs/constant-load.md): force-controlled peeling measured.

``python -m comparisons.benchmark.load_study {limit,stability,phase,duration,figures,all} [--out DIR]``
writes CSV and JSON tables (and, for ``figures``, PNGs) and reports progress on stderr:

* ``limit`` (:func:`mass_limit`): the M → ∞ limit.  With ``F_L`` the time-mean pull force ⟨F⟩ of the
  velocity-controlled run and ``V_p(0) = V``, the load mode's jump times, forces at the jumps and pull speed
  approach the velocity-controlled run's as 1/M; the power law is fitted (:func:`fit_power_law`).  Massless
  tape (``method="regularized"`` at the same ε) and a tape mass (``method="smooth"`` at the same m).
* ``stability`` (:func:`fixed_points`): the load mode's fixed points ``α = 0, v = V_p = V*, F = F_L`` with
  ``f(V*, V) = F_L`` (one per branch: AB, the unstable branch, CD) and the eigenvalues of the analytic
  Jacobian (``peelapprox.kernels.variant_field("eps_load")``) there; the velocity mode's fixed point beside.
* ``phase`` (:func:`phase_diagram`): each (F_L, M) (and I) classified by a run from the default initial state
  (:func:`classify`): ``"stick-slip"`` (jumps until the end), ``"transient->AB"`` / ``"transient->CD"``
  (jumps stop and the orbit settles on the steady peeling of that branch), ``"runaway"`` (V_p still growing
  on CD at the end), ``"breakdown:<reason>"`` (the model ends: the front arrests, the tape goes slack).
* ``duration``: how long stick-slip lasts at the balanced load ``F_L = ⟨F⟩`` against M (a power law).
* ``figures``: docs/figures/load_*.png.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import brentq

from exact import METHODS, ModelBreakdown, SolverBudgetExceeded, SolverFailure, model_of, simulate
from peelapprox import PeelParams, branch_inverse, branch_structure, peel_force
from peelapprox.io import write_rows
from peelapprox.kernels import (
    compiled_law,
    regularized_field_jacobian,
    regularized_parameters,
    variant_field,
    variant_parameters,
)
from peelapprox.plotting import save_figure

from .eps import fit_power_law

__all__ = ["mass_limit", "fixed_points", "classify", "phase_diagram", "stick_slip_duration", "balanced_load",
           "cycle_means", "load_figures", "main"]

Say = Callable[[str], None]
EPS = 1e-7  #: the paper's ε, for the massless tape (method="regularized")


def _quiet(msg: str) -> None:
    """No progress output."""


def _mean_force(tr: Any) -> float:
    """The time mean of F over the stored steps (trapezoid rule) [N]."""
    return float(np.trapezoid(tr.F, tr.t) / (tr.t[-1] - tr.t[0]))


def mass_limit(V: float = 1.0, I: float = 1e-5, masses: Sequence[float] = (1e1, 1e2, 1e3, 1e4, 1e5, 1e6), *,
               tape_mass: float | None = None, t_end: float = 0.2, rtol: float = 1e-10, solver: str = "LSODA",
               progress: Say = _quiet) -> list[dict[str, Any]]:
    """Deviation of the load mode (``F_L = ⟨F⟩``, ``V_p(0) = V``) from velocity control, one row per M.

    Rows: ``M``, ``n_ref`` and ``n_load`` (jumps in ``[0, t_end]``), ``dt_jump`` = max |Δt| over the common
    jumps [s], ``dF_jump`` = max |ΔF| there [N], ``dVp`` = max |V_p − V| over the run [m/s], ``F_L`` [N].
    ``tape_mass=None``: massless tape, the ε-scheme at ε = 1e-7 on both sides; else the tape-mass model
    (``method="smooth"``) at that m on both sides.
    """
    base: dict[str, Any] = dict(V=V, I=I, tape_mass=tape_mass)
    # the model's first method on a scipy solver (regularized for the massless tape, smooth with a tape mass): it
    # solves the model under the load too
    method = next(n for n in model_of(PeelParams(**base)).methods if METHODS[n].solvers)
    kw: dict[str, Any] = dict(solver=solver, rtol=rtol, method=method)
    if method == "regularized":  # the ε-scheme at the paper's ε
        kw.update(eps=EPS)
    case = "massless" if tape_mass is None else f"tape m={tape_mass:g} kg"
    progress(f"limit {case}: velocity-controlled reference, {t_end} s")
    ref = simulate(PeelParams(**base), t_end, **kw)
    F_L = _mean_force(ref)
    rows = []
    for M in masses:
        progress(f"limit {case}: M = {M:g} kg")
        tl = simulate(PeelParams(**base, loading="load", load_mass=M, load=F_L), t_end, **kw)
        n = min(len(ref.jumps), len(tl.jumps))
        rows.append(dict(case=case, V=V, I=I, tape_mass=tape_mass or 0.0, M=M, F_L=F_L, n_ref=len(ref.jumps),
                         n_load=len(tl.jumps),
                         dt_jump=float(np.max(np.abs(tl.jumps.t[:n] - ref.jumps.t[:n]))) if n else math.nan,
                         dF_jump=float(np.max(np.abs(tl.jumps.F[:n] - ref.jumps.F[:n]))) if n else math.nan,
                         dVp=float(np.max(np.abs(np.asarray(tl.Vp) - V))), wall=tl.stats.wall_time))
    return rows


def limit_fits(rows: Sequence[dict[str, Any]], m_min: float = 100.0) -> list[dict[str, Any]]:
    """Power laws ``dev = C M^p`` of each deviation over the rows with ``M >= m_min`` and the same jump count
    (:func:`fit_power_law`): one row per (case, measure) with ``C``, ``p`` and the largest relative residual."""
    out = []
    for case in dict.fromkeys(r["case"] for r in rows):
        sel = [r for r in rows if r["case"] == case and r["M"] >= m_min and r["n_load"] == r["n_ref"]]
        for key in ("dt_jump", "dF_jump", "dVp"):
            C, p, res = fit_power_law(np.array([r["M"] for r in sel]), np.array([r[key] for r in sel]))
            out.append(dict(case=case, measure=key, C=C, p=p, max_rel_residual=res, n=len(sel)))
    return out


def load_roots(F_L: float, V: float) -> list[tuple[str, float]]:
    """The speeds ``V*`` with ``f(V*, V) = F_L`` on each branch of the law at V: ``[(branch, V*), ...]`` with
    branch ``"AB"``, ``"unstable"`` (between the folds) or ``"CD"``; none below ``f(0+, V)``."""
    bs = branch_structure(V)
    if bs.f_max is None or bs.f_min is None or bs.v_max is None or bs.v_min is None:
        raise ValueError(f"V must give the law folds (stick-slip under velocity control), got V={V!r}")
    out = []
    if bs.f_zero < F_L < bs.f_max:
        out.append(("AB", float(branch_inverse(F_L, V, "AB"))))
    if bs.f_min < F_L < bs.f_max:
        out.append(("unstable", float(brentq(lambda v: peel_force(v, V) - F_L, bs.v_max, bs.v_min, xtol=1e-14))))
    if F_L > bs.f_min:
        out.append(("CD", float(branch_inverse(F_L, V, "CD"))))
    return out


def _spectrum(J: np.ndarray) -> dict[str, Any]:
    ev = np.linalg.eigvals(J)
    ev = ev[np.argsort(-ev.real)]
    fast = np.abs(ev) > 1e5  # the ε-scheme's fast direction (|λ| ~ f'/ε) apart from the slow ones
    slow = ev[~fast]
    return dict(max_re=float(ev[0].real), fast=float(ev[fast][0].real) if fast.any() else math.nan,
                slow_max_re=float(slow[0].real), slow_im=float(abs(slow[0].imag)),
                stable=bool(ev[0].real < 0), eigenvalues=" ".join(f"{z.real:.6g}{z.imag:+.6g}j" for z in ev))


def fixed_points(V: float = 1.0, I: float = 1e-5, loads: Sequence[float] = (150, 199, 210, 236, 260, 285, 300),
                 masses: Sequence[float] = (0.1, 1.0, 25.0, 1e3), *, eps: float = EPS) -> list[dict[str, Any]]:
    """Linear stability of the load mode's fixed points (``α = 0, ω = V*/R, F = F_L, v = V_p = V*``) on the
    massless ε-scheme, and of the velocity mode's (``M = inf``, ``F_L = f(V, V)``).  Rows: ``F_L``, ``M``,
    ``branch``, ``V_star``, ``residual`` (max |rate| there: 0 up to rounding), the spectrum
    (:func:`_spectrum`: ``max_re``, the fast eigenvalue, the slowest pair's real and imaginary parts)."""
    fun, jac = variant_field("eps_load")
    rows: list[dict[str, Any]] = []
    for M in masses:
        for F_L in loads:
            p = PeelParams(V=V, I=I, loading="load", load_mass=M, load=F_L)
            cl = compiled_law(p.force, V)
            q = variant_parameters(p, eps, M, F_L)
            for branch, vs in load_roots(F_L, V):
                y = np.array([0.0, vs / p.R, F_L, vs, vs])
                rows.append(dict(mode="load", V=V, I=I, M=M, F_L=F_L, branch=branch, V_star=vs,
                                 residual=float(np.max(np.abs(fun(y, q, cl.fn, cl.coef)))),
                                 **_spectrum(jac(y, q, cl.fn, cl.coef))))
    p = PeelParams(V=V, I=I)
    y = np.array([0.0, V / p.R, float(peel_force(V, V)), V])
    rows.append(dict(mode="velocity", V=V, I=I, M=math.inf, F_L=float(y[2]), branch="unstable", V_star=V,
                     residual=0.0, **_spectrum(regularized_field_jacobian(y, regularized_parameters(p, eps,
                                                                                                    ("paper",))))))
    return rows


def classify(V: float, I: float, F_L: float, M: float, t_end: float, *, rtol: float = 1e-6,
             tail: float = 0.25, keep: bool = False, max_wall: float = 300.0,
             max_steps: int | None = None) -> dict[str, Any]:
    """Run the massless tape under the load (ε = 1e-7, LSODA) from the default initial state and classify it.

    Jumps in the last ``tail`` fraction of ``[0, t_end]``: ``"stick-slip"``, or ``"runaway"`` if V_p is then
    above the CD fixed point's speed and still rising.  Else ``"transient->AB"`` / ``"transient->CD"`` by the
    final v (below / above the law's inflection), with ``duration`` = the last jump's time (0: no jump).
    A :class:`ModelBreakdown` is ``"breakdown:<reason>"`` at its t.  A solver failure (LSODA at rtol 1e-6 can
    step v below 0 on deep AB, where v ~ 1e-5 m/s and f' is large: the driver reports that overshoot as a
    SolverFailure, since the field at rest would accelerate the front again) or an ``"arrest"`` is retried once
    at ``rtol * 1e-3`` (up to
    2e6 steps; ``max_steps`` at first, None: ``simulate``'s default; and ``max_wall`` s each); failing again it
    is ``"unresolved:<exception>"``, not a physical verdict.
    ``keep=True`` adds the trajectory under ``"trajectory"``.
    """
    p = PeelParams(V=V, I=I, loading="load", load_mass=M, load=F_L)
    bs = branch_structure(V)
    row: dict[str, Any] = dict(V=V, I=I, M=M, F_L=F_L, t_end=t_end, f_min=bs.f_min, f_max=bs.f_max)
    t0 = time.perf_counter()
    for tol, steps in ((rtol, max_steps), (rtol * 1e-3, 2_000_000)):  # a solver failure: once more, tighter
        try:
            tr = simulate(p, t_end, method="regularized", solver="LSODA", eps=EPS, rtol=tol, max_steps=steps,
                          max_wall=max_wall)
            break
        except (ModelBreakdown, SolverFailure, SolverBudgetExceeded) as exc:
            failed: Any = exc
            numerical = not isinstance(exc, ModelBreakdown) or exc.reason == "arrest"  # v <= 0 may be overshoot
            if not numerical or tol != rtol:
                cls = (f"breakdown:{exc.reason}" if isinstance(exc, ModelBreakdown)
                       else f"unresolved:{type(exc).__name__}")
                return {**row, "cls": cls, "rtol": tol, "t_stop": float(failed.t), "n_jumps": -1,
                        "duration": math.nan, "Vp_end": math.nan, "v_end": math.nan, "F_end": math.nan,
                        "wall": time.perf_counter() - t0}
    row["rtol"] = tol
    j = tr.jumps
    Vp = np.asarray(tr.Vp)
    late = len(j) and j.t[-1] > (1.0 - tail) * t_end
    cd = [v for b, v in load_roots(F_L, V) if b == "CD"]
    if late:
        rising = Vp[-1] > Vp[tr.t >= (1.0 - tail) * t_end][0]
        cls = "runaway" if (cd and Vp[-1] > cd[0] and rising) else "stick-slip"
    else:
        cls = "transient->AB" if tr.v[-1] <= bs.v_inflection else "transient->CD"
    row.update(cls=cls, t_stop=t_end, n_jumps=len(j), duration=float(j.t[-1]) if len(j) else 0.0,
               Vp_end=float(Vp[-1]), v_end=float(tr.v[-1]), F_end=float(tr.F[-1]), wall=tr.stats.wall_time)
    if keep:
        row["trajectory"] = tr
    return row


def phase_diagram(V: float = 1.0, I_values: Sequence[float] = (1e-5,),
                  loads: Sequence[float] = (180, 210, 236, 260, 285, 300), masses: Sequence[float] = (0.1, 1, 10, 30),
                  *, t_end: Callable[[float], float] = lambda M: 3.0 + 0.5 * M,
                  progress: Say = _quiet) -> list[dict[str, Any]]:
    """:func:`classify` over the grid ``I × M × F_L`` (``t_end(M)``: the horizon, longer for heavier loads)."""
    rows = []
    n, k = len(I_values) * len(masses) * len(loads), 0
    for I in I_values:
        for M in masses:
            for F_L in loads:
                k += 1
                progress(f"phase {k}/{n}: I={I:g} M={M:g} kg F_L={F_L:g} N")
                rows.append(classify(V, I, F_L, M, t_end(M)))
    return rows


def balanced_load(V: float = 1.0, I: float = 1e-5) -> float:
    """The long-run mean pull force of velocity-controlled stick-slip at V [N]: the hybrid solver (ε → 0,
    rtol 1e-9) over [1, 41] s (the first second dropped); 238.601 N at V = 1, I = 1e-5 (its 10 s windows agree
    to 0.07 N)."""
    return _mean_force(simulate(PeelParams(V=V, I=I), 41.0, rtol=1e-9, t_transient=1.0))


def cycle_means(tr: Any) -> np.ndarray:
    """Per stick-slip cycle (from one AB→CD jump to the next): ``(t_mid, ⟨V_p⟩, ⟨F⟩)``, time means over the
    stored steps; shape (n_cycles, 3).  Their slope d⟨F⟩/d⟨V_p⟩ is the cycle-averaged force's dependence on
    the pull speed, which decides whether stick-slip under a load can be stationary (docs/constant-load.md)."""
    up = tr.jumps.t[tr.jumps.from_branch == 0]
    out = []
    for a, b in zip(up[:-1], up[1:]):
        w = (tr.t >= a) & (tr.t <= b)
        t = tr.t[w]
        out.append((0.5 * (a + b), np.trapezoid(tr.Vp[w], t) / (b - a), np.trapezoid(tr.F[w], t) / (b - a)))
    return np.array(out, dtype=float).reshape(-1, 3)


def stick_slip_duration(V: float = 1.0, I: float = 1e-5, masses: Sequence[float] = (1, 3, 10, 30), *,
                        F_L: float | None = None,
                        progress: Say = _quiet) -> tuple[list[dict[str, Any]], dict[str, float]]:
    """How long stick-slip lasts at the balanced load ``F_L = ⟨F⟩`` (default :func:`balanced_load`) against M
    (horizon ``3 + 0.4 M`` s), and the power law ``duration = C M^p`` fitted to the transient ones.  Each row
    adds ``dFdVp``: the least-squares slope of the cycle means (:func:`cycle_means`) ⟨F⟩ against ⟨V_p⟩ over the
    cycles with ⟨V_p⟩ above the AB fold's speed v_max (0.506 m/s at V = 1; NaN below 5 cycles)."""
    F_L = balanced_load(V, I) if F_L is None else F_L
    v_ab = float(branch_structure(V).v_max or 0.0)
    rows = []
    for M in masses:
        progress(f"duration: M = {M:g} kg (F_L = {F_L:.6g} N)")
        row = classify(V, I, F_L, M, 3.0 + 0.4 * M, keep=True, max_steps=2_000_000)
        cyc = cycle_means(row.pop("trajectory")) if "trajectory" in row else np.empty((0, 3))
        above = cyc[cyc[:, 1] > v_ab]  # cycles while V_p is above the AB fold's speed
        row["dFdVp"] = float(np.polyfit(above[:, 1], above[:, 2], 1)[0]) if len(above) >= 5 else math.nan
        row["n_cycles"] = len(cyc)
        rows.append(row)
    ok = [r for r in rows if r["cls"].startswith("transient") and r["duration"] > 0]
    if len(ok) < 3:
        return rows, dict(C=math.nan, p=math.nan, max_rel_residual=math.nan, n=len(ok), F_L=F_L)
    C, p, res = fit_power_law(np.array([r["M"] for r in ok]), np.array([r["duration"] for r in ok]))
    return rows, dict(C=C, p=p, max_rel_residual=res, n=len(ok), F_L=F_L)


_MARKERS = {"stick-slip": ("o", "C3"), "transient->AB": ("v", "C0"), "transient->CD": ("^", "C2"),
            "runaway": (">", "C1")}


def _save(plt: Any, fig: Any, path: Path, paths: list[Path]) -> None:
    """Lay out, write (80 dpi) and close ``fig``; append ``path`` to ``paths``."""
    fig.tight_layout()
    save_figure(fig, path, dpi=80)
    plt.close(fig)
    paths.append(path)


def _plot_tables(plt: Any, tables: Path, out: Path) -> list[Path]:
    """``load_limit.png`` and ``load_phase.png`` from the tables the other parts wrote (those present)."""
    import json

    paths: list[Path] = []
    if (tables / "load_limit.json").is_file():
        rows = json.loads((tables / "load_limit.json").read_text())
        fig, ax = plt.subplots(figsize=(6, 4))
        for case, ls in zip(dict.fromkeys(r["case"] for r in rows), ("-", "--")):
            sel = [r for r in rows if r["case"] == case]
            M = [r["M"] for r in sel]
            for key, lab, c in (("dt_jump", "max |Δt_jump| [s]", "C0"), ("dF_jump", "max |ΔF_jump| [N]", "C1"),
                                ("dVp", "max |V_p − V| [m/s]", "C2")):
                ax.loglog(M, [r[key] for r in sel], ls, marker="o", ms=3, color=c, label=f"{lab}, {case}")
        ax.set_xlabel("loading mass M [kg]")
        ax.set_ylabel("deviation from velocity control")
        ax.legend(fontsize=6)
        ax.set_title("Load mode → velocity control as 1/M (V = 1, I = 1e-5, 0.2 s)", fontsize=9)
        _save(plt, fig, out / "load_limit.png", paths)
    if (tables / "load_phase.json").is_file():
        rows = [r for r in json.loads((tables / "load_phase.json").read_text()) if r["I"] == 1e-5]
        fig, ax = plt.subplots(figsize=(6, 4))
        for cls in dict.fromkeys(r["cls"] for r in rows):
            mk, c = _MARKERS.get(cls, ("x", "k"))
            sel = [r for r in rows if r["cls"] == cls]
            ax.semilogx([r["M"] for r in sel], [r["F_L"] for r in sel], mk, color=c, ms=8, ls="", label=cls)
        for level, lab in ((rows[0]["f_min"], "f_min"), (rows[0]["f_max"], "f_max")):
            ax.axhline(level, color="k", lw=0.6, ls=":")
            ax.text(ax.get_xlim()[0], level, f" {lab}", fontsize=7, va="bottom")
        ax.set_xlabel("loading mass M [kg]")
        ax.set_ylabel("load F_L [N]")
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1, 1))
        ax.set_title("Constant load from V_p(0) = V = 1 (I = 1e-5): end state", fontsize=9)
        _save(plt, fig, out / "load_phase.png", paths)
    return paths


def load_figures(out: Path, tables: Path | None = None, progress: Say = _quiet) -> list[Path]:
    """docs/figures/load_*.png: F(t), V_p(t) and v(t) of two transient runs, one ending on AB and one on CD,
    and of a persistent one (``load_runs.png``, fresh runs), and from the tables in ``tables`` (if written)
    the 1/M limit (``load_limit.png``) and the phase diagram (``load_phase.png``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    paths = [] if tables is None else _plot_tables(plt, tables, out)
    F_b = 238.60124090927533  # balanced_load(1.0, 1e-5), not recomputed here
    cases = [(F_b, 10.0, 4.0, "F_L = ⟨F⟩ = 238.6 N, M = 10 kg:\ntransient, ends in slow peeling (AB)"),
             (285.0, 10.0, 3.0, "F_L = 285 N, M = 10 kg:\ntransient, ends in fast peeling (CD)"),
             (F_b, 1.0, 5.0, "F_L = ⟨F⟩ = 238.6 N, M = 1 kg:\nstick-slip persists (V_p settles near 2.9 m/s)")]
    fig, axes = plt.subplots(3, 3, figsize=(12, 6.5), sharex="col")
    for col, (F_L, M, T, title) in enumerate(cases):
        progress(f"figure: F_L={F_L:.6g} M={M} ({T} s)")
        tr = classify(1.0, 1e-5, F_L, M, T, keep=True, max_steps=2_000_000)["trajectory"]
        axes[0, col].plot(tr.t, tr.F, lw=0.4)
        axes[0, col].axhline(F_L, color="k", ls=":", lw=0.8)
        axes[0, col].set_title(title, fontsize=9)
        axes[1, col].plot(tr.t, tr.Vp, lw=0.6)
        axes[2, col].semilogy(tr.t, np.maximum(tr.v, 1e-6), lw=0.4)
        axes[2, col].set_xlabel("t [s]")
    for ax, lab in zip(axes[:, 0], ("F [N]", "V_p [m/s]", "v [m/s]")):
        ax.set_ylabel(lab)
    fig.suptitle("Constant load, massless tape (V = 1 law, I = 1e-5 kg m², ε = 1e-7)", fontsize=10)
    _save(plt, fig, out / "load_runs.png", paths)
    return paths


def _write(out: Path, name: str, rows: Sequence[dict[str, Any]], say: Say) -> None:
    for ext in (".csv", ".json"):
        say(f"wrote {write_rows(out / (name + ext), rows)}")


def main(argv: Sequence[str] | None = None) -> int:
    """The study's command line (module docstring)."""
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.load_study", description=__doc__.split("\n")[0])
    ap.add_argument("part", choices=("limit", "stability", "phase", "duration", "figures", "all"))
    ap.add_argument("--out", type=Path, default=Path("load_study"), help="directory of the tables (default load_study)")
    ap.add_argument("--figures", type=Path, default=Path("docs/figures"), help="directory of the PNGs")
    a = ap.parse_args(argv)
    out: Path = a.out
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()

    def say(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)

    parts = ("limit", "stability", "phase", "duration", "figures") if a.part == "all" else (a.part,)
    if "limit" in parts:
        rows = mass_limit(progress=say) + mass_limit(tape_mass=1e-4, progress=say)
        _write(out, "load_limit", rows, say)
        _write(out, "load_limit_fit", limit_fits(rows), say)
    if "stability" in parts:
        _write(out, "load_fixed_points", fixed_points(), say)
    if "phase" in parts:
        rows = phase_diagram(progress=say)
        rows += phase_diagram(I_values=(1e-6, 1e-4, 1e-3), loads=(236, 260), masses=(1, 10), progress=say)
        _write(out, "load_phase", rows, say)
    if "duration" in parts:
        rows, fit = stick_slip_duration(progress=say)
        _write(out, "load_duration", rows, say)
        _write(out, "load_duration_fit", [fit], say)
    if "figures" in parts:
        for path in load_figures(a.figures, out, progress=say):
            say(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
