"""The public API of each package (names that move between modules must keep working).

Each set below is the package's public API as of 0.3.0.dev0.  A name may be added to a package (then add it
here), but one listed here may not disappear: the test fails if it is missing from ``__all__`` or does not
resolve.  Moves record themselves in CHANGELOG.md.
"""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest
from _parse import parse

API = {
    "peelapprox": {
        "ALPHA_FORMS", "ALPHA_MODELS", "Attractor", "BRANCHES", "BREAKDOWN_LEVEL", "EPS_RANGE", "LYAPUNOV_TAU",
        "RTOL_RANGE", "STATE_RANGES", "TIME_MAX", "T_TRANSIENT", "WINDOW_DEFAULTS", "F0_FACTOR",
        "BranchStructure", "FixedPoint",
        "EPS_DEFAULT", "GEOMETRIES", "TAPE_MASS_RANGE", "LOADINGS", "LOAD_MASS_RANGE", "LOAD_RANGE", "GRAVITY",
        "INERTIA_RULE", "InertialPeriods", "KernelCacheWarning", "LyapunovResult", "MEASURES", "ModelBreakdown",
        "PARAM_RANGES", "PeelParams", "PeelForce", "Folds", "FitResult", "FoldEstimate", "periodic_orbit",
        "PeriodicOrbit", "continue_orbit", "OrbitBranch", "switch_branch", "basins", "BasinResult", "infer",
        "Inference", "Periodicity", "ReducedSegment",
        "RegimeEstimate",
        "SlopeCriterion",
        "SolverBudgetExceeded", "SolverFailure", "SweepResult", "VELOCITY_RULE", "V_EQUATIONS", "airy_alpha",
        "alpha_numerical", "attractors", "benettin", "branch_inverse", "branch_structure", "cd_damping_time",
        "classify", "cd_decay_alpha", "crude_branch_time", "estimate", "fixed_point", "force_bounds", "force_drops",
        "harmonic_alpha", "inertial_frequency", "inertial_period", "inertial_periods", "load_sweep", "lyapunov",
        "lyapunov_return_map", "lyapunov_tangent", "parse_grid", "peel_force", "peel_force_derivative",
        "periodicity", "quasi_static_branch_time", "reduced_segment", "register_measure", "return_map",
        "settle_time", "sinusoid_alpha", "slope_criterion", "sweep", "wkb_alpha", "wkb_amplitude_phase",
        "wkb_error_bound", "StickSlipObservables", "attractor_observables", "approximate_attractor", "ForceSeries",
        "ApproximateAttractor", "ApproximationWarning",
        "Slips", "Spectrum", "SeriesLyapunov", "SurrogateTest",
        "FrontParams", "FrontPattern", "TransverseModes", "front_pattern", "transverse_growth_rates",
        "burst_catalogue", "BurstCatalogue", "BURST_COLUMNS", "fit_power_law", "PowerLawFit", "MAX_XMIN_CANDIDATES",
        "compare_power_law", "LikelihoodRatio", "ALTERNATIVES", "fit_broken_power_law", "BrokenPowerLawFit",
    },
    "exact": {
        "ATOL_SCALE", "Budget", "Hybrid", "Jump", "Jumps", "METHODS", "ModelBreakdown", "Regularized", "Smooth",
        "STEP_BUDGET", "MODELS", "Model", "Massless", "MasslessLoad", "TapeMass", "TapeMassLoad", "register_model",
        "model_of", "SaveAt",
        "SolverBudgetExceeded", "SolverFailure", "SolverStats", "State", "Trajectory", "compile_kernels",
        "WarmupReport",
        "default_atol", "default_max_steps", "hybrid_field", "initial_state", "lyapunov_variational", "simulate",
        "window_run", "attractors", "Attractor", "DEFAULT_MAX_WALL", "lyapunov", "lyapunov_tangent",
        "lyapunov_return_map", "LyapunovResult", "benettin", "BenettinResult", "check_lyapunov_options",
        "VARIATIONAL_LAWS", "periodic_orbit", "PeriodicOrbit", "solve_orbit", "section_return", "SectionReturn",
        "monodromy_fd",
        "continue_orbit", "OrbitBranch", "BranchPoint", "Bifurcation", "switch_branch", "crest_margin", "Crest",
        "orbit_diagram", "OrbitDiagram", "explain", "MAX_DIAGRAM_VALUES",
        "with_parameter", "parameter_value", "basins", "BasinResult", "BasinAttractor", "MAX_BASIN_STARTS", "infer",
        "Inference",
        "attractor_observables",
        "attractor_set", "AttractorSet", "SetAttractor", "SetOutcome", "SetStart", "EscapePrediction",
        "simulate_front", "FrontTrajectory",
    },
    "comparisons": {
        "CLAIM", "CompareReport", "ComparisonRow", "DEFAULT_MODELS", "ExactRun", "RUNS", "Row", "RunSpec", "SCENES",
        "STAT_RUNS", "Scene", "Segment", "StatRow", "TransientCheck", "TransientNotPassed", "check_past_transient",
        "compare", "exact_run", "local_period", "markdown", "run_compare", "run_reduction", "scene_rows",
        "segments", "statistics", "Figure", "FIGURES", "make_figures", "figures_markdown", "RowTable",
    },
    "peelapprox.io": {"TABLE_EXTENSIONS", "ProgressLine", "fmt_number", "html_table", "jsonable", "optional_import",
                      "param_attrs", "write_csv", "write_rows"},
    "peelapprox.parallel": {"AUTO", "DEADLINE_TEXT", "IDLE_TIMEOUT", "POOL_KINDS", "PROCESSES", "SERIAL", "THREADS",
                            "WORKER_ENV", "cpu_count", "default_kind", "error_text", "map_points", "resolve_kind",
                            "worker_pool"},
    "peelapprox.plotting": {"TRAJECTORY_CYCLES", "cell_edges", "new_figure", "plot_bifurcation", "plot_front",
                            "plot_phase_diagram",
                            "plot_segment", "plot_trajectory", "pyplot", "save_figure", "trajectory_window",
                            "plot_burst_distribution", "TrajectoryWindow", "TRAJECTORY_PANELS", "MAX_BRANCHES"},
    "comparisons.atlas": {
        "atlas", "AtlasResult", "load_atlas", "APPROXIMATIONS", "register_approximation", "OBSERVABLES", "DEFAULTS",
        "TOLERANCE", "estimate_observables", "plot_error_map", "plot_dynamics_map", "plot_segment_maps",
        "write_maps", "atlas_cost", "AtlasCost", "match_set", "SET_DEFAULTS", "plot_multistability_map",
        "plot_confidence_map",
    },
    "comparisons.front": {
        "front_ensemble", "FrontEnsemble", "ENSEMBLE_COLUMNS", "inertia_of_ratio", "FRONT_DEFAULTS", "measure_front",
        "check_front_options", "twin_lyapunov",
    },
    "comparisons.sweep": {
        "MEASURES", "SweepResult", "load_sweep", "parse_grid", "register_measure", "sweep",
        "MANIFEST", "RESERVED", "RESULTS", "record_key", "MAX_SWEEP_POINTS", "check_grid_size",
    },
    "peelapprox.validate": {
        "ArgumentTypeError", "MAX_COUNT", "choice", "duration", "finite", "flag", "function", "in_range", "integer",
        "interval", "nonnegative", "optional", "optional_finite", "paper_model", "params", "path", "positive", "real",
        "reals",
        "state", "states", "times", "rtol", "eps", "shown",
    },
    "peelapprox.errors": {
        "KernelCacheWarning", "ModelBreakdown", "SolverBudgetExceeded", "SolverFailure", "WallBudget",
        "budget_exceeded",
    },
    # the door through which exact (and comparisons) reach the compiled model and integrator
    "peelapprox.kernels": {
        "ALL_LAWS", "BuildExpired", "CompiledLaw", "caller_budget", "cache_status", "cpu_name", "record_warmup",
        "compile_only", "pack_inlined", "pack_law",
        "U_ZERO", "compiled_law", "law_domain", "rebind", "regularized_law_field", "VARIANT_MODELS", "variant_field",
        "variant_parameters", "bound_variant_field",
        "DIFFSL_INPUTS", "DIFFSL_TANGENT_INPUTS", "DIFFSOL_OPTIONS", "LAWS", "LAW_FP", "LAW_FPP", "LAW_LNV",
        "LAW_SIG", "LAW_TYPE", "MAX_REJECTIONS", "MODEL_FIELDS", "M_A", "M_B", "M_GEOM", "M_I", "M_K", "M_L", "M_R",
        "M_V", "N_M", "N_STAGES", "PeerUnavailableError", "Q_EPS", "STEP_FAILED", "branch_inverse_at", "closure",
        "closure_exact", "closure_paper", "closure_d2", "closure_exact_d2", "closure_paper_d2", "constraint_rate",
        "crossing",
        "diffsl_code", "diffsl_inputs", "diffsl_model", "expression_kernel", "family_kernel", "import_optional",
        "interp", "interp1", "interp_mean", "kernel",
        "make_dop853", "model_block", "paper_coefficients", "paper_law", "peel_force_coefficients",
        "peel_force_fp_jit", "peel_force_fpp_jit", "peel_force_lnv_jit", "regularized_field",
        "regularized_field_jacobian", "regularized_jacobian", "regularized_parameters", "regularized_rhs",
        "slow_rates", "solve_theta", "solve_theta_mean", "state_at", "status", "table_coefficients", "table_law",
        "workspace",
        "front_rhs", "front_field", "front_parameters", "front_state_size", "FQ_N", "FQ_GAMMA", "FQ_PERIODIC",
        "N_FQ", "N_FY_TAIL", "FY_ALPHA", "FY_OMEGA", "FY_EAE", "FY_STRIPS",
    },
    "peelapprox.cli": {"build_parser", "main"},
    "comparisons.benchmark": {
        "BENCH_SCENES", "BenchScene", "BenchmarkReport", "EpsRow", "WPRow", "branchwise_reference", "compile_costs",
        "eps_study", "fit_power_law", "jump_errors", "markdown", "matched_ratios", "plot_eps_study",
        "plot_work_precision", "ratio_summary", "rows_as_dicts", "run_benchmark", "small_eps_check",
        "speed_targets", "work_precision",
    },
    "comparisons.benchmark.peers": {
        "DIFFSOL_OPTIONS", "PEERS", "PeerResult", "PeerUnavailableError", "available_peers", "run_peer",
    },
    "comparisons.stress": {
        "ALLOWED_PREFIXES", "BUG_CLASSES", "GRID_ALPHA0", "GRID_I", "GRID_K", "GRID_V", "LONG_RUNS", "LOOSE_ALPHA0",
        "LOOSE_I", "LOOSE_TOLS", "LOOSE_V", "RANDOM_BOX", "StressPoint", "StressRunner", "TOL_POINTS", "TOL_RTOLS",
        "all_points", "budget_edge_probes", "budget_points", "grid_points", "is_allowed", "is_bug", "long_points",
        "loose_points", "main", "pair_long_runs", "random_points", "robustness_markdown", "run_point", "run_points",
        "tolerance_points", "tolerance_table", "variant_points", "write_records",
    },
}

