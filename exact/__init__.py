"""The full peeling model and its solvers.

``simulate(params, t_end, ...)`` integrates the differential-algebraic system FLOW1, FLOW2, flow3 with the
constraint CONSTR of De, Maybhate and Ananthakrishna by one of its methods: the ε → 0 limit
(``method="hybrid"``, the default for the paper's model), the paper's ε-regularised mass-matrix scheme
(``method="regularized"``, the default for a massless tape under a load) or the tape-mass model's smooth ODE
(``method="smooth"``).  The option objects :class:`Hybrid`, :class:`Regularized`, :class:`Smooth` (the method
and its error control), :class:`SaveAt` (what is stored) and :class:`Budget` (the limits) are the validated
forms of ``simulate``'s keywords.

The dynamics of its solutions: ``window_run`` (the jumps over a window after a transient), ``attractors``
(sampled starts grouped by the attractor they reach), ``attractor_observables`` (the slip interval, force
drop, slip and stick times and period of the attractor one window reaches: a
``peelapprox.StickSlipObservables``) and the largest Lyapunov exponent, ``lyapunov(params,
method=...)`` with the methods "two-trajectory", "tangent", "return-map" and "variational" (also
``lyapunov_tangent``, ``lyapunov_return_map``; ``benettin`` is the generic two-trajectory method for any
flow). Each runs the peel-force law ``params.force`` (any law with a compiled kernel; the variational method,
whose DiffSL model is printed from fvV, the paper's only). The return-map analysis of a trajectory
(``return_map``, ``periodicity``, ``force_drops``, ``settle_time``) is the core package's: :mod:`peelapprox`.
"""

from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure

from ._hybrid_driver import compile_kernels, hybrid_field
from ._initial import initial_state
from ._method_contract import default_atol
from ._methods import ATOL_SCALE, STEP_BUDGET, Hybrid, Regularized, Smooth
from ._options import METHODS, Budget, SaveAt, default_max_steps
from ._shared import DEFAULT_MAX_WALL
from ._simulate import simulate
from ._trajectory import Jump, Jumps, SolverStats, State, Trajectory
from .dynamics import (
    MAX_BASIN_STARTS,
    MAX_DIAGRAM_VALUES,
    VARIATIONAL_LAWS,
    Attractor,
    BasinAttractor,
    BasinResult,
    BenettinResult,
    LyapunovResult,
    OrbitDiagram,
    attractor_observables,
    attractors,
    basins,
    benettin,
    check_lyapunov_options,
    explain,
    lyapunov,
    lyapunov_return_map,
    lyapunov_tangent,
    lyapunov_variational,
    orbit_diagram,
    window_run,
)
from .orbits import (
    Bifurcation,
    BranchPoint,
    Crest,
    OrbitBranch,
    PeriodicOrbit,
    SectionReturn,
    continue_orbit,
    crest_margin,
    monodromy_fd,
    parameter_value,
    periodic_orbit,
    section_return,
    solve_orbit,
    switch_branch,
    with_parameter,
)

__all__ = [
    "simulate",
    "Hybrid",
    "Regularized",
    "Smooth",
    "SaveAt",
    "Budget",
    "initial_state",
    "compile_kernels",
    "ATOL_SCALE",
    "STEP_BUDGET",
    "METHODS",
    "default_max_steps",
    "default_atol",
    "hybrid_field",
    "lyapunov_variational",
    "VARIATIONAL_LAWS",
    "periodic_orbit",
    "PeriodicOrbit",
    "solve_orbit",
    "section_return",
    "SectionReturn",
    "monodromy_fd",
    "continue_orbit",
    "OrbitBranch",
    "BranchPoint",
    "Bifurcation",
    "switch_branch",
    "crest_margin",
    "Crest",
    "orbit_diagram",
    "MAX_DIAGRAM_VALUES",
    "explain",
    "with_parameter",
    "parameter_value",
    "OrbitDiagram",
    "basins",
    "MAX_BASIN_STARTS",
    "BasinResult",
    "BasinAttractor",
    "Trajectory",
    "Jumps",
    "Jump",
    "State",
    "SolverStats",
    "ModelBreakdown",
    "SolverBudgetExceeded",
    "SolverFailure",
    # dynamics of the exact solution
    "window_run",
    "attractors",
    "Attractor",
    "attractor_observables",
    "DEFAULT_MAX_WALL",
    "lyapunov",
    "check_lyapunov_options",
    "lyapunov_tangent",
    "lyapunov_return_map",
    "LyapunovResult",
    "benettin",
    "BenettinResult",
]
