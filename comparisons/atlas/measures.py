"""The three sweep measures of an atlas, run at every (I, V) point by the sweep engine.

* ``atlas_exact`` — the exact attractor's observables (:func:`exact.attractor_observables`) and its class:
  ``period-n``, ``aperiodic``, ``too short`` (stick-slip), or the reason there is none: ``steady``,
  ``transient``, ``too few slips``, ``breakdown``, ``budget``.
* ``atlas_segments`` — each reduction's exact-seeded per-segment errors (:func:`comparisons.compare` on the last
  ``segments_per_branch`` complete stays of each branch of the same window): per reduction the median and worst
  ``|Δt|`` and ``|ΔF|`` relative errors, the stays compared and the reduced solves that broke down.
* ``atlas_approx`` — every approximation's prediction (:mod:`comparisons.atlas.approximations`) and
  :func:`peelapprox.estimate`'s regime label.

The exact window is one :func:`exact.window_run` (cached: the two exact measures of a point share it).  Every
status is a string and every number finite or None, never NaN: a breakdown is ``"breakdown:<reason>"``, a spent
step budget ``"budget:<name>"``, a prediction that raised ``"error: <Type>: <message>"``.  The options
(:data:`DEFAULTS`, every one written into the atlas's manifest) are checked by :func:`check_options` before the
first point.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from exact import MODELS, attractor_observables, window_run
from peelapprox import (
    ALPHA_MODELS,
    TIME_MAX,
    V_EQUATIONS,
    WINDOW_DEFAULTS,
    ModelBreakdown,
    PeelParams,
    SolverBudgetExceeded,
)
from peelapprox.io import fmt_number
from peelapprox.validate import duration, integer, state
from peelapprox.validate import rtol as _rtol

from .._compare import DEFAULT_MODELS, compare
from .._segments import segments
from .._worker import error_text
from ..sweep import register_measure
from .approximations import APPROXIMATIONS, OBSERVABLES, _estimate_of, predict
from .records import SEGMENT_STATS, SPREADS, schema

__all__ = ["MEASURE_NAMES", "DEFAULTS", "SPREADS", "SEGMENT_STATS", "reduction_key", "check_options",
           "measure_exact", "measure_segments", "measure_approx"]

#: The atlas's measures, in the order a point runs them (the exact one first: its status is the point's).
MEASURE_NAMES = ("atlas_exact", "atlas_segments", "atlas_approx")

#: The options of an atlas and their defaults.  The exact window: 100 s of transient, then the library's 20 s
#: measured (:data:`peelapprox.WINDOW_DEFAULTS`' rtol 1e-10 and α0 = 0).  Not the library's 30 s of transient:
#: at high inertia and high V the orbit drifts for ~100 s (V = 4, I = 1e-2 needs ~70 s from α0 = 0,
#: docs/dynamics.md), and over the 64 points of an 8 x 8 sample of the 40 x 40 grid the slip interval and force
#: drop after 30 s differ from those after 150 s (measured over 50 s) by over 10 % at 3 to 5 of the 63 stick-slip
#: points, after 100 s at one (docs/atlas.md, "The exact window"); 100 s costs 1.8 times the exact runs of 30 s
#: and keeps the 1600-point atlas within its 15 minutes on 2 cores.  ``segments_per_branch`` complete stays of
#: each branch (the last ones of the window) are compared, at the harness's ``segment_rtol``; ``reductions`` are
#: the harness's :data:`comparisons.DEFAULT_MODELS`.
DEFAULTS: dict[str, Any] = {
    "t_transient": 100.0,
    "t_window": WINDOW_DEFAULTS["window"],
    "rtol": WINDOW_DEFAULTS["rtol"],
    "alpha0": WINDOW_DEFAULTS["alpha0"],
    "segments_per_branch": 8,
    "segment_rtol": 1e-10,
    "reductions": {branch: [list(m) for m in models] for branch, models in DEFAULT_MODELS.items()},
}

#: The PeelParams fields of the models an atlas does not measure (those without the hybrid method:
#: ``Model.parameters``) and their defaults, which leave the paper's model.
_VARIANT_OPTIONS = {f.name: f.default for f in dataclasses.fields(PeelParams)
                    if any(f.name in dict(m.parameters) for m in MODELS.values() if not m.has_hybrid)}


def reduction_key(branch: str, alpha_model: str, v_equation: str) -> str:
    """The name of a reduction in an atlas: ``"AB_approxalpha_approxvdot"``."""
    return f"{branch}_{alpha_model}_{v_equation}"


def _window(options: Mapping) -> dict:
    """The checked window options (:func:`exact.attractor_observables`' names and validators)."""
    kw = {"t_transient": duration("t_transient", options.get("t_transient", DEFAULTS["t_transient"]), zero=True),
          "t_window": duration("t_window", options.get("t_window", DEFAULTS["t_window"])),
          "rtol": _rtol("rtol", options.get("rtol", DEFAULTS["rtol"])),
          "alpha0": state("alpha0", options.get("alpha0", DEFAULTS["alpha0"]), "alpha")}
    if kw["t_transient"] + kw["t_window"] > TIME_MAX:
        raise ValueError(f"t_transient + t_window must be at most {TIME_MAX:g} s, got {kw['t_transient']:g} + "
                         f"{kw['t_window']:g}")
    return kw


def _reductions(options: Mapping) -> dict[str, list[tuple[str, str]]]:
    """The checked ``reductions`` option: ``{"AB": [[alpha_model, v_equation], ...], "CD": [...]}``."""
    red = options.get("reductions", DEFAULTS["reductions"])
    if not isinstance(red, Mapping) or not set(red) <= {"AB", "CD"}:
        raise ValueError(f"reductions must map 'AB' and/or 'CD' to lists of [alpha_model, v_equation], got {red!r}")
    out: dict[str, list[tuple[str, str]]] = {}
    for branch, models in red.items():
        pairs = []
        for m in models if isinstance(models, (list, tuple)) else [None]:
            if not (isinstance(m, (list, tuple)) and len(m) == 2 and m[0] in ALPHA_MODELS and m[1] in V_EQUATIONS):
                raise ValueError(f"reductions[{branch!r}]: each entry must be [alpha_model, v_equation] with "
                                 f"alpha_model in {ALPHA_MODELS} and v_equation in {V_EQUATIONS}, got {m!r}")
            pairs.append((str(m[0]), str(m[1])))
        if len(set(pairs)) != len(pairs):
            raise ValueError(f"reductions[{branch!r}] must not repeat a reduction, got {models!r}")
        out[branch] = pairs
    return out


def _approximations(options: Mapping) -> dict[str, str]:
    """The checked ``approximations`` option: name -> how a worker finds it (``"registry"`` or an import
    reference)."""
    ap = options.get("approximations", {})
    if not isinstance(ap, Mapping) or not all(isinstance(k, str) and isinstance(v, str) for k, v in ap.items()):
        raise ValueError(f"approximations must map names to 'registry' or import references, got {ap!r}")
    unknown = [name for name, ref in ap.items() if ref == "registry" and name not in APPROXIMATIONS]
    if unknown:
        raise ValueError(f"approximations: unknown {unknown}; registered: {sorted(APPROXIMATIONS)}")
    return dict(ap)


def check_options(options: Mapping) -> None:
    """ValueError naming the first invalid atlas option (the sweep calls it before the first point).

    Also refuses a model variant (``tape_mass``, ``loading``, ...): the reduced equations and
    :func:`peelapprox.estimate` are the paper's massless model's under velocity control.
    """
    _window(options)
    if options.get("schema", schema()) != schema():
        raise ValueError(f"schema: the atlas's record schema {options.get('schema')!r} is not this version's "
                         f"{schema()!r}: run the atlas again into a new directory to regenerate it")
    integer("segments_per_branch", options.get("segments_per_branch", DEFAULTS["segments_per_branch"]), lo=0)
    _rtol("segment_rtol", options.get("segment_rtol", DEFAULTS["segment_rtol"]))
    _reductions(options)
    _approximations(options)
    variant = [k for k, default in _VARIANT_OPTIONS.items() if options.get(k) not in (None, default)]
    if variant:
        raise ValueError(f"options {variant}: an atlas measures the reduced equations of the paper's massless model "
                         "under velocity control, which a model variant does not have")


def _wall(options: Mapping) -> dict:
    """``{"max_wall": seconds}``, what is left of the sweep's budget (the same for every measure of a point)."""
    return {"max_wall": options["max_wall"]} if options.get("max_wall") is not None else {}


def _budget(exc: SolverBudgetExceeded) -> dict:
    """A spent step/point budget as a status; the sweep's own wall budget is re-raised (the point is then
    computed on resume)."""
    if exc.budget == "max_wall":
        raise exc
    return {"status": f"budget:{exc.budget}", "reason": " ".join(str(exc).split())[:300]}


def measure_exact(params: PeelParams, options: Mapping) -> dict:
    """Sweep measure ``atlas_exact``: the exact attractor's observables over the window (module docstring).

    ``status`` is ``"ok"`` for stick-slip, else the observables' status (``steady``, ``transient``, ``too few
    slips``), ``breakdown:<reason>`` or ``budget:<name>``; ``class`` is the return map's label on stick-slip
    (``period-n``, ``aperiodic``, ``too short``), else the status without its detail; ``reason`` says why;
    ``observables`` and ``spreads`` the values of :data:`~comparisons.atlas.approximations.OBSERVABLES` and
    :data:`SPREADS` (None where undefined; absent after a breakdown or a spent budget).
    """
    kw = _window(options)
    try:
        obs = attractor_observables(params, **kw, **_wall(options))
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}", "class": "breakdown", "t_breakdown": float(exc.t),
                "reason": f"the model breaks down at t = {fmt_number(exc.t, 4)} s ({exc.reason})"}
    except SolverBudgetExceeded as exc:
        return {**_budget(exc), "class": "budget"}
    rec: dict[str, Any] = {"status": "ok" if obs.is_stick_slip else obs.status,
                           "class": obs.period_label if obs.is_stick_slip else obs.status,
                           "reason": obs.reason, "period": obs.period, "n_slips": obs.n_slips,
                           "observables": [getattr(obs, name) for name in OBSERVABLES],
                           "spreads": [getattr(obs, name) for name in SPREADS]}
    return rec


