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

from collections.abc import Callable
from typing import Any

from numba import types as _t

from peelapprox import PeelParams
from peelapprox.kernels import (
    LAW_FP,
    LAW_LNV,
    LAW_TYPE,
    CompiledLaw,
    compiled_law,
    kernel,
    make_dop853,
    pack_inlined,
    pack_law,
    rebind,
)
from peelapprox.kernels import status as _st

from . import _hybrid as H

__all__ = ["RUN_SIG", "domain_status", "driver", "field_law", "law_for", "pull_force_law"]


_A1 = _t.float64[::1]


@kernel(nrt=False)  # no reference counting around the law call (module docstring)
def _pull_force_P(alpha, v, P):
    """F = f(v) / (1 + c(α))  (CONSTR solved for F), f the law of ``P = (p, law, coef)``: ``law(v, coef, LAW_FP)``."""
    p, law, coef = P
    f, _, _ = law(v, coef, LAW_FP)
    c, _ = H._closure(alpha, p)
    return f / (1.0 + c)


@kernel(signature=_t.float64(_t.float64, _t.float64, _A1, LAW_TYPE, _A1), nrt=False, lazy=True)
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


@kernel(nrt=False)
def _field_law(y, p, law, coef, out):
    """:func:`_rhs_law` with the law and its coefficients as separate arguments (the form Python calls)."""
    _rhs_law(y, (p, law, coef), out)


def field_law() -> Any:
    """``field(y, p, law, coef, out)``: the hybrid field d(τ, α, ω, u)/ds for the law ``law`` with ``coef`` (as
    :func:`exact._hybrid._rhs` for the inlined law), compiled for that one signature on first use (loaded from
    numba's cache when it is there): the saltation tangent's field outside its compiled driver."""
    if not _field_law.signatures:
        _field_law.compile(_t.void(_A1, _A1, LAW_TYPE, _A1, _A1))
        _field_law.disable_compile()
    return _field_law


#: The one signature of both drivers: ``(st, p, law, coef, rtol, atol, t_end, t_store, save_mode, t_eval, out,
#: out_br, jbuf, cnt, max_call_steps) -> status``.
RUN_SIG = _t.int64(
    _A1, _A1, LAW_TYPE, _A1, _t.float64, _A1, _t.float64, _t.float64, _t.int64, _A1, _t.float64[:, ::1], _t.int8[::1],
    _t.float64[:, ::1], _t.int64[::1], _t.int64,
)


def _driver_copy(field: Callable, pull: Callable, pack: Callable) -> Callable:
    """:func:`exact._hybrid._run` reading ``field``, ``pull``, ``pack`` and the DOP853 pieces of ``field`` as its
    globals ``_FIELD``, ``_PULL``, ``_PACK``, ``_dop`` (:func:`peelapprox.kernels.rebind`)."""
    return rebind(H._run, _FIELD=field, _PULL=pull, _PACK=pack, _dop=make_dop853(field))


_DRIVERS = {
    False: kernel(_driver_copy(H._rhs, H.pull_force, pack_inlined), name="run_inlined"),
    True: kernel(_driver_copy(_rhs_law, _pull_force_P, pack_law), name="run_law"),
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


def law_for(params: PeelParams) -> CompiledLaw:
    """The peel-force law of ``params`` as the hybrid drivers take it: :func:`peelapprox.kernels.compiled_law` at
    ``params.V`` (kernel, coefficients, branch structure, domain; ``inlined`` for the paper's law, run by the
    driver with fvV inlined).

    Raises
    ------
    ValueError
        Naming ``params.force``: a law without a compiled kernel, whose folds cannot be found, or whose AB→CD
        jumps would land outside its domain (a table that stops below ``f_max`` on CD).
    """
    law = compiled_law(params.force, params.V)
    bs = law.structure
    if bs.has_folds and bs.v_land_cd is None:
        raise ValueError(f"params.force: {params.force!r} at V={params.V!r} m/s never reaches f_max={bs.f_max!r} N "
                         f"on its fast branch within its domain up to {law.domain[1]!r} m/s: an AB->CD jump could not "
                         "land (extend the table to higher v)")
    return law


def domain_status(status: int, cl: CompiledLaw, v: float, ceiling: float) -> tuple[int, str]:
    """``(status, what)``: a driver's breakdown status re-read as ``LAW_DOMAIN`` where the law's domain, not the
    model, stopped the run -- the floor on AB (NO_ROOT) or a CD→AB landing (NO_LANDING) at a domain starting above
    0, the CD ceiling below ``ceiling`` -- with ``what`` happened (the message's first words)."""
    lo, hi = cl.domain
    bs = cl.structure
    if status == _st.NO_ROOT and lo > 0:
        return _st.LAW_DOMAIN, f"on AB the level F(1 - cos theta) fell to f = {bs.f_zero:.6g} N at the start of the law"
    if status == _st.NO_LANDING and lo > 0:
        return _st.LAW_DOMAIN, (f"the CD->AB jump from f_min = {bs.f_min:.6g} N would land below the start of the law "
                              f"(f = {bs.f_zero:.6g} N there)")
    if status == _st.V_CEILING and hi < ceiling:
        return _st.LAW_DOMAIN, f"v = {v:.6g} m/s rose above the end of the law on CD"
    return status, ""
