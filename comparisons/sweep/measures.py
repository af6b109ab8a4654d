"""The measures of a sweep: the registry (:data:`MEASURES`, :func:`register_measure`) and the built-ins.

A measure is ``fn(params: PeelParams, options: Mapping) -> dict`` of JSON scalars (or lists of them, at most two
levels: the point's slice of an array), evaluated at every grid
point (see :mod:`comparisons.sweep`).  To add one, write the function and register it, with a
``check_options(options)`` that validates every option it reads with the validators of
:mod:`peelapprox.validate` (raising ValueError naming the option and its range); :func:`~comparisons.sweep.sweep`
calls it before the first point:

    from comparisons.sweep import register_measure
    register_measure("mine", fn, check_options=check)

The built-ins: ``regime`` (:func:`peelapprox.estimate`, closed form), ``jumps`` (jump statistics of one
windowed exact run), ``period`` (the return map's period over the same run), ``lyapunov`` (the largest
Lyapunov exponent of :func:`peelapprox.lyapunov`, bits/s).  Their options: ``jumps`` and ``period`` share
the one run of :func:`exact.window_run` and read ``t_transient`` (30 s), ``t_end`` (t_transient + 20 s),
``rtol`` (1e-10) and ``alpha0`` (0), ``period`` also ``period_rtol``; ``lyapunov`` reads ``t_transient`` and
``lyapunov_time`` (50 s); ``solver`` (default: the method's) is the scipy solver of a model variant's runs,
one of :func:`solvers`.  The engine reads the other :class:`~peelapprox.PeelParams` fields (``k, R, l,
geometry`` and the variant's ``tape_mass, loading, load_mass, load``) and adds ``max_wall``, what is left of
the sweep's wall-clock budget, which the built-ins pass on to their runs.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from exact import METHODS, lyapunov, model_of, window_run
from peelapprox import (
    LYAPUNOV_TAU,
    T_TRANSIENT,
    TIME_MAX,
    WINDOW_DEFAULTS,
    ModelBreakdown,
    PeelParams,
    classify,
    estimate,
    force_drops,
    return_map,
)
from peelapprox.validate import choice, duration, in_range, optional, positive, state
from peelapprox.validate import rtol as _rtol

from .store import RESERVED

__all__ = ["MEASURES", "register_measure", "record_key", "measure_period", "measure_lyapunov"]

Measure = Callable[[PeelParams, Mapping], dict]
OptionCheck = Callable[[Mapping], Any]

#: name -> measure function.  Add entries with :func:`register_measure`.
MEASURES: dict[str, Measure] = {}
#: name -> its options check (``check_options`` of :func:`register_measure`), called by the engine before the
#: first point.
OPTION_CHECKS: dict[str, OptionCheck] = {}

_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def measure_ref(fn: Callable) -> str:
    """How workers import ``fn``: ``"module:qualname"`` (the manifest's ``measure_refs``)."""
    return f"{getattr(fn, '__module__', '?')}:{getattr(fn, '__qualname__', '?')}"


def register_measure(name: str, fn: Measure | None = None, *, replace: bool = False,
                     check_options: OptionCheck | None = None):
    """Register ``fn(params, options) -> dict`` under ``name``; called without ``fn``, return a decorator that
    registers the function it decorates.

    Parameters
    ----------
    name : str
        ``[A-Za-z][A-Za-z0-9_]*``, not one of ``I, V, status``.
    fn : callable
        The measure.  Pool and cluster workers import it by ``module:qualname``;
        one they cannot import (a notebook's, ``__main__``'s, a lambda) is
        shipped by value with cloudpickle if installed, else :func:`sweep`
        refuses it before the first point.
    replace : bool
        Registering another function under a taken name raises ValueError
        unless True (registering the same function again, e.g. on re-import,
        is allowed).
    check_options : callable, optional
        ``check_options(options)`` raises ValueError naming an option this
        measure reads that is invalid; :func:`sweep` calls it before the first
        point, so a bad option never turns every point into an error record.

    Returns
    -------
    callable
        ``fn``.
    """
    if fn is None:
        return lambda f: register_measure(name, f, replace=replace, check_options=check_options)
    if not isinstance(name, str) or not _NAME_RE.match(name) or name in RESERVED:
        raise ValueError(
            f"measure name must match [A-Za-z][A-Za-z0-9_]* and not be one of {RESERVED}, got {name!r}")
    if not callable(fn):
        raise ValueError(f"measure {name!r}: fn must be callable (params, options) -> dict, got {fn!r}")
    if check_options is not None and not callable(check_options):
        raise ValueError(f"measure {name!r}: check_options must be callable (options) or None, got {check_options!r}")
    old = MEASURES.get(name)
    if old is not None and old is not fn and measure_ref(old) != measure_ref(fn) and not replace:
        raise ValueError(f"measure {name!r} is already registered as {measure_ref(old)}; "
                         "pass replace=True to replace it")
    MEASURES[name] = fn
    if check_options is None:
        OPTION_CHECKS.pop(name, None)
    else:
        OPTION_CHECKS[name] = check_options
    return fn


def record_key(name: str, key: str) -> str:
    """The record key of ``key`` returned by measure ``name``: ``key`` itself if it is ``name`` or starts
    with ``"<name>_"``, else ``"<name>_<key>"``."""
    return key if (key == name or key.startswith(name + "_")) else f"{name}_{key}"


# --------------------------------------------------------------------------------------------- built-in measures
# ``jumps`` and ``period`` share the one windowed exact run, :func:`exact.window_run` (its last call is cached,
# so the two measures of a point compute it once).  Each passes its runs the engine's option ``max_wall``, what
# is left of the sweep's wall-clock budget (absent: no budget), the same for every measure of a point.

def _wall(options: Mapping) -> dict:
    """``{"max_wall": seconds}`` from the engine's option ``max_wall`` (the sweep's budget left), else ``{}``."""
    return {"max_wall": options["max_wall"]} if options.get("max_wall") is not None else {}


def _measure_regime(params: PeelParams, options: Mapping) -> dict:
    """Regime label of :func:`peelapprox.estimate` and its closed-form time scales (a few ms)."""
    e = estimate(params)
    return {
        "label": e.label,
        "inertia": e.inertia,
        "velocity": e.velocity,
        "fixed_point_stable": bool(e.fixed_point_stable),
        "inertia_ratio": e.inertia_ratio,
        "period_at_mean": e.period_at_mean,
        "cd_damping_time": e.cd_damping_time,
        "t_ab_crude": e.t_ab_crude,
        "t_ab_quasi_static": e.t_ab_quasi_static,
        "t_cd_quasi_static": e.t_cd_quasi_static,
        "oscillations_per_ab": e.oscillations_per_ab,
        "force_gap": e.force_gap,
    }


def _measure_jumps(params: PeelParams, options: Mapping) -> dict:
    """Stick-slip jump statistics of the exact solution in the window ``[t_transient, t_end]``
    (``window_run``: t_transient 30 s, t_end t_transient + 20 s, rtol 1e-10).

    ``count`` jumps in the window, ``n_slips`` of them AB→CD; ``mean_interval``
    = mean time between consecutive jumps (either kind), ``mean_period`` =
    mean time between consecutive AB→CD jumps (the stick-slip period);
    ``mean_force_drop`` = mean over AB→CD jumps of F there minus F at the next
    CD→AB jump [N].  Statistics that need more jumps than the window holds are
    None.  A :class:`ModelBreakdown` gives ``status = "breakdown:<reason>"``
    and the breakdown time ``t_breakdown``.
    """
    try:  # the same windowed run (and defaults) as the `period` measure: computed once per point
        traj = window_run(params, **_window_options(options), **_solver(params, options), **_wall(options))
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}", "t_breakdown": float(exc.t)}
    t = np.asarray(traj.jumps.t, dtype=float)
    t_slip = t[np.asarray(traj.jumps.from_branch) == 0]  # AB -> CD
    drops = force_drops(traj)
    return {
        "status": "ok",
        "count": int(t.size),
        "n_slips": int(return_map(traj).size),
        "mean_interval": float(np.mean(np.diff(t))) if t.size >= 2 else None,
        "mean_period": float(np.mean(np.diff(t_slip))) if t_slip.size >= 2 else None,
        "mean_force_drop": float(np.mean(drops)) if drops.size else None,
    }