def measure_segments(params: PeelParams, options: Mapping) -> dict:
    """Sweep measure ``atlas_segments``: each reduction on the window's last ``segments_per_branch`` complete
    stays of each branch, seeded from their exact entries (:func:`comparisons.compare`).

    ``stats``: per reduction (in the order of the option ``reductions``) the values of :data:`SEGMENT_STATS`:
    ``dt_median``, ``dt_worst``, ``dF_median``, ``dF_worst`` (of ``|approx - exact| / |exact|`` over its stays;
    None without a stay it solved), ``n`` (stays solved) and ``failed`` (stays whose reduced solve broke down or did
    not reach the fold); ``n_AB``, ``n_CD`` the stays compared.  ``status`` as ``atlas_exact``'s for a breakdown
    or a spent budget, else ok.
    """
    kw = _window(options)
    n = integer("segments_per_branch", options.get("segments_per_branch", DEFAULTS["segments_per_branch"]), lo=0)
    models = _reductions(options)
    try:  # the very run of atlas_exact (window_run's cache: the same arguments)
        tr = window_run(params, t_transient=kw["t_transient"], window=kw["t_window"], rtol=kw["rtol"],
                        alpha0=kw["alpha0"], **_wall(options))
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}"}
    except SolverBudgetExceeded as exc:
        return {"status": _budget(exc)["status"]}
    segs = segments(tr, last=2 * n) if n else []  # the last n of each branch: the branches alternate
    chosen = {b: [s for s in segs if s.branch == b][-n:] if n else [] for b in ("AB", "CD")}
    rows = compare(tr, models, segs=chosen["AB"] + chosen["CD"],
                   rtol=_rtol("segment_rtol", options.get("segment_rtol", DEFAULTS["segment_rtol"])), periods=False)
    stats = []
    for branch, pairs in models.items():
        for am, ve in pairs:
            mine = [r for r in rows if r.branch == branch and r.alpha_model == am and r.v_equation == ve]
            ok = [r for r in mine if r.status == "ok"]
            row: list[float | int | None] = []
            for attr in ("dt_rel_error", "dF_rel_error"):
                errs = np.array([abs(getattr(r, attr)) for r in ok if getattr(r, attr) is not None])
                row += [float(np.median(errs)), float(errs.max())] if errs.size else [None, None]
            stats.append([*row, len(ok), len(mine) - len(ok)])
    return {"status": "ok", "n_AB": len(chosen["AB"]), "n_CD": len(chosen["CD"]), "stats": stats}


