"""The hybrid solver's two drivers: the peel-force law inlined, or passed as a typed function argument (issue 15).

The driver body is one function, :func:`exact._hybrid._run`; it calls its field, pull force and DOP853 pieces
through module globals, which this module binds twice:

* ``driver(False)`` -- the paper's law fvV **inlined** (the field :func:`exact._hybrid._rhs`, the parameter
  vector ``p`` carrying ``b, A``): the default path, the arithmetic and the speed of 0.2.0;
* ``driver(True)`` -- the law as an **argument**: ``law`` of type :data:`peelapprox.kernels.LAW_TYPE` and its
  coefficients ``coef`` (float64[::1]) travel with ``p`` as ``P = (p, law, coef)`` to the field
  :func:`_rhs_law`, which calls ``law(u, coef, LAW_LNV)``.  Compiled once for :data:`RUN_SIG`, it runs every
  compiled law (:data:`peelapprox.kernels.LAWS`) with any coefficients without compiling again.

Why two: through the argument the law is an indirect call that LLVM cannot inline into the field (~4 ns of a
~25 ns field evaluation, ~12 per step: +5-10 % per step on the benchmark scenes; ``python -m
comparisons.benchmark.law_cost``), so the default path keeps the inlined law.  Both drivers are compiled for the
same explicit signature on first use and cached across processes (module-level function copies: numba does not
cache a closure over dispatchers across processes).  The kernels that call a law are compiled without numba's
reference-counting runtime (``kernel(nrt=False)``): it wraps every indirect call with an array argument in atomic
reference-count updates it cannot prune (measured: 62 instead of 29 ns per field evaluation).
"""

from __future__ import annotations

import math
import types as pytypes
from collections.abc import Callable
from typing import Any, cast

import numpy as np
from numba import types as _t
from scipy.optimize import brentq

from peelapprox import BranchStructure, PeelParams, branch_structure
from peelapprox.kernels import (
    LAW_FP,
    LAW_LNV,
    LAW_TYPE,
    LAWS,
    cubic_v_structure,
    kernel,
    make_dop853,
    paper_coefficients,
)

from . import _hybrid as H

__all__ = ["HYBRID_LAWS", "RUN_SIG", "branch_root", "driver", "law_for", "pull_force_law"]

#: The laws (``PeelParams.force``, by ``peelapprox._law.law_label``) that ``simulate(method="hybrid")`` runs.
HYBRID_LAWS = ("paper", "cubic")

_A1 = _t.float64[::1]


@kernel(nrt=False)  # no reference counting around the law call (module docstring)
def _pull_force_P(alpha, v, P):
    """F = f(v) / (1 + c(α))  (CONSTR solved for F), f the law of ``P = (p, law, coef)``: ``law(v, coef, LAW_FP)``."""
    p, law, coef = P
    f, _, _ = law(v, coef, LAW_FP)
    c, _ = H._closure(alpha, p)
    return f / (1.0 + c)


@kernel(signature=_t.float64(_t.float64, _t.float64, _A1, LAW_TYPE, _A1), nrt=False)
def pull_force_law(alpha, v, p, law, coef):
    """:func:`exact._hybrid.pull_force` for the law ``law`` with the coefficients ``coef``."""
    return _pull_force_P(alpha, v, (p, law, coef))


@kernel(nrt=False)  # no reference counting around the law call (module docstring)
def _rhs_law(y, P, out):
    """The field of :func:`exact._hybrid._rhs` for the law of ``P = (p, law, coef)``: ``law(u, coef, LAW_LNV)``
    gives ``(v, f, v f')``."""
    p, law, coef = P
    v, f, g = law(y[3], coef, LAW_LNV)
    H._field(y, p, v, f, g, out)


@kernel(inline="always")
def _pack_paper(p, law, coef):
    """What the inlined-law driver's field receives: ``p`` (the paper's law reads ``p[M_B], p[M_A]``)."""
    return p


@kernel(inline="always")
def _pack_law(p, law, coef):
    """What the law driver's field receives: ``(p, law, coef)``."""
    return (p, law, coef)


#: The one signature of both drivers: ``(st, p, law, coef, rtol, atol, t_end, t_store, save_mode, t_eval, out,
#: out_br, jbuf, cnt, max_call_steps) -> status``.
RUN_SIG = _t.int64(
    _A1, _A1, LAW_TYPE, _A1, _t.float64, _A1, _t.float64, _t.float64, _t.int64, _A1, _t.float64[:, ::1], _t.int8[::1],
    _t.float64[:, ::1], _t.int64[::1], _t.int64,
)


