"""External compiled peer solvers on the paper's ε-regularised system.

The system is the one integrated by ``exact.simulate(method="regularized")``
(see :mod:`exact._regularized`): state ``X = (α, ω, F, v)``,

    M Ẋ = φ(X),   M = diag(1, 1, 1, ε),

with φ from :func:`peelapprox.kernels.regularized_rhs` (FLOW1, FLOW2,
flow3 and ``φ_v = F (1 - cos θ) - f(v, V)``), the closure of ``cos θ`` given by
``params.geometry`` and the peel force f of Eq. (fvV).  The same initial state
as the hybrid and the scipy solvers (:func:`exact.initial_state`) is used.

Peers
-----
``"ida"``
    SUNDIALS IDA (variable-order, variable-step BDF for implicit DAEs) through
    ``sksundae.ida`` in residual form ``r = M Ẋ - φ(X)``, with the analytic
    Jacobian ``∂r/∂X + c_j ∂r/∂Ẋ = -∂φ/∂X + c_j M`` and a consistent ``Ẋ(0)``.
``"cvode"``
    SUNDIALS CVODE through ``sksundae.cvode`` on the equivalent ODE
    ``Ẋ = M⁻¹ φ(X)``: BDF, dense direct linear solver, analytic Jacobian.
``"diffsol"``
    pydiffsol (the Rust crate diffsol): its BDF (NDF, after ode15s) with the
    mass matrix M, the model written in DiffSL
    (:func:`peelapprox.kernels.diffsl_code`, printed from the symbolic source) and
    JIT-compiled by LLVM; the Jacobian comes from the compiler's automatic
    differentiation.

The two SUNDIALS peers call back into Python for every right-hand-side or
Jacobian evaluation; the callbacks are the numba-compiled kernels the scipy
driver uses (:func:`peelapprox.kernels.regularized_field`,
:func:`~peelapprox.kernels.regularized_field_jacobian`), so only the call
overhead is Python.  diffsol evaluates the model in JIT-compiled code with no Python in
the loop.

Tolerances
----------
Every peer controls the local error per step in a weighted RMS norm,
``sqrt(mean_i (err_i / (atol_i + rtol |X_i|))^2) <= 1``, as scipy's solvers do,
with ``atol`` defaulting to ``rtol * exact.ATOL_SCALE["regularized"]``
exactly as ``exact.simulate(method="regularized")`` (:func:`exact.default_atol`).  pydiffsol accepts only a
scalar ``atol``; the DiffSL model therefore integrates the scaled state
``y_i = X_i / atol_i`` with ``atol = 1``, which gives exactly the weights
``atol_i + rtol |X_i|`` on X (the relative part is scale invariant).  The
tolerances are *local*: equal ``rtol`` does not mean equal global accuracy
across peers (different methods, orders and error estimators).

Jumps
-----
A jump is recorded where v crosses the inflection velocity ``v_infl`` of
``f(·, V)`` in either direction, as :mod:`exact._regularized` does.  IDA and
CVODE locate it with their root finders (``eventsfn``, non-terminal, on
``v - v_infl``).  For diffsol the DiffSL model carries ``stop { v - v_infl }``
with an identity ``reset``: diffsol's root finder stops the integration at the
crossing, records the state twice (before and after the identity reset) and
restarts the BDF there; those duplicated output times are the crossing
times.  (Restarting at each crossing is part of diffsol's cost.)

Time
----
``wall_time`` is ``time.perf_counter()`` around the integration call only
(``solve``).  Model construction is reported separately in
``compile_time``: for diffsol the DiffSL JIT compilation, for the SUNDIALS
peers the loading (from numba's on-disk cache) or compiling of the numba
kernels, which happens once per process, plus the solver object's
construction.

One module per backend (:mod:`.sundials`, :mod:`.diffsol`); :mod:`.common` holds the list of peers, the
result type, the argument checks, the availability probe and :func:`run_peer`, which dispatches to them.
"""

from peelapprox.kernels import DIFFSOL_OPTIONS

from .common import PEERS, PeerResult, PeerUnavailableError, available_peers, run_peer

__all__ = ["PEERS", "PeerResult", "PeerUnavailableError", "available_peers", "run_peer", "DIFFSOL_OPTIONS"]
