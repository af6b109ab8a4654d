"""peelapprox: stick-slip peeling of an adhesive tape from a roller.

Companion library to R. De, A. Maybhate and G. Ananthakrishna, "Dynamics of
stick-slip in peeling of an adhesive tape".  The core package holds the model
parameters, the peel-force function, the paper's reduced branch-wise
equations (Sec. V) and regime estimates; the exact DAE solvers live in the
``exact`` package and the approximate-vs-exact harness in ``comparisons``.
"""

from . import _dynamics  # noqa: F401  (registers the sweep measures "period" and "lyapunov")
from ._alpha import (
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
from ._errors import KernelCacheWarning, ModelBreakdown, SolverBudgetExceeded, SolverFailure
from ._estimate import (
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
from ._params import GEOMETRIES, PARAM_RANGES, PeelParams
from ._peelforce import (
    BRANCHES,
    BranchStructure,
    FixedPoint,
    branch_inverse,
    branch_structure,
    fixed_point,
    peel_force,
    peel_force_derivative,
)
from ._returnmap import Periodicity, classify, force_drops, periodicity, return_map, settle_time
from ._segment import ALPHA_MODELS, V_EQUATIONS, ReducedSegment, reduced_segment
from ._sweep import MEASURES, SweepResult, load_sweep, parse_grid, register_measure, sweep
from ._version import __version__ as __version__

#: Names offered here that live in the ``exact`` package (they run its solver): imported from it on first
#: access (module ``__getattr__``), so that ``import peelapprox`` does not import ``exact``.
_FROM_EXACT = ("attractors", "Attractor", "lyapunov", "lyapunov_tangent", "lyapunov_return_map", "LyapunovResult",
               "benettin")

__all__ = [
    "PeelParams",
    "GEOMETRIES",
    "PARAM_RANGES",
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
    # dynamics of the exact solution: they live in exact, imported from it on first access
    "attractors",
    "Attractor",
    "lyapunov",
    "lyapunov_tangent",
    "lyapunov_return_map",
    "LyapunovResult",
    "benettin",
    # (I, V) sweeps
    "sweep",
    "load_sweep",
    "SweepResult",
    "register_measure",
    "MEASURES",
    "parse_grid",
]


def __getattr__(name: str):
    """The names of :data:`_FROM_EXACT`, imported from ``exact`` when first asked for (PEP 562)."""
    if name in _FROM_EXACT:
        import exact

        value = getattr(exact, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_FROM_EXACT))