def _driver_copy(field: Callable, pull: Callable, pack: Callable) -> pytypes.FunctionType:
    """:func:`exact._hybrid._run` reading ``field``, ``pull``, ``pack`` and the DOP853 pieces of ``field`` as its
    globals ``_FIELD``, ``_PULL``, ``_PACK``, ``_dop``: a module-level function (no closure), so numba caches it."""
    run = H._run
    g = dict(run.__globals__, _FIELD=field, _PULL=pull, _PACK=pack, _dop=make_dop853(field))
    fn = pytypes.FunctionType(run.__code__, g, run.__name__, run.__defaults__, None)
    fn.__qualname__, fn.__module__, fn.__doc__ = run.__qualname__, run.__module__, run.__doc__
    return fn


_DRIVERS = {
    False: kernel(_driver_copy(H._rhs, H.pull_force, _pack_paper), name="run_inlined"),
    True: kernel(_driver_copy(_rhs_law, _pull_force_P, _pack_law), name="run_law"),
}


def driver(law_argument: bool) -> Any:
    """The hybrid driver, compiled for :data:`RUN_SIG` on first use (loaded from numba's cache when it is there)
    and for no other signature.

    Parameters
    ----------
    law_argument : bool
        False: the paper's law fvV inlined, ``law`` and ``coef`` unused (the default path).  True: the law
        ``law`` (:data:`peelapprox.kernels.LAW_TYPE`) with the coefficients ``coef``.

    Returns
    -------
    numba dispatcher
        ``run(st, p, law, coef, rtol, atol, t_end, t_store, save_mode, t_eval, out, out_br, jbuf, cnt,
        max_call_steps) -> status`` (:func:`exact._hybrid._run`).
    """
    d = _DRIVERS[bool(law_argument)]
    if not d.signatures:
        d.compile(RUN_SIG)
        d.disable_compile()
    return d


def law_for(params: PeelParams) -> tuple[Callable, np.ndarray, BranchStructure, bool]:
    """The peel-force law of ``params`` as the hybrid drivers take it: ``(law, coef, branch structure, given)``.

    * the paper's law (``PeelParams.force`` = ``PeelForce.paper()``, the default): the inlined driver's
      ``(paper_law, [b, A] = peel_force_coefficients(V), branch_structure(V), False)``;
    * ``PeelForce.cubic(a, b, c, d)``: ``(cubic_v_law, [a, b, c, d], cubic_v_structure(coef, V), True)``, run
      by the law driver ``driver(True)`` (folds and landings in closed form).

    Raises
    ------
    ValueError
        Naming ``params.force``: for any other law (``validate.params`` refuses those first), or a cubic
        without two folds whose CD→AB jumps land (``cubic_v_structure``'s conditions).
    """
    force = params.force
    if force.kind == "paper":
        return LAWS["paper"], paper_coefficients(params.V), branch_structure(params.V), False
    if force.kind == "family" and force.name == "cubic":
        named = dict(force.coefficients)
        coef = np.array([named[k] for k in ("a", "b", "c", "d")], dtype=float)
        try:
            bs = cubic_v_structure(coef, params.V)
        except ValueError as e:
            raise ValueError(f"params.force: {force!r} cannot be run by the hybrid solver: {e}") from None
        return LAWS["cubic_v"], coef, bs, True
    raise ValueError(f"params.force: {force!r} is not yet supported by exact.simulate; see issue 15")


def branch_root(law: Callable, coef: np.ndarray, bs: BranchStructure, G: float, branch: str) -> float:
    """v on ``branch`` with ``f(v) = G`` (CONSTR) for the compiled law ``law`` with ``coef``: Brent's method in
    ln v (relative accuracy ~4 ulp in v), bracketed by the law's folds ``bs`` -- AB on ``(0, v_max]`` from
    ``v = e^-690`` (where ``f = f(0+)`` to rounding), CD on ``[v_min, ∞)`` up to where f first exceeds G
    (doubling).  ``G`` must be in ``bs.level_range(branch)`` (the caller checks :meth:`BranchStructure.has_root`).
    """

    def g(u: float) -> float:
        return float(law(math.exp(u), coef, LAW_FP)[0]) - G

    if branch == "AB":  # the laws run through here have folds (law_for)
        lo, hi = -690.0, math.log(cast(float, bs.v_max))
    else:
        lo = hi = math.log(cast(float, bs.v_min))
        while g(hi) < 0.0:
            hi += math.log(2.0)
    if g(hi) == 0.0:
        return math.exp(hi)
    return math.exp(brentq(g, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps))
