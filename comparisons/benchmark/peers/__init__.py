"""External compiled peer solvers on the paper's ε-regularised system, for the work-precision benchmark.

The system is the one ``exact.simulate(method="regularized")`` integrates: ``M Ẋ = φ(X)``, ``X = (α, ω, F,
v)``, ``M = diag(1, 1, 1, ε)``, φ from :func:`peelapprox.kernels.regularized_rhs`, from the same initial state
(:func:`exact.initial_state`).  The peers: ``"ida"`` (SUNDIALS IDA on the residual ``M Ẋ - φ(X)``) and
``"cvode"`` (SUNDIALS CVODE on ``Ẋ = M⁻¹ φ(X)``), both BDF with the analytic Jacobian, calling back into the
numba kernels of the scipy driver (:mod:`.sundials`); ``"diffsol"`` (diffsol's BDF with the mass matrix, the
model printed in DiffSL by :func:`peelapprox.kernels.diffsl_code`, JIT-compiled, no Python in the loop;
:mod:`.diffsol`).

Tolerances: every peer controls the local error per step in scipy's weighted RMS norm, ``atol`` defaulting to
``rtol * exact.ATOL_SCALE["regularized"]`` as ``simulate``'s; pydiffsol takes only a scalar ``atol``, so its
model integrates ``X_i / atol_i`` with ``atol = 1``, the same weights.  Equal local ``rtol`` does not mean equal
global accuracy across peers.  Jumps: the crossings of the inflection velocity ``v_infl``, as in
:mod:`exact._regularized`, by the solvers' root finders (diffsol stops and restarts its BDF at each, part of
its cost).  Time: ``wall_time`` is the integration call alone; ``compile_time`` the model's construction
(diffsol's JIT, or loading the numba kernels and building the solver).

:mod:`.common` holds the list of peers, the result type, the argument checks, the availability probe and
:func:`run_peer`, which dispatches to the backends.
"""

from peelapprox.kernels import DIFFSOL_OPTIONS

from .common import PEERS, PeerResult, PeerUnavailableError, available_peers, run_peer

__all__ = ["PEERS", "PeerResult", "PeerUnavailableError", "available_peers", "run_peer", "DIFFSOL_OPTIONS"]
