"""The paper's Figures 2-9, regenerated from our exact solutions (``peelapprox figures``).

Each entry of :data:`FIGURES` names the paper's caption, the parameters and what we draw; the drawing
functions take an output directory and return the files written.  Figures 8-9 are the harness's
approximate-vs-exact overlays (:mod:`comparisons._scenes`).  Where the paper's run cannot be reproduced
exactly (its initial state is not given) the start we use is stated in ``note``.  matplotlib is imported
lazily, inside the drawing functions.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from peelapprox import PeelParams, branch_structure, peel_force
from peelapprox.plotting import new_figure, save_figure

__all__ = ["Figure", "FIGURES", "make_figures", "figures_markdown"]


@dataclass(frozen=True)
class Figure:
    """One of the paper's figures: its caption (abridged), our parameters and notes, and the drawer."""

    name: str
    caption: str
    params: str
    note: str
    draw: Callable[[str], list[str]]


def _sim(V, I, t_end, *, t_transient=0.0, alpha0=0.0, **kw):
    from exact import simulate

    return simulate(PeelParams(V=V, I=I), t_end, alpha0=alpha0, t_transient=t_transient, rtol=1e-10, **kw)


def _f_curve(ax, V, vlo=1e-4, vhi=30.0, **kw):
    v = np.logspace(np.log10(vlo), np.log10(vhi), 800)
    ax.plot(v, peel_force(v, V), "k-", lw=kw.pop("lw", 2), label=kw.pop("label", f"f(v, V={V:g})"), **kw)


def _phase(ax, v, F, branch, V, title):
    _f_curve(ax, V)
    for br, c in ((0, "C0"), (1, "C3")):
        m = branch == br
        ax.plot(v[m], F[m], ".", ms=1.5, color=c, label="AB" if br == 0 else "CD")
    ax.set_xscale("log")
    lo, hi = float(np.min(F)), float(np.max(F))
    pad = 0.15 * (hi - lo) if hi > lo else 0.05 * abs(hi) + 1.0
    ax.set_ylim(lo - pad, hi + pad)  # the orbit's range: f(v) rises to ~1400 N beyond it and would squash it
    ax.set_xlabel("v [m/s]")
    ax.set_ylabel("F [N]")
    ax.set_title(title, fontsize=9)


def _save(fig, out, name):
    path = os.path.join(out, f"{name}.png")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)  # reproducible bytes; a figure made without pyplot: nothing to close
    return [path]


def _fig2(out):
    fig = new_figure(figsize=(6, 4.2), layout=None)
    ax = fig.subplots()
    for V, ls in ((1, "-"), (2, "--"), (4, "-."), (6, ":")):
        v = np.logspace(-4, np.log10(30), 800)
        ax.semilogx(v, peel_force(v, V), "k" + ls, label=f"V = {V}")
        bs = branch_structure(V)
        if bs.has_folds:
            ax.plot([bs.v_max, bs.v_min], [bs.f_max, bs.f_min], "ko", ms=3)
    ax.set_xlabel("v [m/s]")
    ax.set_ylabel("f(v, V) [N]")
    ax.legend()
    ax.set_title("Fig. 2(a): f(v, V) (Eq. fvV); dots: the folds", fontsize=9)
    return _save(fig, out, "fig2")


def _fig3(out):
    fig = new_figure(figsize=(10, 7), layout=None)
    axs = fig.subplots(2, 2)
    tr = _sim(0.4, 1e-5, 2.0, t_transient=1.0, alpha0=0.2)
    _phase(axs[0, 0], tr.v, tr.F, tr.branch, 0.4, "(a) V=0.4, I=1e-5: v–F (start α0 = 0.2)")
    tr = _sim(1.0, 1e-5, 1.0, t_transient=0.5)
    _phase(axs[0, 1], tr.v, tr.F, tr.branch, 1.0, "(b) V=1, I=1e-5: v–F")
    m = tr.t <= 0.7
    axs[1, 0].plot(tr.t[m], tr.alpha[m], lw=0.8)
    axs[1, 0].set_xlabel("t [s]")
    axs[1, 0].set_ylabel("α [rad]")
    axs[1, 0].set_title("(c) V=1, I=1e-5: α(t)", fontsize=9)
    tr = _sim(2.0, 1e-5, 42.0, t_transient=40.0)
    axs[1, 1].plot(tr.t, tr.F, lw=0.8)
    axs[1, 1].set_xlabel("t [s]")
    axs[1, 1].set_ylabel("F [N]")
    axs[1, 1].set_title("(d) V=2, I=1e-5: F(t) after 40 s (ours: period 7; paper: 4)", fontsize=9)
    axs[0, 0].legend(fontsize=7)
    return _save(fig, out, "fig3")


