"""Work-precision benchmark of the exact solvers, the ε study and the speed targets, timed in one run.

``peelapprox benchmark [--quick] [--out DIR]`` (or :func:`run_benchmark`) measures, on this machine and
in one process:

1. **Work precision** on three scenes (:data:`BENCH_SCENES`: V=1, I=1e-5; V=1, I=1e-2; V=4, I=1e-2) over
   a fixed horizon: CPU (wall) time against the error of the jump sequence, for

   * the hybrid ε → 0 solver (``exact.simulate``, ``method="hybrid"``) at rtol 1e-4 … 1e-12;
   * the paper's ε-regularised scheme on scipy's Radau, BDF and LSODA at ε = 1e-7 (the paper's) and 1e-10;
   * the external compiled peers on the same regularised system (SUNDIALS IDA and CVODE through
     scikit-sundae, Rust diffsol through pydiffsol; :mod:`comparisons.benchmark.peers`), when the optional
     ``peelapprox[bench]`` extra is installed.

   **Error metric** (:func:`jump_errors`): over the first N jumps of the reference (all the jumps in the
   horizon), ``max_j |t_j - t_j^ref| / T̄`` with T̄ the reference's mean interval between jumps, and
   ``max_j |F_j - F_j^ref| / F_j^ref``; the reported error is the larger of the two.  A run with a different
   number of jumps in the horizon has error ``inf`` (it is on another orbit) and is shown as such.  The
   regularised runs record a jump where v crosses the inflection velocity of f, the hybrid one at the fold:
   their difference is the ε-bias of the paper's scheme (fold-passage delay + transit), which is part of
   their error by design — it is what a user of that scheme gets.
   **Reference**: the hybrid solver at rtol 1e-13, cross-checked by a second, independent method
   (:func:`branchwise_reference`: scipy's DOP853 on (α, ω, F) with v from the branch inverse of CONSTR and
   the folds as events — no desingularisation, no shared integrator code); their agreement is reported.
   **Timing** as the SciML work-precision benchmarks: one untimed warm-up per configuration, then the
   minimum over repeats.  The multi-second scipy Radau/BDF runs are warmed up on the horizon up to the
   reference's second jump (which exercises every code path) and timed once.

2. **ε study** (:func:`eps_study`): the regularised scheme's jump-time bias vs ε from 1e-4 to 1e-12 (Radau,
   rtol 1e-10), a least-squares power law ``bias = C ε^p`` (the fold-passage theory gives p = 2/3), and
   what happens at ε = 1e-15 in double precision.

3. **Targets** (:func:`speed_targets`): µs per accepted step on every scene, V=4, I=1e-2 for 200 s, the
   speed-up over Radau at matched error, and where the time goes (field evaluations vs. the rest, per jump).

Outputs: ``work_precision.csv`` / ``.json``, ``eps_study.csv``, ``work_precision.png``, ``eps_study.png`` and
``benchmark.md`` (pasted into ``docs/performance.md``).

Modules: :mod:`.scenes` (the scenes and the error metric), :mod:`.reference` (the branch-wise reference
solver), :mod:`.work_precision`, :mod:`.eps` (the ε study), :mod:`.targets` (speed targets, compilation
costs), :mod:`.run` (:func:`run_benchmark`), :mod:`.report` (the report and its markdown), :mod:`.plots`,
:mod:`.timing` and :mod:`.peers` (one module per external peer).  Two scripts time the other jobs:
``python -m comparisons.benchmark.reduced_cost`` (the reduced equations, :mod:`.reduced_cost`) and
``python -m comparisons.benchmark.compare_cost`` (``peelapprox compare``, cold and warm, :mod:`.compare_cost`).
The tape-mass model (docs/tape-mass.md): ``python -m comparisons.benchmark.tape_mass`` (its solvers' work precision
across the mass range, :mod:`.tape_mass`) and ``python -m comparisons.benchmark.tape_mass_limit`` (the low-mass
limit and the ε of a tape mass, :mod:`.tape_mass_limit`).
"""

from .eps import EpsRow, eps_study, fit_power_law, small_eps_check
from .plots import plot_eps_study, plot_work_precision
from .reference import branchwise_reference
from .report import BenchmarkReport, markdown, rows_as_dicts
from .run import run_benchmark
from .scenes import BENCH_SCENES, BenchScene, jump_errors
from .targets import compile_costs, speed_targets
from .work_precision import WPRow, matched_ratios, ratio_summary, work_precision

__all__ = [
    "BenchScene",
    "BENCH_SCENES",
    "WPRow",
    "EpsRow",
    "BenchmarkReport",
    "branchwise_reference",
    "jump_errors",
    "work_precision",
    "matched_ratios",
    "ratio_summary",
    "eps_study",
    "small_eps_check",
    "fit_power_law",
    "speed_targets",
    "compile_costs",
    "run_benchmark",
    "markdown",
    "rows_as_dicts",
    "plot_work_precision",
    "plot_eps_study",
]
