"""The arguments of :func:`exact.continue_orbit` (``exact/orbits/_continuation.py``), checked in their order (the
first bad one is named, with its valid range) and gathered with what the continuation derives from them: the
start's parameter value, the span to ``stop`` and its sign, the steps and the wall budget."""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

from peelapprox.errors import WallBudget
from peelapprox.validate import finite, function, in_range, integer, optional, positive

from ._corrector import PARAMETERS, VARIANT_PARAMETERS, check_parameter, parameter_value, with_parameter
from ._periodic import PeriodicOrbit


class _Options(NamedTuple):
    """:func:`continue_orbit`'s arguments, checked, with the start's value ``lam0``, the ``span`` to ``stop`` and
    its ``sign``, the initial, smallest and largest steps and the wall budget."""

    parameter: str
    lam0: float
    stop: float
    span: float
    sign: float
    h: float
    hmin: float
    hmax: float
    max_points: int
    max_correction: float
    graze_tol: float
    crest_tol: float
    tol: float
    rtol: float
    locate_tol: float
    progress: Callable[[int, float], None] | None
    wall: WallBudget


def _checked_options(orbit, parameter, stop, step, min_step, max_step, max_points, tol, rtol, locate_tol,
                     max_correction, graze_tol, crest_tol, progress, max_wall) -> _Options:
    """:func:`continue_orbit`'s arguments checked, in this order (the first bad one is named)."""
    if not isinstance(orbit, PeriodicOrbit):
        raise TypeError(f"orbit must be an exact.PeriodicOrbit, got {type(orbit).__name__}")
    if isinstance(parameter, str) and parameter in VARIANT_PARAMETERS:
        raise ValueError(f"parameter={parameter!r}: continue_orbit follows orbits of the paper's massless, "
                         f"velocity-controlled model (the hybrid section map with saltation matrices) in "
                         f"{', '.join(PARAMETERS)} or a family coefficient; over a model variant's parameter use "
                         f"exact.orbit_diagram(params, {parameter!r}, values)")
    parameter = check_parameter(orbit.params, parameter)
    lam0 = parameter_value(orbit.params, parameter)
    stop = finite("stop", stop)
    try:
        with_parameter(orbit.params, parameter, stop)
    except ValueError as exc:
        raise ValueError(f"stop must be a valid value of {parameter}, got {stop!r}: {exc}") from None
    span = abs(stop - lam0)
    if not span > 0:
        raise ValueError(f"stop must differ from the start's {parameter}={lam0}, got {stop}")
    sign = 1.0 if stop > lam0 else -1.0
    h = in_range("step", step, 0.0, span, lo_open=True) if step is not None else span / 50
    hmin = in_range("min_step", min_step, 0.0, span, lo_open=True) if min_step is not None else span * 1e-5
    hmax = in_range("max_step", max_step, 0.0, span, lo_open=True) if max_step is not None else span / 10
    max_points = integer("max_points", max_points, 2, 100_000)
    max_correction = in_range("max_correction", max_correction, 0.0, 1.0, lo_open=True)
    graze_tol = in_range("graze_tol", graze_tol, 0.0, 1.0)
    crest_tol = in_range("crest_tol", crest_tol, 0.0, 1.0)
    tol = in_range("tol", tol, 1e-14, 1e-3)
    rtol = in_range("rtol", rtol, 1e-14, 1e-6)
    locate_tol = in_range("locate_tol", locate_tol, 0.0, 1.0, lo_open=True, hi_open=True)
    progress = optional(function, "progress", progress)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    return _Options(parameter, lam0, stop, span, sign, h, hmin, hmax, max_points, max_correction, graze_tol,
                    crest_tol, tol, rtol, locate_tol, progress, wall)