def _fig4(out):
    from peelapprox import periodicity, return_map

    tr = _sim(1.0, 1e-2, 40.0, t_transient=30.0)
    t_k, x = return_map(tr, with_times=True)
    n = periodicity(x).period or 1  # one cycle of the return map (period 8 here)
    t0, t1 = t_k[0], t_k[n] if t_k.size > n else tr.t[-1]
    m = (tr.t >= t0) & (tr.t <= t1)
    fig = new_figure(figsize=(10, 7), layout=None)
    axs = fig.subplots(2, 2)
    _phase(axs[0, 0], tr.v[m], tr.F[m], tr.branch[m], 1.0, "(a) V=1, I=1e-2: v–F, one cycle")
    for ax, y, lab, name in ((axs[0, 1], tr.alpha, "α [rad]", "(b) α(t)"), (axs[1, 0], tr.F, "F [N]",
                             f"(c) F(t) (return map: {_period_label(return_map(tr))})"),
                             (axs[1, 1], tr.v, "v [m/s]", "(d) v(t)")):
        ax.plot(tr.t[m], y[m], lw=0.8)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(lab)
        ax.set_title(name, fontsize=9)
    axs[1, 1].set_yscale("log")
    return _save(fig, out, "fig4")


def _period_label(x):
    from peelapprox import periodicity

    return periodicity(x).label if len(x) > 1 else "–"


def _fig5(out):
    tr = _sim(4.0, 1e-2, 22.0, t_transient=20.0, alpha0=0.3)
    fig = new_figure(figsize=(10, 7), layout=None)
    axs = fig.subplots(2, 2)
    axs[0, 0].plot(tr.t, tr.F, lw=0.6)
    axs[0, 0].set_ylabel("F [N]")
    axs[0, 0].set_title("(a) V=4, I=1e-2: F(t) (start α0 = 0.3, after 20 s)", fontsize=9)
    axs[0, 1].plot(tr.t, tr.alpha, lw=0.6)
    axs[0, 1].set_ylabel("α [rad]")
    axs[0, 1].set_title("(b) α(t)", fontsize=9)
    _phase(axs[1, 0], tr.v, tr.F, tr.branch, 4.0, "(c) v–F")
    axs[1, 1].plot(tr.t, tr.v, lw=0.6)
    axs[1, 1].set_yscale("log")
    axs[1, 1].set_ylabel("v [m/s]")
    axs[1, 1].set_title("(d) v(t)", fontsize=9)
    for ax in (axs[0, 0], axs[0, 1], axs[1, 1]):
        ax.set_xlabel("t [s]")
    return _save(fig, out, "fig5")


_FIG6_V = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5)


def fig6_data(Vs=_FIG6_V, Is=(1e-5, 1e-2), *, t_transient=20.0,
              window=20.0) -> dict[float, np.ndarray]:
    """Mean force drop [N] per V for each I (NaN where a run breaks down or has no slip)."""
    from exact import ModelBreakdown
    from peelapprox import force_drops

    out = {}
    for I in Is:
        row = []
        for V in Vs:
            try:
                d = force_drops(_sim(V, I, t_transient + window, t_transient=t_transient, save="jumps"))
                row.append(float(d.mean()) if d.size else np.nan)
            except ModelBreakdown:
                row.append(np.nan)
        out[I] = np.array(row)
    return out


def _fig6(out):
    from peelapprox import force_drops

    data = fig6_data(_FIG6_V)
    fig = new_figure(figsize=(11, 4.2), layout=None)
    axs = fig.subplots(1, 2)
    ax = axs[0]
    for I, ls in ((1e-2, "--o"), (1e-5, ":s")):
        ax.plot(_FIG6_V, data[I], "k" + ls, label=f"I = {I:g}")
    ax.set_xlabel("V [m/s]")
    ax.set_ylabel("mean force drop ΔF [N]")
    ax.legend()
    ax.set_title("Fig. 6: mean force drop vs V (20 s after a 20 s transient)", fontsize=9)
    # ours: the distribution behind the means (I = 1e-2: many small drops of the rapid-jump cascades)
    for V in (1.0, 2.0, 4.0):
        d = force_drops(_sim(V, 1e-2, 40.0, t_transient=20.0, save="jumps"))
        axs[1].hist(d, bins=np.linspace(0, max(1.0, float(d.max())), 60), histtype="step", density=True,
                    label=f"V = {V:g} ({d.size} drops, median {np.median(d):.1f} N)")
    axs[1].set_xlabel("force drop ΔF [N]")
    axs[1].set_ylabel("probability density [1/N]")
    axs[1].set_yscale("log")
    axs[1].legend(fontsize=7)
    axs[1].set_title("ours: drop-size distribution, I = 1e-2", fontsize=9)
    return _save(fig, out, "fig6")


def _fig7(out):
    tr = _sim(0.4, 1e-3, 22.0, t_transient=20.0, alpha0=0.2)
    fig = new_figure(figsize=(11, 4.2), layout=None)
    axs = fig.subplots(1, 2)
    _phase(axs[0], tr.v, tr.F, tr.branch, 0.4, "Fig. 7: V=0.4, I=1e-3 in the v–F plane (start α0 = 0.2)")
    G = tr.F * (1 + tr.closure_c)  # the pull side of CONSTR, F (1 - cos θ)
    _phase(axs[1], tr.v, G, tr.branch, 0.4, "the same orbit in the v–F(1+sin α) plane: on f's stable branches")
    axs[1].set_ylabel("F (1 + sin α) [N]")
    for ax in axs:
        ax.set_xlim(1e-3, 30)
    axs[0].legend(fontsize=7)
    return _save(fig, out, "fig7")


