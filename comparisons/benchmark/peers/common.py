"""The peers' common ground: which peers exist, their result, the argument checks, the availability probe and
:func:`run_peer`, which dispatches to the backend modules (:mod:`.sundials`, :mod:`.diffsol`)."""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from exact import default_atol, initial_state
from peelapprox import branch_structure
from peelapprox.kernels import PeerUnavailableError, import_optional
from peelapprox.validate import choice, duration, in_range, reals
from peelapprox.validate import eps as _eps
from peelapprox.validate import params as _params

from . import diffsol, sundials

if TYPE_CHECKING:  # pragma: no cover
    from peelapprox import PeelParams

__all__ = ["PEERS", "PeerResult", "PeerUnavailableError", "available_peers", "run_peer"]

#: The peers :func:`run_peer` knows.
PEERS = ("ida", "cvode", "diffsol")

#: Package (import name, pip name) each peer needs.
_PACKAGES = {
    "ida": ("sksundae", "scikit-sundae"),
    "cvode": ("sksundae", "scikit-sundae"),
    "diffsol": ("pydiffsol", "pydiffsol"),
}


@dataclass(frozen=True)
class PeerResult:
    """Outcome of one peer run.

    Attributes
    ----------
    peer : str
        One of :data:`PEERS`.
    eps, rtol : float
        Regularisation ε and relative tolerance used.
    atol : ndarray, shape (4,)
        Absolute tolerances used for ``(α, ω, F, v)``.
    jump_t, jump_F : ndarray
        Times [s] where v crossed the inflection velocity (either direction)
        and F [N] there, in time order.  On failure: IDA and CVODE keep the
        crossings found before the solver stopped; diffsol raises inside its
        ``solve`` and returns nothing, so they are empty.
    n_steps : int
        Accepted steps (IDA, CVODE: internal steps returned by the one-step
        solve; diffsol: output intervals of ``solve``, crossings not counted);
        -1 if unavailable.
    n_rhs : int
        Right-hand-side (IDA: residual) evaluations; -1 if the peer does not
        expose it (diffsol).
    wall_time : float
        Seconds spent in the integration call only.
    compile_time : float
        Seconds spent building the model in this call (JIT compilation,
        kernel loading, solver construction).
    status : str
        ``"ok"`` or ``"failed: <message>"``.
    """

    peer: str
    eps: float
    rtol: float
    atol: np.ndarray
    jump_t: np.ndarray
    jump_F: np.ndarray
    n_steps: int
    n_rhs: int
    wall_time: float
    compile_time: float
    status: str


def _import(peer: str):
    mod, pip = _PACKAGES[peer]
    return import_optional(mod, pip, f"peer {peer!r}")


@functools.cache
def _works(peer: str) -> bool:
    try:
        mod = _import(peer)
        return diffsol.smoke(mod) if peer == "diffsol" else sundials.smoke(mod, peer)
    except Exception:  # noqa: BLE001 - any failure means "not usable here"
        return False


def available_peers() -> tuple[str, ...]:
    """The peers whose package imports and solves a one-line ODE here.

    Returns
    -------
    tuple of str
        A subset of :data:`PEERS`, in that order.  The check runs once per
        process and peer.
    """
    return tuple(p for p in PEERS if _works(p))


def _check(peer, params, t_end, eps, rtol, atol):
    choice("peer", peer, PEERS)
    _params("params", params)  # every law; the diffsol peer refuses a table (no closed form)
    t_end, eps = duration("t_end", t_end), _eps("eps", eps)
    rt = in_range("rtol", rtol, 0.0, 1.0, lo_open=True, hi_open=True)
    if atol is not None:
        reals("atol", atol, 0.0)  # kind and sign; exact.simulate's parser checks the shape
    a = default_atol("regularized", rt, atol)  # exact.simulate's default and checks
    if np.any(a == 0.0):  # the DiffSL model divides by atol (it integrates X / atol)
        raise ValueError(f"atol must be in (0, inf) for the peers, got {atol!r}")
    return t_end, eps, rt, a


def run_peer(
    peer: str,
    params: PeelParams,
    t_end: float,
    *,
    eps: float,
    rtol: float,
    atol: None | float | Sequence[float] = None,
    alpha0: float = 0.0,
) -> PeerResult:
    """Integrate the ε-regularised system from 0 to ``t_end`` with an external peer.

    Parameters
    ----------
    peer : {"ida", "cvode", "diffsol"}
        See :mod:`comparisons.benchmark.peers`.
    params : PeelParams
        Physical parameters and ``geometry`` (closure of ``cos θ``).
    t_end, eps, rtol : float
        Final time [s], > 0; regularisation ε > 0 (the paper: 1e-7); relative tolerance in (0, 1).
    atol : None, float or 4 floats, optional
        Absolute tolerances of ``(α, ω, F, v)``, > 0; default ``rtol * exact.ATOL_SCALE["regularized"]``, as
        ``exact.simulate(method="regularized")``.
    alpha0 : float
        Initial α; the rest of the start is :func:`exact.initial_state` ``(params, alpha0=alpha0)``.

    Returns
    -------
    PeerResult
        Crossings of the inflection velocity, counters and timings.  A solver failure does not raise:
        ``status`` is ``"failed: <message>"``.

    Raises
    ------
    ValueError
        A bad argument, or an ``alpha0`` with no consistent start; the message names it and its range.
    PeerUnavailableError
        (an ``ImportError``) The peer's package is not installed.

    Notes
    -----
    SUNDIALS runs with ``max_num_steps`` = 1e8 (the run is one ``solve``), the analytic Jacobian, dense LU, the
    rest at its defaults (BDF up to order 5); diffsol with :data:`peelapprox.kernels.DIFFSOL_OPTIONS`, since at
    its defaults the stale Jacobian across a fold fails Newton (ε = 1e-7, rtol = 1e-6) and the restart after a
    crossing needs steps below ``min_timestep`` = 1e-13 s (ε = 1e-9 or rtol <= 1e-10).
    """
    t_end, eps, rtol, a = _check(peer, params, t_end, eps, rtol, atol)
    s0 = initial_state(params, alpha0=alpha0)
    mod = _import(peer)
    y0 = np.array([s0.alpha, s0.omega, s0.F, s0.v])
    vm = branch_structure(params.V, force=params.force).v_inflection
    if peer == "diffsol":
        out = diffsol.run(params, t_end, eps, rtol, a, y0)
    else:
        out = sundials.run(mod, peer, params, t_end, eps, rtol, a, y0, vm)
    return PeerResult(peer=peer, eps=eps, rtol=rtol, atol=a, **out)
