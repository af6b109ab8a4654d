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
    "TANGENT_OPTIONS",  # noqa: F822 - moved to exact._variational, re-exported by __getattr__ below
    "tangent_solve",  # noqa: F822 - idem
    "lyapunov_regularized",
]


def __getattr__(name: str):
    """``TANGENT_OPTIONS`` and ``tangent_solve`` moved with the ε-variational Lyapunov exponent
    (``lyapunov_regularized``, now :func:`exact.lyapunov_variational`) to :mod:`exact._variational`."""
    if name in ("TANGENT_OPTIONS", "tangent_solve"):
        from exact import _variational

        return getattr(_variational, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