def _fig89(out):
    from ._report import run_compare

    run_compare(["case-I-times", "case-II-point-a"], statistics_runs=(), figures_dir=out)
    return [os.path.join(out, n) for n in ("fig8_ab.png", "fig8_cd.png", "fig9.png")]


FIGURES: dict[str, Figure] = {f.name: f for f in (
    Figure("fig2", "(a) f(v, V) against v (log axis) for V = 1, 2, 4, 6; (b) the experimental G(v) curve.",
           "V = 1, 2, 4, 6", "Panel (b) is experimental data (Maugis & Barquins) and is not reproduced.", _fig2),
    Figure("fig3", "(a) v–F trajectory for V = 0.4, I = 1e-5 with f(v, V); (b) v–F for V = 1, I = 1e-5; "
                   "(c) α(t) for V = 1, I = 1e-5; (d) F(t) (period 4) for V = 2, I = 1e-5.",
           "I = 1e-5; V = 0.4, 1, 2",
           "(a) starts at α0 = 0.2 (from α0 = 0, V = 0.4 breaks down: v → 0 on AB); (d) from α0 = 0 our orbit "
           "is period 7; periods 2, 7 and 9 coexist there, we found no period 4 (docs/dynamics.md).", _fig3),
    Figure("fig4", "(a) v–F for a single cycle for I = 1e-2, V = 1 with f(v, V); (b) α(t), (c) F(t) (period 8), "
                   "(d) v(t).", "V = 1, I = 1e-2", "One period-8 cycle after a 30 s transient.", _fig4),
    Figure("fig5", "(a) F(t) for V = 4, I = 1e-2; (b) α(t); (c) the phase trajectory; (d) v(t).",
           "V = 4, I = 1e-2", "Start α0 = 0.3 (from α0 = 0 the transient lasts ~70 s); our return map has "
           "period 49 > 32 (docs/dynamics.md).", _fig5),
    Figure("fig6", "Mean force drop against V for I = 1e-2 (dashed) and I = 1e-5 (dotted).",
           "I = 1e-5, 1e-2; V = 0.5 … 4.5", "Drop = F at an AB→CD jump minus F at the next CD→AB jump.  Right "
           "panel (ours): the drop-size distributions behind the means at I = 1e-2.", _fig6),
    Figure("fig7", "A phase plot of a canard-type solution in the v–F plane for V = 0.4, I = 1e-3.",
           "V = 0.4, I = 1e-3", "Right panel (ours): the same orbit against F(1 + sin α) lies on the stable "
           "branches of f — it only looks like a canard in the v–F plane (docs/dynamics.md).", _fig7),
    Figure("fig8", "Approximate (continuous) vs exact v(t) for I = 1e-5, V = 1, AB branch; inset: CD branch.",
           "V = 1, I = 1e-5", "Drawn by the comparison harness (fig8_ab.png, fig8_cd.png).", _fig89),
    Figure("fig9", "Approximate vs exact v(t) for V = 1, I = 1e-2.", "V = 1, I = 1e-2",
           "Drawn by the comparison harness, with fig8.", _fig89),
)}


def make_figures(only=None, out: str = "docs/figures", *, progress: Callable[[str], None] | None = None
                 ) -> dict[str, list[str]]:
    """Draw the paper's figures (all, or the names in ``only``) into ``out``; returns the files per figure.

    """
    names = list(FIGURES) if not only else list(only)
    bad = [n for n in names if n not in FIGURES]
    if bad:
        raise ValueError(f"unknown figure(s) {bad}; known: {', '.join(FIGURES)}")
    os.makedirs(out, exist_ok=True)
    done: dict[str, list[str]] = {}
    for n in names:
        if n == "fig9" and "fig8" in done:
            done[n] = done["fig8"]
            continue
        if progress:
            progress(f"drawing {n}")
        done[n] = FIGURES[n].draw(out)
    return done


def figures_markdown(files: dict[str, list[str]], rel: str = "figures") -> str:
    """docs/figures.md: each figure with the paper's caption, our parameters and notes, and the image."""
    L = ["# The paper's figures, regenerated", "",
         "Generated by `peelapprox figures --out docs/figures` (this page: `--markdown docs/figures.md`). "
         "Captions are the paper's (abridged); *ours* says what differs.", ""]
    for n, fig in FIGURES.items():
        if n not in files:
            continue
        L += [f"## {n[:3].capitalize()}. {n[3:]}", "", f"**Paper:** {fig.caption}", "",
              f"**Parameters:** {fig.params}.  **Ours:** {fig.note}", ""]
        shown = [p for p in files[n] if not (n == "fig9" and "fig8" in os.path.basename(p))
                 and not (n == "fig8" and "fig9" in os.path.basename(p))]
        for p in shown:
            L += [f"![{n}]({rel}/{os.path.basename(p)})", ""]
    return "\n".join(L)