#: The names of comparisons.sweep that peelapprox also offers (lazily); the store's names are not among them.
SWEEP_NAMES = ("MEASURES", "SweepResult", "load_sweep", "parse_grid", "register_measure", "sweep")

ROOT = Path(__file__).resolve().parents[1]


def _public_modules() -> list[tuple[str, Path]]:
    """Every public module of the three packages: no component of its dotted name starts with ``_``
    (``__init__`` files stand for their package; ``__main__`` is an entry point, not a module to import)."""
    found = []
    for package in ("peelapprox", "exact", "comparisons"):
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            if not any(part.startswith("_") for part in parts):
                found.append((".".join(parts), path))
    return found


def _defines_all(path: Path) -> bool:
    tree = parse(path.read_text(encoding="utf-8"))
    for node in tree.body:
        targets = (node.targets if isinstance(node, ast.Assign)
                   else [node.target] if isinstance(node, ast.AnnAssign) else [])
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return True
    return False


def test_every_public_module_declares_all():
    """Hypothesis: every public module (and package) of the three packages states its public names in a
    module-level ``__all__`` (categorical: the list of modules without one is empty), so that what is public
    is a decision, not whatever happens not to start with an underscore."""
    modules = _public_modules()
    assert {"peelapprox", "exact", "comparisons", "peelapprox.kernels", "comparisons.sweep.store"} <= {
        name for name, _ in modules}
    missing = sorted(name for name, path in modules if not _defines_all(path))
    assert not missing, f"public modules without __all__: {missing}"