def measure_approx(params: PeelParams, options: Mapping) -> dict:
    """Sweep measure ``atlas_approx``: every approximation of the option ``approximations`` at this point, and
    :func:`peelapprox.estimate`'s ``regime`` label.

    One value per approximation (in the option's order): ``prediction_status`` (its own, ``breakdown:<reason>``,
    or ``error: <Type>: <message>`` when it raised), ``prediction_reason``, ``prediction_period``, and
    ``predicted``, its values of :data:`~comparisons.atlas.approximations.OBSERVABLES`.  ``status`` is ok:
    a prediction that fails is a result of the atlas, not a failure of the point.
    """
    rec: dict[str, Any] = {"status": "ok"}
    try:
        rec["regime"] = _estimate_of(params).label
    except Exception as exc:
        rec["regime"] = error_text(exc, 200)
    ds = []
    for name, ref in _approximations(options).items():
        try:
            d = predict(name, params, ref)
        except ModelBreakdown as exc:
            d = {"status": f"breakdown:{exc.reason}", "reason": f"the reduced map breaks down ({exc.reason})"}
        except Exception as exc:
            d = {"status": error_text(exc, 300), "reason": "the approximation raised"}
        ds.append(d)
    rec.update(prediction_status=[d["status"] for d in ds], prediction_reason=[d["reason"] for d in ds],
               prediction_period=[d.get("period") for d in ds],
               predicted=[[d.get(field) for field in OBSERVABLES] for d in ds])
    return rec


register_measure("atlas_exact", measure_exact, check_options=check_options)
register_measure("atlas_segments", measure_segments, check_options=check_options)
register_measure("atlas_approx", measure_approx, check_options=check_options)
