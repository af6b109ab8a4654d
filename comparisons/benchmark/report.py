"""One benchmark run's results (:class:`BenchmarkReport`) and their rendering as the markdown tables of
docs/performance.md and as plain rows for CSV/JSON."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

from peelapprox.io import fmt_number as _g3  # 3 significant digits, None/NaN as a dash

from .eps import EpsRow
from .scenes import BENCH_SCENES
from .work_precision import WPRow, ratio_summary

__all__ = ["BenchmarkReport", "markdown", "rows_as_dicts"]


@dataclass
class BenchmarkReport:
    """Everything one ``peelapprox benchmark`` run measured."""

    rows: list[WPRow]
    references: list[dict]
    ratios: list[dict]
    eps_rows: list[EpsRow]
    eps_fit: dict
    small_eps: list[EpsRow]
    targets: list[dict]
    peers: tuple
    quick: bool
    wall_time: float
    machine: str = field(default="")
    compile: tuple = (math.nan, math.nan)


def markdown(rep: BenchmarkReport) -> str:
    """The report as markdown (the tables of docs/performance.md)."""
    L = [f"Measured in one run ({'--quick' if rep.quick else 'full'}), {rep.wall_time:.0f} s in all, on {rep.machine}.",
         f"Peers installed: {', '.join(rep.peers) or 'none'}.", ""]
    L += ["### References", "",
          "| scene | horizon [s] | jumps | branch-wise check: Δt/T̄ | ΔF/F |", "|---|---|---|---|---|"]
    for ref in rep.references:
        L.append(f"| {ref['scene']} | {ref['horizon']:g} | {ref['n_jumps']} | {_g3(ref['check_t'])} | "
                 f"{_g3(ref['check_F'])} |")
    L += ["", "### Work precision", "",
          "| scene | method | solver | ε | rtol | error (max of the two) | Δt/T̄ | ΔF/F | time [s] | steps | RHS "
          "| status |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rep.rows:
        eps = "0" if r.method == "hybrid" else f"{r.eps:.0e}"
        L.append(f"| {r.scene} | {r.method} | {r.solver} | {eps} | {r.rtol:.0e} | {_g3(r.error)} | {_g3(r.err_t)} | "
                 f"{_g3(r.err_F)} | {_g3(r.time)} | {r.steps} | {r.n_rhs} | {r.status} |")
    L += ["", "### Speed-up at matched error: summary", "",
          "The smallest ratio over each solver's runs (its best showing) per scene; details below.", "",
          "| solver | " + " | ".join(s.name for s in BENCH_SCENES) + " |",
          "|---|" + "---|" * len(BENCH_SCENES)]
    for solver, per in ratio_summary(rep.ratios).items():
        L.append(f"| {solver} | " + " | ".join(f"{per[s.name]:.0f}×" if s.name in per else "–"
                                                for s in BENCH_SCENES) + " |")
    L += ["", "### Speed-up at matched error", "",
          "Each regularised run against the fastest hybrid run with an error at most as large.", "",
          "| scene | run | its error | its time [s] | hybrid rtol | hybrid error | hybrid time [s] | ratio |",
          "|---|---|---|---|---|---|---|---|"]
    for m in rep.ratios:
        L.append(f"| {m['scene']} | {m['solver']} ε={m['eps']:.0e} rtol {m['rtol']:.0e} | {_g3(m['error'])} | "
                 f"{_g3(m['time'])} | {m['hybrid_rtol']:.0e} | {_g3(m['hybrid_error'])} | {_g3(m['hybrid_time'])} | "
                 f"{m['ratio']:.0f}× |")
    L += ["", "### ε study (V=1, I=1e-5: the first passage of each fold; Radau rtol 1e-10)", "",
          "| ε | delay at the AB fold [s] | delay at the CD fold [s] | max ΔF/F | time [s] | steps | status |",
          "|---|---|---|---|---|---|---|"]
    for e in rep.eps_rows:
        L.append(f"| {e.eps:.0e} | {_g3(e.delay_ab)} | {_g3(e.delay_cd)} | {_g3(e.err_F)} | {_g3(e.time)} | {e.steps} |"
                 f" {e.status} |")
    for key, (C, p, res) in rep.eps_fit.items():
        L += ["", f"Fit of the {key.replace('delay_', '').upper()} delay over ε ∈ [1e-12, 1e-5]: "
                  f"{C:.3g} · ε^{p:.4f} s (max relative residual {res:.1e})."]
    L += ["", "### Tiny ε in double precision (same horizon, rtol 1e-8)", "",
          "| ε | solver | delay at the AB fold [s] | delay at the CD fold [s] | time [s] | status |",
          "|---|---|---|---|---|---|"]
    for e in rep.small_eps:
        L.append(f"| {e.eps:.0e} | {e.solver} | {_g3(e.delay_ab)} | {_g3(e.delay_cd)} | {_g3(e.time)} | {e.status} |")
    L += ["", "### Speed targets", "",
          "| scene | simulated [s] | wall [s] | steps | jumps | µs/step | RHS/step | ns/RHS | RHS share of time "
          "| steps/jump |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for t in rep.targets:
        L.append(f"| {t['scene']} | {t['t_end']:g} | {t['wall']:.3g} | {t['steps']} | {t['jumps']} | "
                 f"{t['us_per_step']:.2f} | {t['rhs_per_step']:.1f} | {t['rhs_ns']:.0f} | "
                 f"{100 * t['rhs_share']:.0f} % | "
                 f"{t['steps_per_jump']:.1f} |")
    L += ["", f"Kernel compilation in a fresh process with an empty numba cache: {rep.compile[0]:.1f} s; loading "
              f"the on-disk cache in a fresh process: {rep.compile[1]:.2f} s (never included in the times above)."]
    return "\n".join(L) + "\n"


def rows_as_dicts(rep: BenchmarkReport) -> tuple[list[dict], list[dict]]:
    """(work-precision rows, ε rows including the tiny-ε check) as plain dicts for CSV/JSON."""
    return [asdict(r) for r in rep.rows], [asdict(e) for e in rep.eps_rows + rep.small_eps]