@pytest.mark.parametrize("package", sorted(API))
def test_public_names_stay_offered(package):
    """Hypothesis: every listed name is in the package's ``__all__`` and resolves to an object (exact set
    inclusion; a name that disappears is an API break)."""
    mod = importlib.import_module(package)
    missing = API[package] - set(mod.__all__)
    assert not missing, f"{package} no longer offers {sorted(missing)}"
    for name in mod.__all__:
        assert getattr(mod, name) is not None, name


@pytest.mark.parametrize("package", sorted(API))
def test_all_lists_no_unknown_name(package):
    """``__all__`` holds no name this test does not know: a new public name is a decision, recorded here
    (exact set comparison)."""
    mod = importlib.import_module(package)
    assert set(mod.__all__) == API[package], sorted(set(mod.__all__) ^ API[package])


def test_the_errors_are_one_class_each():
    """The model exceptions offered by both packages are the same classes (one place: peelapprox.errors)."""
    import exact
    import peelapprox

    for name in ("ModelBreakdown", "SolverBudgetExceeded", "SolverFailure"):
        assert getattr(exact, name) is getattr(peelapprox, name)


def test_version_single_sourced():
    """The installed distribution's version is the package's (pyproject reads peelapprox._version)."""
    from importlib.metadata import version

    import peelapprox

    assert version("peelapprox") == peelapprox.__version__