def solvers() -> tuple[str, ...]:
    """The valid values of the option ``solver``: every scipy solver of :data:`exact.METHODS`, read when an
    option is checked (so a method added to the table is accepted)."""
    return tuple(dict.fromkeys(s for m in METHODS.values() for s in m.solvers))


def _check_solver(options: Mapping) -> str | None:
    return optional(choice, "solver", options.get("solver"), solvers())


def _solver(params: PeelParams, options: Mapping) -> dict:
    """``{"solver": options["solver"]}`` for the runs of a model without the hybrid method (``Model.has_hybrid``:
    a tape mass, a load), else ``{}`` (the hybrid method has its own integrator); the option checked (ValueError
    naming it and the solvers)."""
    solver = _check_solver(options)
    return {"solver": solver} if solver is not None and not model_of(params).has_hybrid else {}


def _check_window_options(options: Mapping) -> None:
    """The options of the windowed run (:func:`_window_options` checks them)."""
    _window_options(options)


def _window_options(options) -> dict:
    """The :func:`window_run` arguments from sweep options (``t_end`` = t_transient + window also accepted;
    ``solver`` checked here, passed by :func:`_solver`),
    checked by the same validators as :func:`window_run` (ValueError/TypeError naming the option and its valid
    range; the sweep calls this before the first point)."""
    _check_solver(options)
    kw = dict(WINDOW_DEFAULTS)
    kw.update({key: options[key] for key in kw if options.get(key) is not None})
    kw["t_transient"] = duration("t_transient", kw["t_transient"], zero=True)
    kw["alpha0"] = state("alpha0", kw["alpha0"], "alpha")
    kw["rtol"] = _rtol("rtol", kw["rtol"])
    if options.get("t_end") is not None:
        t_end = duration("t_end", options["t_end"])
        if not t_end > kw["t_transient"]:
            raise ValueError(f"t_end must be greater than t_transient = {kw['t_transient']:g} (the measured window "
                             f"is [t_transient, t_end]), got {options['t_end']!r}")
        kw["window"] = t_end - kw["t_transient"]
    kw["window"] = duration("window", kw["window"])
    if kw["t_transient"] + kw["window"] > TIME_MAX:
        raise ValueError(f"t_transient + window must be at most {TIME_MAX:g} s (simulate's t_end), got "
                         f"{kw['t_transient']:g} + {kw['window']:g}")
    return kw


