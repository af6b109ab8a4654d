"""The full peeling model: its solvers, its periodic orbits and its dynamics, in three rooms behind one face.

* **Solving** (this package's own modules): ``simulate(params, t_end, ...)`` integrates the DAE FLOW1, FLOW2,
  flow3 with the constraint CONSTR of De, Maybhate and Ananthakrishna by one of the methods in ``METHODS``:
  the ε → 0 limit ``Hybrid`` (the paper's model's default), the ε-regularised mass-matrix scheme
  ``Regularized`` (a massless tape under a load) or the tape-mass model's smooth ODE ``Smooth``, each solving
  some of the models in ``MODELS`` (``Massless``, ``MasslessLoad``, ``TapeMass``, ``TapeMassLoad``: frozen
  dataclasses deriving from ``Model``, which carry their state layout, field, events and start); ``SaveAt`` and
  ``Budget`` say what is stored and the limits.  The saltation-tangent driver the other two rooms share is
  here too.
* **Orbits** (:mod:`exact.orbits`): the AB→CD section map and its Jacobian, periodic orbits by Newton and their
  Floquet multipliers, continuation in a parameter with its bifurcations, crest and grazing ends, and the
  switch to a doubled branch (``periodic_orbit``, ``continue_orbit``, ``switch_branch``).
* **Dynamics** (:mod:`exact.dynamics`, built on the orbits, never the other way): windowed runs, attractors
  and their observables, basins, brute-force orbit diagrams and the largest Lyapunov exponent by four methods
  (``attractors``, ``basins``, ``orbit_diagram``, ``lyapunov(params, method=...)``).

Every public name is importable from ``exact`` itself; the return-map analysis of a trajectory
(``return_map``, ``periodicity``) is the core package's, :mod:`peelapprox`.
"""

from typing import TYPE_CHECKING

from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure

from ._hybrid_driver import hybrid_field
from ._initial import initial_state
from ._method_contract import default_atol
from ._methods import ATOL_SCALE, STEP_BUDGET, Hybrid, Regularized, Smooth
from ._model import MODELS, Model, model_of, register_model
from ._models import Massless, MasslessLoad, TapeMass, TapeMassLoad
from ._options import METHODS, Budget, SaveAt, default_max_steps
from ._shared import DEFAULT_MAX_WALL
from ._simulate import simulate
from ._trajectory import Jump, Jumps, SolverStats, State, Trajectory
from ._warmup import WarmupReport, compile_kernels

if TYPE_CHECKING:  # the orbits, dynamics and front rooms: imported on first access (``_LAZY`` below)
    from .dynamics import (
        MAX_BASIN_STARTS,
        MAX_DIAGRAM_VALUES,
        VARIATIONAL_LAWS,
        Attractor,
        AttractorSet,
        BasinAttractor,
        BasinResult,
        BenettinResult,
        EscapePrediction,
        Inference,
        LyapunovResult,
        OrbitDiagram,
        SetAttractor,
        SetOutcome,
        SetStart,
        attractor_observables,
        attractor_set,
        attractors,
        basins,
        benettin,
        check_lyapunov_options,
        explain,
        infer,
        lyapunov,
        lyapunov_return_map,
        lyapunov_tangent,
        lyapunov_variational,
        orbit_diagram,
        window_run,
    )
    from .front import FrontTrajectory, simulate_front
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
    "simulate_front",
    "FrontTrajectory",
    "Hybrid",
    "Regularized",
    "Smooth",
    "MODELS",
    "Model",
    "Massless",
    "MasslessLoad",
    "TapeMass",
    "TapeMassLoad",
    "register_model",
    "model_of",
    "SaveAt",
    "Budget",
    "initial_state",
    "compile_kernels",
    "WarmupReport",
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
    "attractor_set",
    "AttractorSet",
    "SetAttractor",
    "SetOutcome",
    "SetStart",
    "EscapePrediction",
    "DEFAULT_MAX_WALL",
    "lyapunov",
    "check_lyapunov_options",
    "lyapunov_tangent",
    "lyapunov_return_map",
    "LyapunovResult",
    "benettin",
    "BenettinResult",
    "infer",
    "Inference",
]


#: The names of the orbits, dynamics and front rooms: name -> module, imported on first access (a module
#: ``__getattr__``), so that ``import exact`` and a first ``simulate`` import only the solving room
#: (docs/performance.md, "After `peelapprox warmup`"; tests/test_cold_start.py).  Each is the module's own object.
_LAZY: dict[str, str] = {}
_LAZY.update(dict.fromkeys((
    "MAX_BASIN_STARTS", "MAX_DIAGRAM_VALUES", "VARIATIONAL_LAWS", "Attractor", "AttractorSet", "BasinAttractor",
    "BasinResult", "BenettinResult", "EscapePrediction", "Inference", "LyapunovResult", "OrbitDiagram",
    "SetAttractor", "SetOutcome", "SetStart", "attractor_observables", "attractor_set", "attractors", "basins",
    "benettin", "check_lyapunov_options", "explain", "infer", "lyapunov", "lyapunov_return_map",
    "lyapunov_tangent", "lyapunov_variational", "orbit_diagram", "window_run"
), "exact.dynamics"))
_LAZY.update(dict.fromkeys((
    "FrontTrajectory", "simulate_front"
), "exact.front"))
_LAZY.update(dict.fromkeys((
    "Bifurcation", "BranchPoint", "Crest", "OrbitBranch", "PeriodicOrbit", "SectionReturn", "continue_orbit",
    "crest_margin", "monodromy_fd", "parameter_value", "periodic_orbit", "section_return", "solve_orbit",
    "switch_branch", "with_parameter"
), "exact.orbits"))


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # once: later lookups are plain module attributes
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
