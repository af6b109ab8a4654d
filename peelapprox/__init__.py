"""peelapprox: stick-slip peeling of an adhesive tape from a roller.

Companion library to R. De, A. Maybhate and G. Ananthakrishna, "Dynamics of
stick-slip in peeling of an adhesive tape".  The core package holds the model
parameters, the peel-force function, the paper's reduced branch-wise
equations (Sec. V) and regime estimates; the exact DAE solvers live in the
``exact`` package and the approximate-vs-exact harness in ``comparisons``.

The (I, V) sweep (``sweep``, ``load_sweep``, ``SweepResult``, ``register_measure``, ``MEASURES``,
``parse_grid``) is an experiment and lives in :mod:`comparisons.sweep`; these names are offered here too,
imported from there on first use (``import peelapprox`` imports no sibling package).  So are the
dynamics that run the exact solver, from :mod:`exact`: ``lyapunov`` (``exact.lyapunov(params, method=...)``),
``lyapunov_tangent``, ``lyapunov_return_map``, ``LyapunovResult``, ``benettin``, ``attractors``,
``Attractor``, ``attractor_observables``, ``periodic_orbit``, ``continue_orbit``, ``switch_branch``,
``basins``, ``infer`` (parameters from measured force traces).  The return-map analysis of a trajectory
(``return_map``, ``periodicity``, ``classify``,
``force_drops``, ``settle_time``) is the core's own, and so is the one definition of a stick-slip attractor's
observables, ``StickSlipObservables`` (read off any trajectory by ``StickSlipObservables.from_trajectory``;
``attractor_observables`` runs the exact solver for them).  Each re-exported name is its home module's very
object (``peelapprox.periodic_orbit is exact.periodic_orbit``), documented once, on its home's API page.
The burst statistics (``burst_catalogue``, ``fit_power_law``, ...), the reduced equations and the approximate
attractor (``reduced_segment``, ``approximate_attractor``, ``estimate``, the α forms) and a measured force trace
(``ForceSeries``, ``SeriesLyapunov``) are this package's own, imported on first use too: ``import peelapprox`` and a
first ``exact.simulate`` import none of them, nor scipy's optimize, integrate or special (docs/performance.md).
"""

from typing import TYPE_CHECKING

from ._observables import StickSlipObservables
from ._params import PeelParams
from ._ranges import (
    EPS_DEFAULT,
    EPS_RANGE,
    F0_FACTOR,
    GEOMETRIES,
    GRAVITY,
    LOAD_MASS_RANGE,
    LOAD_RANGE,
    LOADINGS,
    LYAPUNOV_TAU,
    PARAM_RANGES,
    RTOL_RANGE,
    STATE_RANGES,
    T_TRANSIENT,
    TAPE_MASS_RANGE,
    TIME_MAX,
    WINDOW_DEFAULTS,
)
from ._returnmap import Periodicity, classify, force_drops, periodicity, return_map, settle_time
from ._slips import Slips
from ._version import __version__ as __version__
from .errors import KernelCacheWarning, ModelBreakdown, SolverBudgetExceeded, SolverFailure
from .front import FrontParams, FrontPattern, TransverseModes, front_pattern, transverse_growth_rates
from .law import (
    BRANCHES,
    BREAKDOWN_LEVEL,
    BranchStructure,
    FitResult,
    FixedPoint,
    FoldEstimate,
    Folds,
    PeelForce,
    branch_inverse,
    branch_structure,
    fixed_point,
    peel_force,
    peel_force_derivative,
)