def _period_options(options) -> dict:
    """The checked options of the ``period`` measure: :func:`_window_options` and ``period_rtol`` (1e-6)."""
    return {**_window_options(options), "period_rtol": positive("period_rtol", options.get("period_rtol", 1e-6))}


def _lyapunov_options(options) -> dict:
    """The checked options of the ``lyapunov`` measure: ``t_transient`` (30 s), ``lyapunov_time`` (50 s, at most
    1e6 s) and ``alpha0`` (0), with :func:`lyapunov`'s validators."""
    return {"t_transient": duration("t_transient", options.get("t_transient", T_TRANSIENT), zero=True),
            "lyapunov_time": in_range("lyapunov_time", options.get("lyapunov_time", 50.0), 2 * LYAPUNOV_TAU,
                                      TIME_MAX),
            "alpha0": state("alpha0", options.get("alpha0", 0.0), "alpha"),
            "solver": _check_solver(options)}


def measure_period(params: PeelParams, options) -> dict:
    """Sweep measure ``period``: the return map's period over the window of :func:`window_run` (options
    ``t_transient`` = 30 s, ``t_end`` = t_transient + 20 s, ``rtol`` = 1e-10, ``alpha0`` = 0,
    ``period_rtol`` = 1e-6).  ``period`` is None when aperiodic (no n <= 32 repeats), too short or without
    stick-slip; a ``ModelBreakdown`` is ``status = "breakdown:<reason>"``."""
    kw = _period_options(options)
    period_rtol = kw.pop("period_rtol")
    try:
        tr = window_run(params, **kw, **_solver(params, options), **_wall(options))
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}"}
    p = classify(tr, period_rtol=period_rtol)
    return {"status": "ok", "label": p.label, "period": p.period,
            "mismatch": p.mismatch if math.isfinite(p.mismatch) else None, "n_returns": p.n_returns}


def measure_lyapunov(params: PeelParams, options) -> dict:
    """Sweep measure ``lyapunov``: :func:`lyapunov` with its defaults, except options ``t_transient`` (30 s),
    ``alpha0`` (0) and ``lyapunov_time``, its measured time ``T`` (50 s: ``round(T/tau)`` renormalisation
    intervals of 0.005 s)."""
    kw = _lyapunov_options(options)
    try:
        r = lyapunov(params, t_transient=kw["t_transient"], T=kw["lyapunov_time"], alpha0=kw["alpha0"],
                     **_solver(params, options), **_wall(options))
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}"}
    return {"status": "ok", "bits_per_s": r.bits_per_s, "stderr_bits": r.stderr_bits, "n_jumps": r.n_jumps}


register_measure("regime", _measure_regime)
register_measure("jumps", _measure_jumps, check_options=_check_window_options)
register_measure("period", measure_period, check_options=_period_options)
register_measure("lyapunov", measure_lyapunov, check_options=_lyapunov_options)
