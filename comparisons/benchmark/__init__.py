"""Work-precision benchmark of the exact solvers, the ε study and the speed targets, timed in one run.

``peelapprox benchmark [--quick] [--out DIR]`` (or :func:`run_benchmark`) measures, on this machine and
in one process:

1. **Work precision** (:mod:`.work_precision`) on three scenes (:data:`BENCH_SCENES`) over a fixed horizon:
   wall time against the error of the jump sequence (:func:`jump_errors`) for the hybrid solver at rtol 1e-4 …
   1e-12, the paper's ε-regularised scheme on scipy's Radau, BDF and LSODA at ε = 1e-7 and 1e-10, and the
   external compiled peers (:mod:`.peers`, with the ``bench`` extra).  The regularised runs' error includes the
   scheme's ε-bias by design: it is what a user of that scheme gets.  The reference is the hybrid solver at
   rtol 1e-13, cross-checked by an independent method (:func:`branchwise_reference`).  Timing as the SciML
   benchmarks: an untimed warm-up, then the minimum over repeats (:mod:`.timing`).
2. **ε study** (:func:`eps_study`): the regularised jump's bias against ε from 1e-4 to 1e-12 and its power
   law ``C ε^p`` (the fold-passage theory gives p = 2/3), and what happens at ε = 1e-15 in double precision.
3. **Targets** (:func:`speed_targets`): µs per step on every scene, a 200 s run, the speed-up over Radau at
   matched error, and where the time goes.

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
limit and the ε of a tape mass, :mod:`.tape_mass_limit`).  ``python -m comparisons.benchmark.attractor_sets`` times
:func:`exact.attractor_set` against one :func:`exact.attractor_observables` call on seeded random points
(:mod:`.attractor_sets`).  ``python -m comparisons.benchmark.infer_targets`` measures how often
:func:`exact.infer` recovers I and k from synthetic measured traces at seeded random points, per class of trace
(:mod:`.infer_targets`).
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
