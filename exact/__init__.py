"""The full peeling model and its solvers.

``simulate(params, t_end, ...)`` integrates the differential-algebraic system
FLOW1, FLOW2, flow3 with the constraint CONSTR of De, Maybhate and
Ananthakrishna, either in the ε → 0 limit (``method="hybrid"``, default) or
with the paper's ε-regularised mass-matrix scheme (``method="regularized"``).
The option objects :class:`Hybrid`, :class:`Regularized` (the method and its
error control), :class:`SaveAt` (what is stored) and :class:`Budget` (the
limits) are the validated forms of ``simulate``'s keywords.
"""

from peelapprox._errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure

from ._options import Budget, Hybrid, Regularized, SaveAt
from ._simulate import (
    ATOL_SCALE,
    STEP_BUDGET,
    compile_kernels,
    default_atol,
    default_max_steps,
    hybrid_field,
    initial_state,
    simulate,
)
from ._trajectory import Jump, Jumps, SolverStats, State, Trajectory
from ._variational import lyapunov_variational

__all__ = [
    "simulate",
    "Hybrid",
    "Regularized",
    "SaveAt",
    "Budget",
    "initial_state",
    "compile_kernels",
    "ATOL_SCALE",
    "STEP_BUDGET",
    "default_max_steps",
    "default_atol",
    "hybrid_field",
    "lyapunov_variational",
    "Trajectory",
    "Jumps",
    "Jump",
    "State",
    "SolverStats",
    "ModelBreakdown",
    "SolverBudgetExceeded",
    "SolverFailure",
]
