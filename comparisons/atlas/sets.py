"""The atlas over attractor sets (opt-in: ``atlas(..., sets=True)``, ``peelapprox atlas --sets``).

The sweep measure ``atlas_sets`` runs at each point :func:`exact.attractor_set` (the atlas's window, every start
of its default design, in the worker) and :func:`peelapprox.approximate_attractor` (its defaults), and records:

* the *exact set*: the attractors reached from at least ``set_min_share`` (10 %) of the starts, their number
  (``n_attractors``: multistability; ``n_stick_slip`` of them stick-slip) and labels;
* the *predicted set*: the primary prediction's status, period, ``confidence`` and its reason, and the number of
  predictions of the set (``n_predicted``: the primary and its alternatives);
* ``set_match``: the primary matches ANY stick-slip attractor of the exact set (:func:`match_set`: slip interval
  and force drop both within :data:`~comparisons.atlas.approximations.TOLERANCE` of the attractor's,
  ``|predicted - exact| / |exact|``), and ``strict_match``: the same against the attractor of the set's first
  start (the solver's default start, the one :func:`exact.attractor_observables` runs from);
* where the primary and the matched attractor are both periodic and both have multipliers (the exact ones only
  with ``set_stability``): their largest ``|μ|`` and the difference.

A point where no start stick-slips has ``set_match`` None; the rates of :func:`set_summary` count a
non-stick-slip or failed prediction at a stick-slip point as a miss.  The record's own ``status`` is ``ok`` (the
point's status stays the exact measure's); ``set_status`` is :attr:`exact.AttractorSet.status`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from exact import attractor_set
from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded, approximate_attractor
from peelapprox.validate import flag, in_range

from .._worker import error_text
from ..sweep import register_measure
from .approximations import TOLERANCE, last_output
from .measures import _wall, _window

__all__ = ["SET_DEFAULTS", "SET_MEASURE", "MATCHED", "match_set", "measure_sets", "check_set_options",
           "set_summary"]

#: The measure's name (added to the atlas's measures only with ``sets=True``).
SET_MEASURE = "atlas_sets"
#: The options of the set measure and their defaults (written into the manifest only with ``sets=True``, so an
#: atlas without sets keeps the options, and the manifest, it had).  ``set_min_share``: an attractor counts when
#: reached from at least this share of the starts; ``set_stability``: compute the exact multipliers and
#: exponents (:func:`exact.attractor_set`'s ``stability``; about twice the cost).
SET_DEFAULTS: dict[str, Any] = {"set_min_share": 0.1, "set_stability": False}
#: The observables a match compares (both within :data:`TOLERANCE`).
MATCHED = ("slip_interval", "force_drop")


def _get(obs: Any, name: str) -> float | None:
    v = obs.get(name) if isinstance(obs, Mapping) else getattr(obs, name, None)
    return None if v is None else float(v)


def match_set(predicted: Any, exact: Sequence[Any], *, tol: float = TOLERANCE,
              fields: tuple[str, ...] = MATCHED) -> tuple[int | None, float | None]:
    """The exact attractor ``predicted`` matches: ``(index, distance)``.

    ``distance`` to attractor ``k`` is ``max |predicted - exact_k| / |exact_k|`` over ``fields`` (the atlas's
    relative error, the exact value the reference); the nearest attractor with every field defined and nonzero
    is taken.  ``index`` is its index in ``exact`` when ``distance <= tol``, else None; ``(None, None)`` when no
    attractor (or ``predicted``) defines the fields.

    Parameters
    ----------
    predicted : StickSlipObservables or mapping
        Anything with the ``fields`` as attributes or keys.
    exact : sequence
        The exact attractors' observables (the same kinds of objects).
    tol : float
        In [0, 10] (0.10).
    """
    tol = in_range("tol", tol, 0.0, 10.0)
    mine = [_get(predicted, f) for f in fields]
    if any(v is None for v in mine):
        return None, None
    best: tuple[int, float] | None = None
    for k, obs in enumerate(exact):
        theirs = [_get(obs, f) for f in fields]
        if any(v is None or v == 0 for v in theirs):
            continue
        d = max(abs(a - e) / abs(e) for a, e in zip(mine, theirs, strict=True))  # type: ignore[operator, arg-type]
        if best is None or d < best[1]:
            best = (k, d)
    if best is None:
        return None, None
    return (best[0] if best[1] <= tol else None), best[1]


def check_set_options(options: Mapping) -> None:
    """ValueError naming an invalid set option (``set_min_share`` in [0, 1], ``set_stability`` a bool)."""
    in_range("set_min_share", options.get("set_min_share", SET_DEFAULTS["set_min_share"]), 0.0, 1.0)
    flag("set_stability", options.get("set_stability", SET_DEFAULTS["set_stability"]))


def _max_mu(mult: Any) -> float | None:
    return None if not mult else float(max(abs(m) for m in mult))


def _predicted(params: PeelParams) -> tuple[Any, dict]:
    """The primary prediction (None where it raised) and its record fields: the atlas's ``approx:default``
    prediction of this point when it ran (:func:`~comparisons.atlas.approximations.last_output`), else computed."""
    try:
        a = last_output("approx:default", params, approximate_attractor)
        if a is None:
            a = approximate_attractor(params, warn=False)
    except ModelBreakdown as exc:
        return None, {"predicted_status": f"breakdown:{exc.reason}", "confidence": "low",
                      "confidence_reason": "the reduced map breaks down", "n_predicted": 0}
    except Exception as exc:
        return None, {"predicted_status": error_text(exc, 300), "confidence": "low",
                      "confidence_reason": "the approximation raised", "n_predicted": 0}
    return a, {"predicted_status": a.status, "predicted_period": a.period, "confidence": a.confidence,
               "confidence_reason": a.confidence_reason[:300], "n_predicted": len(a.set),
               "predicted_slip_interval": a.slip_interval, "predicted_force_drop": a.force_drop,
               "predicted_max_multiplier": _max_mu(a.multipliers)}


def measure_sets(params: PeelParams, options: Mapping) -> dict:
    """Sweep measure ``atlas_sets``: the exact attractor set and the predicted set at this point, and whether
    the primary prediction matches an attractor of the set and the default start's (module docstring)."""
    kw = _window(options)
    min_share = in_range("set_min_share", options.get("set_min_share", SET_DEFAULTS["set_min_share"]), 0.0, 1.0)
    stability = flag("set_stability", options.get("set_stability", SET_DEFAULTS["set_stability"]))
    a, rec = _predicted(params)
    rec["status"] = "ok"
    try:
        s = attractor_set(params, t_transient=kw["t_transient"], t_window=kw["t_window"], rtol=kw["rtol"],
                          stability=stability, workers=0, **_wall(options))
    except SolverBudgetExceeded as exc:
        if exc.budget == "max_wall":
            raise
        return {**rec, "set_status": f"budget:{exc.budget}"}
    if s.status == "max_wall" and options.get("max_wall") is not None:  # the sweep's budget: computed on resume
        raise SolverBudgetExceeded("the sweep's max_wall ran out inside attractor_set", budget="max_wall",
                                   limit=float(options["max_wall"]), t=0.0, state={})
    counted = [x for x in s.attractors if x.share >= min_share and x.kind != "breakdown"]
    ss = [x for x in counted if x.is_stick_slip]
    primary = s.primary
    rec.update({"set_status": s.status, "n_attractors": len(counted), "n_stick_slip": len(ss),
                "labels": "; ".join(f"{x.label} {x.share:.2f}" for x in counted),
                "primary_class": None if primary is None else primary.label,
                "primary_share": None if primary is None else primary.share, "set_wall": s.wall_time})
    stick_slip = a is not None and a.is_stick_slip
    k, d = match_set(a, [x.observables for x in ss]) if stick_slip and ss else (None, None)
    rec.update({"set_match": None if not ss else k is not None, "set_distance": d,
                "matched_label": None if k is None else ss[k].label,
                "matched_share": None if k is None else ss[k].share})
    strict = primary is not None and primary.is_stick_slip
    ks, ds = match_set(a, [primary.observables]) if stick_slip and strict else (None, None)  # type: ignore[union-attr]
    rec.update({"default_stick_slip": strict, "strict_match": None if not strict else ks is not None,
                "strict_distance": ds})
    if k is not None and a is not None and a.multipliers and ss[k].multipliers:
        mp, me = _max_mu(a.multipliers), _max_mu(ss[k].multipliers)
        rec.update({"exact_max_multiplier": me, "multiplier_error": abs(mp - me)})  # type: ignore[operator]
    return rec


