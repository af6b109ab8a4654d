"""Numerical stress tests of the exact solver (:func:`exact.simulate`).

    python -m comparisons.stress [--quick] [--out DIR] [--timeout S] [--t-end S] [--n-random N]

Every run of the model must end in a :class:`~exact.Trajectory` or in one of
the documented exceptions -- never in a non-finite value, never in a hang.
The suite runs a grid over (I, V, k, α0), a seeded random sample, a tolerance
sweep, a loose-tolerance grid, budget probes, a few variants (regularised
scheme, exact geometry) and long runs (≥ 1e5 jumps), each point in a separate
worker process with a wall-clock timeout, and classifies each run.

Modules
-------
:mod:`~comparisons.stress.points`
    :class:`StressPoint` and the point lists of the suite.
:mod:`~comparisons.stress.run`
    :func:`run_point` (one point in this process) and the outcome classes
    (:func:`is_allowed`, :func:`is_bug`).
:mod:`~comparisons.stress.runner`
    :class:`StressRunner` (the hang- and crash-proof worker process),
    :func:`run_points`, :func:`budget_edge_probes`.
:mod:`~comparisons.stress.report`
    :func:`robustness_markdown`, :func:`tolerance_table`,
    :func:`pair_long_runs`, :func:`write_records`.
:mod:`~comparisons.stress.cli`
    :func:`main`, the command line.
"""

from .cli import main
from .points import (
    GRID_ALPHA0,
    GRID_I,
    GRID_K,
    GRID_V,
    LONG_RUNS,
    LOOSE_ALPHA0,
    LOOSE_I,
    LOOSE_TOLS,
    LOOSE_V,
    RANDOM_BOX,
    TOL_POINTS,
    TOL_RTOLS,
    StressPoint,
    all_points,
    budget_points,
    grid_points,
    long_points,
    loose_points,
    random_points,
    tolerance_points,
    variant_points,
)
from .report import pair_long_runs, robustness_markdown, tolerance_table, write_records
from .run import ALLOWED_PREFIXES, BUG_CLASSES, is_allowed, is_bug, run_point
from .runner import StressRunner, budget_edge_probes, run_points

__all__ = [
    "GRID_I", "GRID_V", "GRID_K", "GRID_ALPHA0", "RANDOM_BOX", "TOL_RTOLS", "TOL_POINTS", "LONG_RUNS",
    "ALLOWED_PREFIXES", "BUG_CLASSES",
    "LOOSE_V", "LOOSE_I", "LOOSE_ALPHA0", "LOOSE_TOLS",
    "StressPoint", "grid_points", "random_points", "tolerance_points", "loose_points", "budget_points",
    "variant_points",
    "long_points",
    "all_points", "run_point", "StressRunner", "run_points", "budget_edge_probes",
    "is_allowed", "is_bug", "tolerance_table", "pair_long_runs", "robustness_markdown", "write_records", "main",
]