if TYPE_CHECKING:  # imported on first access (``_LAZY`` below); here for the type checkers
    from ._measured._series import ForceSeries, Spectrum
    from ._measured._series_lyapunov import SeriesLyapunov, SurrogateTest
    from ._reduced._alpha import (
        ALPHA_FORMS,
        InertialPeriods,
        airy_alpha,
        alpha_numerical,
        cd_damping_time,
        cd_decay_alpha,
        harmonic_alpha,
        inertial_frequency,
        inertial_period,
        inertial_periods,
        sinusoid_alpha,
        wkb_alpha,
        wkb_amplitude_phase,
        wkb_error_bound,
    )
    from ._reduced._approx_result import ApproximateAttractor, ApproximationWarning
    from ._reduced._approximate import approximate_attractor
    from ._reduced._estimate import (
        INERTIA_RULE,
        VELOCITY_RULE,
        RegimeEstimate,
        SlopeCriterion,
        crude_branch_time,
        estimate,
        force_bounds,
        quasi_static_branch_time,
        slope_criterion,
    )
    from ._reduced._segment import ALPHA_MODELS, V_EQUATIONS, ReducedSegment, reduced_segment
    from .bursts import (
        ALTERNATIVES,
        BURST_COLUMNS,
        MAX_XMIN_CANDIDATES,
        BrokenPowerLawFit,
        BurstCatalogue,
        LikelihoodRatio,
        PowerLawFit,
        burst_catalogue,
        compare_power_law,
        fit_broken_power_law,
        fit_power_law,
    )

__all__ = [
    "PeelParams",
    "FrontParams",
    "FrontPattern",
    "TransverseModes",
    "front_pattern",
    "transverse_growth_rates",
    "ForceSeries",
    "Slips",
    "Spectrum",
    "SeriesLyapunov",
    "SurrogateTest",
    "PeelForce",
    "Folds",
    "FitResult",
    "FoldEstimate",
    "GEOMETRIES",
    "PARAM_RANGES",
    "STATE_RANGES",
    "TIME_MAX",
    "RTOL_RANGE",
    "EPS_RANGE",
    "EPS_DEFAULT",
    "TAPE_MASS_RANGE",
    "LOADINGS",
    "LOAD_MASS_RANGE",
    "LOAD_RANGE",
    "GRAVITY",
    "T_TRANSIENT",
    "LYAPUNOV_TAU",
    "WINDOW_DEFAULTS",
    "F0_FACTOR",
    "BREAKDOWN_LEVEL",
    "peel_force",
    "peel_force_derivative",
    "branch_structure",
    "branch_inverse",
    "BranchStructure",
    "fixed_point",
    "FixedPoint",
    "BRANCHES",
    "ModelBreakdown",
    "SolverBudgetExceeded",
    "SolverFailure",
    "KernelCacheWarning",
    # reduced α equations (Sec. V)
    "inertial_frequency",
    "inertial_period",
    "inertial_periods",
    "InertialPeriods",
    "harmonic_alpha",
    "airy_alpha",
    "sinusoid_alpha",
    "wkb_amplitude_phase",
    "wkb_alpha",
    "wkb_error_bound",
    "alpha_numerical",
    "ALPHA_FORMS",
    "cd_damping_time",
    "cd_decay_alpha",
    # reduced velocity equation on a branch
    "reduced_segment",
    "ReducedSegment",
    "ALPHA_MODELS",
    "V_EQUATIONS",
    # estimates
    "estimate",
    "RegimeEstimate",
    "INERTIA_RULE",
    "VELOCITY_RULE",
    "crude_branch_time",
    "quasi_static_branch_time",
    "force_bounds",
    "slope_criterion",
    "SlopeCriterion",
    # the return map of an exact trajectory
    "return_map",
    "periodicity",
    "Periodicity",
    "classify",
    "force_drops",
    "settle_time",
    # the observables of a stick-slip attractor (exact: attractor_observables; the reduced equations' prediction)
    "StickSlipObservables",
    "approximate_attractor",
    "ApproximateAttractor",
    "ApproximationWarning",
    # burst catalogues and their power-law statistics (any power series or measured catalogue)
    "burst_catalogue",
    "BurstCatalogue",
    "BURST_COLUMNS",
    "fit_power_law",
    "PowerLawFit",
    "MAX_XMIN_CANDIDATES",
    "compare_power_law",
    "LikelihoodRatio",
    "ALTERNATIVES",
    "fit_broken_power_law",
    "BrokenPowerLawFit",
    # dynamics of the exact solution: they live in exact, imported from it on first access
    "attractors",
    "Attractor",
    "attractor_observables",
    "lyapunov",
    "lyapunov_tangent",
    "lyapunov_return_map",
    "LyapunovResult",
    "benettin",
    "periodic_orbit",
    "PeriodicOrbit",
    "continue_orbit",
    "OrbitBranch",
    "switch_branch",
    "basins",
    "BasinResult",
    "infer",
    "Inference",
    # (I, V) sweeps
    "sweep",
    "load_sweep",
    "SweepResult",
    "register_measure",
    "MEASURES",
    "parse_grid",
]

