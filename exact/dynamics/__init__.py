"""The dynamics of the exact solution: windowed runs and the attractors they reach (``window_run``,
``attractors``, ``attractor_observables``), the set of coexisting attractors with their stability
(``attractor_set``), basins of attraction (``basins``), brute-force orbit diagrams
(``orbit_diagram``, ``explain``), the largest Lyapunov exponent by four methods (``lyapunov``; ``benettin``
for any flow) and the parameters that reproduce measured force traces (``infer``).

Built on the solvers of :mod:`exact` and on :mod:`exact.orbits` (basins name their periodic orbits, diagrams are
explained by continued branches).  Every name here is also :mod:`exact`'s.
"""

from ._attractor_set import attractor_set
from ._attractor_set_result import AttractorSet, SetAttractor, SetOutcome, SetStart
from ._attractors import Attractor, attractor_observables, attractors, window_run
from ._basins import MAX_BASIN_STARTS, BasinAttractor, BasinResult, basins
from ._benettin import BenettinResult, LyapunovResult, benettin
from ._diagram import MAX_DIAGRAM_VALUES, OrbitDiagram, explain, orbit_diagram
from ._escape import EscapePrediction
from ._infer import Inference, infer
from ._lyapunov import check_lyapunov_options, lyapunov, lyapunov_return_map, lyapunov_tangent
from ._variational import VARIATIONAL_LAWS, lyapunov_variational

__all__ = [
    "window_run", "attractors", "Attractor", "attractor_observables", "basins", "MAX_BASIN_STARTS", "BasinResult",
    "BasinAttractor", "orbit_diagram", "MAX_DIAGRAM_VALUES", "explain", "OrbitDiagram", "lyapunov",
    "check_lyapunov_options", "lyapunov_tangent", "lyapunov_return_map", "LyapunovResult", "benettin",
    "BenettinResult", "lyapunov_variational", "VARIATIONAL_LAWS", "infer", "Inference", "attractor_set",
    "AttractorSet", "SetAttractor", "SetOutcome", "SetStart", "EscapePrediction",
]