def set_summary(rows: Sequence[Mapping[str, Any]]) -> list[dict]:
    """The set rates from per-point set records (``set_match``, ``strict_match``, ``confidence``,
    ``default_stick_slip``): one row each, in the shape of :meth:`AtlasResult.summary`'s rows
    (``approximation`` ``"sets:approx:default"``, ``observable`` the rate, ``stick_slip`` its denominator,
    ``within`` its numerator, ``fraction``; ``compared`` the points with a prediction compared).

    * ``set_match``: of the points whose exact set has a stick-slip attractor, those whose primary matches one;
    * ``strict_match``: of the points whose default start stick-slips, those whose primary matches its attractor;
    * ``unflagged_match``: of the set's stick-slip points with confidence high, those matching the set;
    * ``unflagged_share``: of the set's stick-slip points, those with confidence high.
    """
    sets = [r for r in rows if r.get("set_match") is not None]
    strict = [r for r in rows if r.get("default_stick_slip")]
    high = [r for r in sets if r.get("confidence") == "high"]

    def row(name: str, of: list, hit: int) -> dict:
        return {"approximation": "sets:approx:default", "observable": name, "stick_slip": len(of),
                "compared": sum(1 for r in of if r.get("set_distance") is not None or name == "unflagged_share"),
                "within": hit, "fraction": hit / len(of) if of else None, "median_error": None, "worst_error": None}

    return [row("set_match", sets, sum(1 for r in sets if r["set_match"])),
            row("strict_match", strict, sum(1 for r in strict if r.get("strict_match"))),
            row("unflagged_match", high, sum(1 for r in high if r["set_match"])),
            row("unflagged_share", sets, len(high))]


register_measure(SET_MEASURE, measure_sets, check_options=check_set_options)
