"""The public API of each package (issue 14: names that move between rooms must keep working).

Each set below is the package's public API as of 0.2.0.dev0.  A name may be added to a package (then add it
here), but one listed here may not disappear: the test fails if it is missing from ``__all__`` or does not
resolve.  Moves record themselves in CHANGELOG.md.
"""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

API = {
    "peelapprox": {
        "ALPHA_FORMS", "ALPHA_MODELS", "Attractor", "BRANCHES", "BREAKDOWN_LEVEL", "EPS_RANGE", "LYAPUNOV_TAU",
        "RTOL_RANGE", "STATE_RANGES", "TIME_MAX", "T_TRANSIENT", "WINDOW_DEFAULTS", "BranchStructure", "FixedPoint",
        "EPS_DEFAULT", "GEOMETRIES",
        "INERTIA_RULE", "InertialPeriods", "KernelCacheWarning", "LyapunovResult", "MEASURES", "ModelBreakdown",
        "PARAM_RANGES", "PeelParams", "Periodicity", "ReducedSegment", "RegimeEstimate", "SlopeCriterion",
        "SolverBudgetExceeded", "SolverFailure", "SweepResult", "VELOCITY_RULE", "V_EQUATIONS", "airy_alpha",
        "alpha_numerical", "attractors", "benettin", "branch_inverse", "branch_structure", "cd_damping_time",
        "classify", "cd_decay_alpha", "crude_branch_time", "estimate", "fixed_point", "force_bounds", "force_drops",
        "harmonic_alpha", "inertial_frequency", "inertial_period", "inertial_periods", "load_sweep", "lyapunov",
        "lyapunov_return_map", "lyapunov_tangent", "parse_grid", "peel_force", "peel_force_derivative",
        "periodicity", "quasi_static_branch_time", "reduced_segment", "register_measure", "return_map",
        "settle_time", "sinusoid_alpha", "slope_criterion", "sweep", "wkb_alpha", "wkb_amplitude_phase",
        "wkb_error_bound",
    },
    "exact": {
        "ATOL_SCALE", "Budget", "Hybrid", "Jump", "Jumps", "ModelBreakdown", "Regularized", "STEP_BUDGET", "SaveAt",
        "SolverBudgetExceeded", "SolverFailure", "SolverStats", "State", "Trajectory", "compile_kernels",
        "default_atol", "default_max_steps", "hybrid_field", "initial_state", "lyapunov_variational", "simulate",
        "window_run", "attractors", "Attractor", "DEFAULT_MAX_WALL", "lyapunov", "lyapunov_tangent",
        "lyapunov_return_map", "LyapunovResult", "benettin", "BenettinResult", "check_lyapunov_options",
    },
    "comparisons": {
        "CLAIM", "CompareReport", "ComparisonRow", "DEFAULT_MODELS", "ExactRun", "RUNS", "Row", "RunSpec", "SCENES",
        "STAT_RUNS", "Scene", "Segment", "StatRow", "TransientCheck", "TransientNotPassed", "check_past_transient",
        "compare", "exact_run", "local_period", "markdown", "run_compare", "run_reduction", "scene_rows",
        "segments", "statistics", "Figure", "FIGURES", "make_figures", "figures_markdown",
    },
    "peelapprox.io": {"TABLE_EXTENSIONS", "fmt_number", "jsonable", "write_csv", "write_rows"},
    "peelapprox.plotting": {"plot_phase_diagram", "plot_segment", "plot_trajectory", "pyplot"},
    "comparisons.sweep": {
        "MEASURES", "SweepResult", "load_sweep", "parse_grid", "register_measure", "sweep",
    },
}


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


def test_import_peelapprox_does_not_import_exact():
    """Issue 14 (rooms): the core imports no sibling package; the names it offers that live in ``exact``
    (the Lyapunov family, attractors) are imported on first access.  Hypothesis, in a fresh interpreter:
    after ``import peelapprox`` ``exact`` is not in ``sys.modules``; ``dir(peelapprox)`` lists the lazy names;
    accessing ``peelapprox.lyapunov`` imports ``exact`` and gives the very object ``exact.lyapunov``
    (identity, categorical)."""
    code = ("import sys, peelapprox; assert 'exact' not in sys.modules, 'exact imported'; "
            "assert {'lyapunov', 'attractors', 'LyapunovResult'} <= set(dir(peelapprox)); "
            "f = peelapprox.lyapunov; import exact; assert f is exact.lyapunov; "
            "from peelapprox import Attractor; assert Attractor is exact.Attractor; print('ok')")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr


def test_import_peelapprox_imports_no_sibling_package():
    """Hypothesis: ``import peelapprox`` loads neither ``exact`` nor ``comparisons`` (the rooms' one-way
    doors); the sweep names it offers are imported from ``comparisons.sweep`` on first access only.  A fresh
    interpreter, since this one has imported everything already."""
    code = ("import sys, peelapprox\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('exact', 'comparisons')))\n"
            "assert 'sweep' in dir(peelapprox)\n"
            "peelapprox.MEASURES\n"
            "print('comparisons.sweep' in sys.modules)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["[]", "True"], proc.stdout


def test_sweep_names_are_the_same_objects_both_ways():
    """The lazily re-exported sweep names are the objects of ``comparisons.sweep``; in particular MEASURES is
    one registry, so a measure registered through either name is seen through the other (identity)."""
    import comparisons.sweep
    import peelapprox

    for name in API["comparisons.sweep"]:
        assert getattr(peelapprox, name) is getattr(comparisons.sweep, name), name
    assert peelapprox.register_measure is comparisons.sweep.register_measure
    assert {"regime", "jumps", "period", "lyapunov"} <= set(peelapprox.MEASURES)
    with pytest.raises(AttributeError, match="no attribute 'nosuch'"):
        peelapprox.nosuch  # noqa: B018 - the lazy __getattr__ still refuses unknown names


def test_matplotlib_is_imported_by_plotting_only():
    """Issue 14 (one matplotlib set-up, :func:`peelapprox.plotting.pyplot`): importing the packages, the CLI and
    the plotting module itself loads no matplotlib; drawing does.  Fresh interpreter (categorical: module set)."""
    code = ("import sys, peelapprox, peelapprox.cli, peelapprox.plotting, exact, comparisons, comparisons.benchmark\n"
            "print('matplotlib' in sys.modules)\n"
            "peelapprox.plotting.pyplot()\n"
            "print('matplotlib.pyplot' in sys.modules)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False", "True"], proc.stdout
