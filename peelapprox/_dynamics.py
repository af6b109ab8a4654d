"""The sweep measures ``period`` and ``lyapunov`` and their option checks (registered with the sweep).

Temporary home (issue 14): the return-map analysis moved to :mod:`peelapprox._returnmap` and the functions
that run the exact solver to :mod:`exact` (``exact._attractors``, ``exact._lyapunov``); these measures move
with the sweep engine to ``comparisons``.  They import ``exact`` lazily, inside their bodies.

For ``peelapprox._sweep`` (not yet moved), which imports the dynamics from here, ``force_drops`` and
``return_map`` are imported here and ``window_run``, now in :mod:`exact`, still resolves here lazily (module
``__getattr__``).
"""

from __future__ import annotations

import math

from ._params import LYAPUNOV_TAU, RTOL_RANGE, T_TRANSIENT, TIME_MAX, WINDOW_DEFAULTS, PeelParams
from ._returnmap import classify, force_drops, return_map  # noqa: F401  (the last two: imported by _sweep)
from ._sweep import register_measure
from ._validate import duration, in_range, positive, state

__all__ = ["measure_period", "measure_lyapunov"]


def __getattr__(name: str):
    if name == "window_run":
        import exact

        return exact.window_run
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _rtol(name: str, x) -> float:
    return in_range(name, x, *RTOL_RANGE)


def _window_options(options) -> dict:
    """The :func:`exact.window_run` arguments from sweep options (``t_end`` = t_transient + window also accepted),
    checked by the same validators as :func:`exact.window_run` (ValueError/TypeError naming the option and its valid
    range; the sweep calls this before the first point)."""
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
    1e6 s) and ``alpha0`` (0), with :func:`exact.lyapunov`'s validators."""
    return {"t_transient": duration("t_transient", options.get("t_transient", T_TRANSIENT), zero=True),
            "lyapunov_time": in_range("lyapunov_time", options.get("lyapunov_time", 50.0), 2 * LYAPUNOV_TAU,
                                      TIME_MAX),
            "alpha0": state("alpha0", options.get("alpha0", 0.0), "alpha")}


def measure_period(params: PeelParams, options) -> dict:
    """Sweep measure ``period``: the return map's period over the window of :func:`exact.window_run` (options
    ``t_transient`` = 30 s, ``t_end`` = t_transient + 20 s, ``rtol`` = 1e-10, ``alpha0`` = 0,
    ``period_rtol`` = 1e-6).  ``period`` is None when aperiodic (no n <= 32 repeats), too short or without
    stick-slip; a ``ModelBreakdown`` is ``status = "breakdown:<reason>"``."""
    from exact import ModelBreakdown, window_run

    kw = _period_options(options)
    period_rtol = kw.pop("period_rtol")
    try:
        tr = window_run(params, **kw)
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}"}
    p = classify(tr, period_rtol=period_rtol)
    return {"status": "ok", "label": p.label, "period": p.period,
            "mismatch": p.mismatch if math.isfinite(p.mismatch) else None, "n_returns": p.n_returns}


def measure_lyapunov(params: PeelParams, options) -> dict:
    """Sweep measure ``lyapunov``: :func:`exact.lyapunov` with its defaults, except options ``t_transient`` (30 s)
    and ``lyapunov_time`` (50 s of renormalisation intervals of 0.005 s)."""
    from exact import ModelBreakdown, lyapunov

    tau = LYAPUNOV_TAU
    kw = _lyapunov_options(options)
    try:
        r = lyapunov(params, t_transient=kw["t_transient"], tau=tau, n=max(2, int(kw["lyapunov_time"] / tau)),
                     alpha0=kw["alpha0"])
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}"}
    return {"status": "ok", "bits_per_s": r.bits_per_s, "stderr_bits": r.stderr_bits, "n_jumps": r.n_jumps}


register_measure("period", measure_period, check_options=_period_options)
register_measure("lyapunov", measure_lyapunov, check_options=_lyapunov_options)
