"""Backward-compatible alias of :mod:`comparisons.benchmark.peers` (the external peer solvers moved there in
0.2.0, one module per backend), of the DiffSL model (now :mod:`peelapprox.kernels`, printed by
``peelapprox/_diffsl.py``) and of the ε-variational Lyapunov exponent (now :func:`exact.lyapunov_variational`).

``from comparisons._peers import ...`` keeps working for every name this module exported; new code should
use the new homes.
"""

from comparisons.benchmark.peers import (  # noqa: F401 - re-exported
    DIFFSOL_OPTIONS,
    PEERS,
    PeerResult,
    PeerUnavailableError,
    available_peers,
    run_peer,
)
from exact import lyapunov_variational as lyapunov_regularized  # noqa: F401 - re-exported under its old name
from peelapprox.kernels import (  # noqa: F401 - re-exported
    DIFFSL_INPUTS,
    DIFFSL_TANGENT_INPUTS,
    diffsl_code,
    diffsl_inputs,
    diffsl_model,
)

__all__ = [
    "PEERS",
    "PeerResult",
    "PeerUnavailableError",
    "available_peers",
    "run_peer",
    "diffsl_code",
    "diffsl_model",
    "diffsl_inputs",
    "DIFFSL_INPUTS",
    "DIFFSL_TANGENT_INPUTS",
    "DIFFSOL_OPTIONS",
    "lyapunov_regularized",
]

