"""peelapprox: stick-slip peeling of an adhesive tape from a roller.

Companion library to R. De, A. Maybhate and G. Ananthakrishna, "Dynamics of
stick-slip in peeling of an adhesive tape".  The core package holds the model
parameters and the peel-force function; the exact DAE solvers live in the
``exact`` package and the approximate-vs-exact harness in ``comparisons``.
"""

from ._errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure
from ._params import GEOMETRIES, PeelParams
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

__version__ = "0.1.0"

__all__ = [
    "PeelParams",
    "GEOMETRIES",
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
]
