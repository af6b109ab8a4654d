"""Approximate-vs-exact comparison harness (segments, seeding, the paper's scenes, error tables).

Public names are re-exported here; the modules are private.
"""

from ._compare import DEFAULT_MODELS, ComparisonRow, RowTable, compare, run_reduction
from ._figures import FIGURES, Figure, figures_markdown, make_figures
from ._report import STAT_RUNS, CompareReport, StatRow, markdown, run_compare, statistics
from ._runs import RUNS, ExactRun, RunSpec, TransientCheck, TransientNotPassed, check_past_transient, exact_run
from ._scenes import CLAIM, SCENES, Row, Scene, scene_rows
from ._segments import Segment, local_period, segments

__all__ = [
    "Segment", "segments", "local_period",
    "compare", "run_reduction", "ComparisonRow", "RowTable", "DEFAULT_MODELS",
    "RunSpec", "RUNS", "ExactRun", "exact_run", "check_past_transient", "TransientCheck", "TransientNotPassed",
    "Row", "Scene", "SCENES", "scene_rows", "CLAIM",
    "StatRow", "CompareReport", "statistics", "run_compare", "markdown", "STAT_RUNS",
    "Figure", "FIGURES", "make_figures", "figures_markdown",
]