#: One fresh interpreter for the three import checks below (each reads its own lines): the steps run in the
#: order that keeps each check valid (``import peelapprox`` alone first, then the lazy names, then every
#: package, then drawing); one interpreter start-up instead of three.
FRESH_CODE = (
    "import sys, peelapprox\n"
    "print(sorted(m for m in sys.modules if m.split('.')[0] in ('exact', 'comparisons')))\n"
    "print({'lyapunov', 'attractors', 'LyapunovResult', 'sweep'} <= set(dir(peelapprox)))\n"
    "f = peelapprox.lyapunov; import exact; from peelapprox import Attractor\n"
    "print(f is exact.lyapunov, Attractor is exact.Attractor)\n"
    "print('comparisons.sweep' in sys.modules, end=' '); peelapprox.MEASURES\n"
    "print('comparisons.sweep' in sys.modules)\n"
    "import peelapprox.cli, peelapprox.plotting, comparisons, comparisons.benchmark\n"
    "print('matplotlib' in sys.modules)\n"
    "peelapprox.plotting.pyplot()\n"
    "print('matplotlib.pyplot' in sys.modules)\n"
)


@pytest.fixture(scope="module")
def fresh() -> list[str]:
    """The lines :data:`FRESH_CODE` prints in a fresh interpreter (this one has imported everything already)."""
    proc = subprocess.run([sys.executable, "-c", FRESH_CODE], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.splitlines()


def test_import_peelapprox_does_not_import_exact(fresh):
    """The rooms: the core imports no sibling package; the names it offers that live in ``exact``
    (the Lyapunov family, attractors) are imported on first access.  Hypothesis, in a fresh interpreter:
    after ``import peelapprox`` ``exact`` is not in ``sys.modules``; ``dir(peelapprox)`` lists the lazy names;
    accessing ``peelapprox.lyapunov`` imports ``exact`` and gives the very object ``exact.lyapunov``
    (identity, categorical)."""
    assert fresh[0] == "[]", "exact imported"
    assert fresh[1] == "True" and fresh[2] == "True True", fresh


def test_import_peelapprox_imports_no_sibling_package(fresh):
    """Hypothesis: ``import peelapprox`` loads neither ``exact`` nor ``comparisons`` (the rooms' one-way
    doors); the sweep names it offers are imported from ``comparisons.sweep`` on first access only (not before
    it, not by ``exact``).  A fresh interpreter, since this one has imported everything already."""
    assert fresh[0] == "[]", fresh
    assert fresh[1] == "True" and fresh[3] == "False True", fresh


def test_sweep_names_are_the_same_objects_both_ways():
    """The lazily re-exported sweep names are the objects of ``comparisons.sweep``; in particular MEASURES is
    one registry, so a measure registered through either name is seen through the other (identity)."""
    import comparisons.sweep
    import peelapprox

    for name in SWEEP_NAMES:
        assert getattr(peelapprox, name) is getattr(comparisons.sweep, name), name
    assert peelapprox.register_measure is comparisons.sweep.register_measure
    assert {"regime", "jumps", "period", "lyapunov"} <= set(peelapprox.MEASURES)
    with pytest.raises(AttributeError, match="no attribute 'nosuch'"):
        peelapprox.nosuch  # noqa: B018 - the lazy __getattr__ still refuses unknown names


def test_matplotlib_is_imported_by_plotting_only(fresh):
    """One matplotlib set-up (:func:`peelapprox.plotting.pyplot`): importing the packages, the CLI and
    the plotting module itself loads no matplotlib; drawing does.  Fresh interpreter (categorical: module set)."""
    assert fresh[4:] == ["False", "True"], fresh