#: Names offered here that live in another package: name -> module, imported on first access (a module
#: ``__getattr__``), so that ``import peelapprox`` imports no sibling package.  The object is the module's
#: own (``peelapprox.MEASURES is comparisons.sweep.MEASURES``: one registry).
_LAZY = {name: "comparisons.sweep" for name in
         ("sweep", "load_sweep", "SweepResult", "register_measure", "MEASURES", "parse_grid")}
# the dynamics that run the exact solver (the Lyapunov family, attractors) live in exact
_LAZY.update({name: "exact" for name in ("attractors", "Attractor", "attractor_observables", "lyapunov",
                                         "lyapunov_tangent", "lyapunov_return_map", "LyapunovResult", "benettin",
                                         "periodic_orbit", "PeriodicOrbit", "continue_orbit", "OrbitBranch",
                                         "switch_branch", "basins", "BasinResult", "infer", "Inference")})
#: This package's own names whose modules import scipy's optimize/integrate/special (the burst statistics), imported
#: on first access the same way (documented on this package's page, their home), so that ``import peelapprox`` and a
#: first ``exact.simulate`` import none of them (docs/performance.md, "After `peelapprox warmup`";
#: tests/test_cold_start.py).
_OWN_HOMES: dict[str, tuple[str, ...]] = {
    "peelapprox.bursts": (
        "ALTERNATIVES", "BURST_COLUMNS", "MAX_XMIN_CANDIDATES", "BrokenPowerLawFit", "BurstCatalogue",
        "LikelihoodRatio", "PowerLawFit", "burst_catalogue", "compare_power_law", "fit_broken_power_law",
        "fit_power_law"),
    # the reduced equations, the approximate attractor, the estimates and a measured force trace: the reduced-map
    # kernels' modules, scipy's integrate/special on use, none needed by exact.simulate
    "peelapprox._measured._series": ("ForceSeries", "Spectrum"),
    "peelapprox._measured._series_lyapunov": ("SeriesLyapunov", "SurrogateTest"),
    "peelapprox._reduced._alpha": (
        "ALPHA_FORMS", "InertialPeriods", "airy_alpha", "alpha_numerical", "cd_damping_time", "cd_decay_alpha",
        "harmonic_alpha", "inertial_frequency", "inertial_period", "inertial_periods", "sinusoid_alpha", "wkb_alpha",
        "wkb_amplitude_phase", "wkb_error_bound"),
    "peelapprox._reduced._approx_result": ("ApproximateAttractor", "ApproximationWarning"),
    "peelapprox._reduced._approximate": ("approximate_attractor",),
    "peelapprox._reduced._estimate": (
        "INERTIA_RULE", "VELOCITY_RULE", "RegimeEstimate", "SlopeCriterion", "crude_branch_time", "estimate",
        "force_bounds", "quasi_static_branch_time", "slope_criterion"),
    "peelapprox._reduced._segment": ("ALPHA_MODELS", "V_EQUATIONS", "ReducedSegment", "reduced_segment"),
}
_OWN_LAZY = {name: module for module, names in _OWN_HOMES.items() for name in names}

def __getattr__(name: str):
    module = _LAZY.get(name) or _OWN_LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY) | set(_OWN_LAZY))
