"""The benchmark's two figures: work precision per scene and the ε study's delays with their power laws
(matplotlib is imported when a figure is drawn)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from peelapprox.plotting import new_figure, save_figure

from .report import BenchmarkReport
from .scenes import BENCH_SCENES

__all__ = ["plot_work_precision", "plot_eps_study"]


def plot_work_precision(rep: BenchmarkReport, path=None, *, fig: Any = None):
    """Time vs error, one panel per scene, one line per method family (log-log), into ``fig`` (an empty figure;
    default a new :func:`peelapprox.plotting.new_figure`), written to ``path`` when given; returns the figure."""
    scenes = [s.name for s in BENCH_SCENES]
    if fig is None:
        fig = new_figure(figsize=(5 * len(scenes), 4.2), layout=None)  # no pyplot: nothing to close
    axes = fig.subplots(1, len(scenes), squeeze=False)
    for ax, sc in zip(axes[0], scenes):
        rows = [r for r in rep.rows if r.scene == sc and math.isfinite(r.error) and math.isfinite(r.time)]
        keys = sorted({(r.method, r.solver, r.eps) for r in rows}, key=lambda k: (k[0] != "hybrid", k))
        for key in keys:
            rr = sorted([r for r in rows if (r.method, r.solver, r.eps) == key], key=lambda r: r.rtol)
            label = "hybrid (ε→0)" if key[0] == "hybrid" else f"{key[1]} ε={key[2]:.0e}"
            ax.loglog([r.error for r in rr], [r.time for r in rr], "o-" if key[0] == "hybrid" else ".--",
                      lw=2 if key[0] == "hybrid" else 1, label=label)
        ax.set_title(sc)
        ax.set_xlabel("error: max(|Δt|/T̄, |ΔF|/F) over the jumps")
        ax.set_ylabel("wall time [s]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    if path:
        save_figure(fig, path, dpi=110)
    return fig


def plot_eps_study(rep: BenchmarkReport, path=None, *, ax: Any = None, fig: Any = None):
    """Fold-passage delay vs ε (log-log) with the fitted power laws, on ``ax`` or into the (empty) figure ``fig``
    (default a new :func:`peelapprox.plotting.new_figure`), written to ``path`` when given; returns the figure."""
    if ax is None:
        ax = (fig if fig is not None else new_figure(figsize=(5.5, 4.2), layout=None)).subplots()
    fig = ax.figure
    for key, mk in (("delay_ab", "o"), ("delay_cd", "s")):
        ok = [e for e in rep.eps_rows if e.status == "ok" and getattr(e, key) > 0]
        name = key.replace("delay_", "").upper()
        line, = ax.loglog([e.eps for e in ok], [getattr(e, key) for e in ok], mk, label=f"{name} fold")
        if key in rep.eps_fit:
            C, p, _ = rep.eps_fit[key]
            x = np.logspace(-12, -5, 50)
            ax.loglog(x, C * x**p, "-", color=line.get_color(), label=f"{C:.3g} ε^{p:.3f}")
    ax.set_xlabel("ε")
    ax.set_ylabel("jump delay t_reg − t_hybrid [s]")
    ax.set_title("ε-regularised scheme (Radau, rtol 1e-10)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    if path:
        save_figure(fig, path, dpi=110)
    return fig
