"""The records of an atlas read as maps and tables: :class:`AtlasResult` and :func:`load_atlas` (read-only).

The relative error of an approximation's observable is computed here, from the records, and nowhere else:
``(predicted - exact) / |exact|`` where the exact attractor stick-slips (``atlas_exact_status == "ok"``), the
approximation predicts stick-slip and both values exist; elsewhere it is undefined and
:meth:`AtlasResult.undefined` says why.  Maps are :class:`numpy.ma.MaskedArray` (masked where undefined, the
data under the mask 0): no NaN anywhere.
"""

from __future__ import annotations

import json
import os
from typing import Any

import numpy as np

from peelapprox.io import fmt_number, html_table, jsonable, optional_import, write_rows

from ..sweep import SweepResult, load_sweep, record_key
from ..sweep.store import failed
from .approximations import OBSERVABLES, TOLERANCE, UNITS
from .measures import MEASURE_NAMES, reduction_key
from .records import NOT_COMPUTED, SEGMENT_STATS, SPREADS, AtlasArrays, grid_index, is_none, upgrade
from .sets import SET_MEASURE, set_summary

__all__ = ["AtlasResult", "load_atlas", "TABLES", "SET_FIELDS"]

#: The tables of an atlas (:meth:`AtlasResult.tables`), each written as ``atlas_<name>.csv`` / ``.json``; an atlas
#: with sets (``atlas(..., sets=True)``) also has ``sets`` (:meth:`AtlasResult.set_rows`) and ``set_summary``.
TABLES = ("points", "errors", "segments", "summary", "regimes")
#: The fields of a set record (:mod:`comparisons.atlas.sets`) in :meth:`AtlasResult.set_rows`, in order.
SET_FIELDS = ("set_status", "n_attractors", "n_stick_slip", "labels", "primary_class", "primary_share",
              "predicted_status", "predicted_period", "confidence", "confidence_reason", "n_predicted",
              "predicted_slip_interval", "predicted_force_drop", "set_match", "set_distance", "matched_label",
              "matched_share", "default_stick_slip", "strict_match", "strict_distance", "predicted_max_multiplier",
              "exact_max_multiplier", "multiplier_error", "set_wall")

_NOT_COMPUTED = NOT_COMPUTED


def _exact_key(field: str) -> str:
    return record_key("atlas_exact", field)


def _approx_key(field: str) -> str:
    return record_key("atlas_approx", field)


def _set_key(field: str) -> str:
    return record_key(SET_MEASURE, field)


def _number(v: Any) -> float | None:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def _slice(rec: dict, key: str, n: int) -> list:
    """The record's list under ``key``, n Nones where it has none."""
    vals = rec.get(key)
    return [None] * n if vals is None else list(vals)


class AtlasResult:
    """An atlas's records on its (I, V) grid: the exact dynamics, the predictions, their relative errors and
    the reductions' per-segment errors, as maps (arrays ``[i, j]`` for ``I_values[i], V_values[j]``), tables,
    an xarray Dataset and figures.

    Attributes
    ----------
    sweep : comparisons.sweep.SweepResult
        The records themselves (the atlas's directory is a sweep directory).
    records : list of dict
        Its records in this version's format (:mod:`comparisons.atlas.records`; an atlas of the first format is
        read through :func:`~comparisons.atlas.records.upgrade`), grid order.
    arrays : comparisons.atlas.records.AtlasArrays
        Every map, built once from the records: the exact observables ``[i, j, observable]``, the predictions
        ``[approximation, i, j, observable]``, the segment statistics ``[reduction, i, j, stat]``, the statuses.
    I_values, V_values : ndarray
        The grid.
    approximations : tuple of str
        The approximations measured (names of :data:`~comparisons.atlas.approximations.APPROXIMATIONS`).
    skipped : dict
        Registered approximations that were not importable when the atlas started -> why.
    observables : tuple of str
        :data:`~comparisons.atlas.approximations.OBSERVABLES`.
    reductions : tuple of str
        The reductions compared per segment, ``"<branch>_<alpha_model>_<v_equation>"``.
    options : dict
        The atlas's options (window, segments, reductions, approximations, model fields).
    out : str or None
        Its directory.
    """

    def __init__(self, sweep: SweepResult):
        missing = [m for m in MEASURE_NAMES if m not in sweep.measures]
        if missing:
            raise ValueError(f"not an atlas: the sweep in {sweep.out!r} lacks the measures {missing} "
                             f"(it has {list(sweep.measures)})")
        self.sweep = sweep
        self.I_values, self.V_values = sweep.I_values, sweep.V_values
        self.options = dict(sweep.options)
        self.approximations = tuple(self.options.get("approximations", {}))
        self.skipped = dict(self.options.get("skipped_approximations", {}))
        self.observables = OBSERVABLES
        self.reductions = tuple(reduction_key(b, am, ve) for b, pairs in self.options.get("reductions", {}).items()
                                for am, ve in pairs)
        self.out = sweep.out
        self.force = sweep.force
        #: The atlas compares attractor sets (``atlas(..., sets=True)``; :mod:`comparisons.atlas.sets`).
        self.has_sets = SET_MEASURE in sweep.measures
        written = self.options.get("schema")
        self.records = [upgrade(rec, self.approximations, self.reductions, written) for rec in sweep.records]
        self._ij = grid_index(self.records, self.I_values, self.V_values)
        self.arrays = AtlasArrays(self.records, self._ij, self.shape, len(self.approximations), len(self.reductions))

    # ------------------------------------------------------------------------------------------ the grid
    @property
    def shape(self) -> tuple[int, int]:
        """``(len(I_values), len(V_values))``."""
        return (self.I_values.size, self.V_values.size)

    @property
    def complete(self) -> bool:
        """Every grid point has a record."""
        return self.sweep.complete

    def missing(self) -> list[tuple[float, ...]]:
        """(I, V) of the points not computed yet."""
        return self.sweep.missing()

    def failed(self) -> list[tuple[float, ...]]:
        """(I, V) of the points where a measure raised (``status`` ``"error: ..."``)."""
        return self.sweep.failed()

    def _grid(self, fn) -> np.ndarray:
        """An object array of ``fn(record or None)`` over the grid (one pass over the records)."""
        return self.arrays.grid(self.records, fn)

    def _masked(self, fn) -> np.ma.MaskedArray:
        """A masked float array of ``fn(record or None)`` (masked where it is None; 0 under the mask)."""
        vals = self._grid(fn)
        mask = is_none(vals)
        data = np.where(mask, 0.0, vals).astype(float)
        return np.ma.MaskedArray(data, mask=mask)

    # ------------------------------------------------------------------------------------------ the exact side
    def exact_class(self) -> np.ndarray:
        """The exact dynamics at each point (str): ``period-n``, ``aperiodic``, ``too short`` where it
        stick-slips; else ``steady``, ``transient``, ``too few slips``, ``breakdown``, ``budget``; ``failed``
        where a measure raised, ``not computed`` where the point is still to run."""
        a = self.arrays
        fallback = np.where(a.failed, "failed", a.status).astype(object)
        cls = np.where(is_none(a.exact_class) | (a.exact_class == ""), fallback, a.exact_class)
        return np.where(a.computed, cls, _NOT_COMPUTED).astype(object)

    def status(self) -> np.ndarray:
        """Each point's status (``ok`` where the exact attractor stick-slips; ``not computed`` if not run)."""
        return np.where(self.arrays.computed, self.arrays.status, _NOT_COMPUTED).astype(object)

    def stick_slip(self) -> np.ndarray:
        """Boolean map: the exact attractor stick-slips (``status == "ok"``)."""
        return self.status() == "ok"

    def regime(self) -> np.ndarray:
        """:func:`peelapprox.estimate`'s regime label at each point (``not computed`` where the point is still
        to run, ``failed`` where its record has none)."""
        return np.where(self.arrays.computed, self.arrays.regime, _NOT_COMPUTED).astype(object)

    def exact(self, observable: str) -> np.ma.MaskedArray:
        """An exact observable (or its spread, ``<observable>_spread``, or ``period``), masked where the
        record has none."""
        self._check_observable(observable, (*OBSERVABLES, *SPREADS, "period", "n_slips"))
        a = self.arrays
        if observable in ("period", "n_slips"):
            return getattr(a, observable).copy()
        if observable in SPREADS:
            return a.spreads[..., SPREADS.index(observable)].copy()
        return a.exact[..., OBSERVABLES.index(observable)].copy()

    # ------------------------------------------------------------------------------------------ predictions
    def _check_name(self, name: str) -> int:
        if name not in self.approximations:
            raise ValueError(f"approximation {name!r} is not in this atlas; it has {list(self.approximations)}"
                             + (f" (skipped: {self.skipped})" if self.skipped else ""))
        return self.approximations.index(name)

    @staticmethod
    def _check_observable(observable: str, known=OBSERVABLES) -> None:
        if observable not in known:
            raise ValueError(f"observable must be one of {list(known)}, got {observable!r}")

    def prediction(self, name: str, observable: str) -> np.ma.MaskedArray:
        """Approximation ``name``'s prediction of ``observable`` (or ``period``), masked where it has none."""
        a = self._check_name(name)
        self._check_observable(observable, (*OBSERVABLES, "period"))
        if observable == "period":
            return self.arrays.prediction_period[a].copy()
        return self.arrays.predicted[a, ..., OBSERVABLES.index(observable)].copy()

    def prediction_status(self, name: str) -> np.ndarray:
        """Approximation ``name``'s status at each point (``stick-slip``, ``steady``, ``breakdown:...``,
        ``error: ...``; ``not computed``)."""
        st = self.arrays.prediction_status[self._check_name(name)]
        return np.where(self.arrays.computed, np.where(is_none(st), "failed", st), _NOT_COMPUTED).astype(object)

    def undefined(self, name: str, observable: str) -> np.ndarray:
        """Why the relative error of ``name``'s ``observable`` is undefined at each point ("" where defined):
        ``not computed``, ``failed: ...``, ``exact: <class>`` (no stick-slip there), ``predicted: <status>``
        (the approximation predicts none, or failed), ``no exact value``, ``not predicted``."""
        a = self._check_name(name)
        self._check_observable(observable)
        return self.arrays.undefined(a, OBSERVABLES.index(observable))

    def relative_error(self, name: str, observable: str, *, signed: bool = False) -> np.ma.MaskedArray:
        """``|predicted - exact| / |exact|`` of ``name``'s ``observable`` (``signed``: without the outer
        absolute value), masked where undefined (:meth:`undefined` says why)."""
        a = self._check_name(name)
        self._check_observable(observable)
        return self.arrays.relative_error(a, OBSERVABLES.index(observable), signed)

    def segment_error(self, reduction: str, stat: str = "dt_median") -> np.ma.MaskedArray:
        """A reduction's per-point summary of its per-segment relative errors: ``stat`` one of ``dt_median``,
        ``dt_worst``, ``dF_median``, ``dF_worst`` (or the counts ``n``, ``failed``), masked where the point has
        none (no stick-slip, no stay solved)."""
        if reduction not in self.reductions:
            raise ValueError(f"reduction must be one of {list(self.reductions)}, got {reduction!r}")
        self._check_observable(stat, SEGMENT_STATS)
        return self.arrays.segment_stats[self.reductions.index(reduction), ..., SEGMENT_STATS.index(stat)].copy()

    # ------------------------------------------------------------------------------------------ summaries
    def _error_map(self, name: str, observable: str) -> np.ma.MaskedArray:
        """The relative errors :meth:`within` counts: approximation ``name``'s (:meth:`relative_error`), or for
        ``name = "segments:<reduction>"`` its :meth:`segment_error` ``observable`` at the exact stick-slip points."""
        reduction = name[len("segments:"):] if name.startswith("segments:") else None
        if name not in self.approximations and reduction in self.reductions:
            m = self.segment_error(reduction, observable)
            return np.ma.MaskedArray(m.data, mask=np.ma.getmaskarray(m) | ~self.stick_slip())
        return self.relative_error(name, observable)

    def within(self, name: str, observable: str, tol: float = TOLERANCE) -> dict:
        """How often ``name`` predicts ``observable`` within ``tol``: over the exact stick-slip points, the
        number ``stick_slip``, ``compared`` (error defined), ``within`` (error <= tol), ``fraction`` (within /
        stick_slip; None without stick-slip points), ``median_error`` and ``worst_error`` (None if none).
        ``name`` is an approximation, or ``"segments:<reduction>"`` with ``observable`` a stat of
        :meth:`segment_error` (its per-point errors at the exact stick-slip points)."""
        vals = self._error_map(name, observable).compressed()
        n_ss = int(self.stick_slip().sum())
        n_in = int((vals <= tol).sum())
        return {"approximation": name, "observable": observable, "stick_slip": n_ss, "compared": int(vals.size),
                "within": n_in, "fraction": n_in / n_ss if n_ss else None,
                "median_error": float(np.median(vals)) if vals.size else None,
                "worst_error": float(vals.max()) if vals.size else None}

    def summary(self, tol: float = TOLERANCE) -> list[dict]:
        """:meth:`within` for every approximation and observable, then for every reduction the same of its
        per-point median ``|Δt|`` and ``|ΔF|`` errors (``approximation`` = ``segments:<reduction>``,
        ``observable`` = ``dt_median`` / ``dF_median``); with sets, then the rows of :meth:`set_summary`."""
        rows = [self.within(n, o, tol) for n in self.approximations for o in OBSERVABLES]
        rows += [self.within(f"segments:{red}", stat, tol) for red in self.reductions
                 for stat in ("dt_median", "dF_median")]
        if self.has_sets:
            rows += self.set_summary()
        return rows

    def by_regime(self, tol: float = TOLERANCE) -> list[dict]:
        """:meth:`within` per regime label of :func:`peelapprox.estimate`: for every approximation, label and
        observable (and ``"slip_interval+force_drop"``, both within at once), the exact stick-slip points with
        that label (``stick_slip``), how many of them have a defined error (``compared``), how many are within
        ``tol`` (``within``) and the ``fraction`` within (of ``stick_slip``): what ``estimate(p).validity``
        quotes."""
        regimes, ss = self.regime(), self.stick_slip()
        rows = []
        for name in self.approximations:
            ok = {o: self.relative_error(name, o).filled(np.inf) <= tol for o in OBSERVABLES}
            defined = {o: ~np.ma.getmaskarray(self.relative_error(name, o)) for o in OBSERVABLES}
            ok["slip_interval+force_drop"] = ok["slip_interval"] & ok["force_drop"]
            defined["slip_interval+force_drop"] = defined["slip_interval"] & defined["force_drop"]
            for label in sorted({str(x) for x in regimes[ss]}):
                sel = ss & (regimes == label)
                n = int(sel.sum())
                for obs in (*OBSERVABLES, "slip_interval+force_drop"):
                    n_in = int((ok[obs] & sel).sum())
                    rows.append({"approximation": name, "regime": label, "observable": obs, "stick_slip": n,
                                 "compared": int((defined[obs] & sel).sum()), "within": n_in,
                                 "fraction": n_in / n if n else None})
        return rows

    # ------------------------------------------------------------------------------------------ sets
    def _check_sets(self) -> None:
        if not self.has_sets:
            raise ValueError("this atlas has no attractor sets: run it with sets=True (peelapprox atlas --sets)")

    def multistability(self) -> np.ma.MaskedArray:
        """The number of exact attractors reached from at least ``set_min_share`` of the starts (breakdowns not
        counted) at each point, masked where the point has no set record."""
        self._check_sets()
        return self._masked(lambda rec: None if rec is None else _number(rec.get(_set_key("n_attractors"))))

    def confidence(self) -> np.ndarray:
        """The primary prediction's confidence at each point: ``high``, ``low``, or ``not computed`` / ``failed``
        where the point has no set record."""
        self._check_sets()
        return self._grid(lambda rec: _NOT_COMPUTED if rec is None else rec.get(_set_key("confidence"), "failed"))

    def set_rows(self) -> list[dict]:
        """One row per computed point: I, V, the exact class and the set record's :data:`SET_FIELDS` (None where
        absent)."""
        self._check_sets()
        return [{"I": rec["I"], "V": rec["V"], "exact_class": rec.get(_exact_key("class")),
                 **{f: rec.get(_set_key(f)) for f in SET_FIELDS}} for rec in self.records]

    def set_summary(self) -> list[dict]:
        """:func:`comparisons.atlas.sets.set_summary` of :meth:`set_rows`: the set-match rate, the strict rate,
        the rate among unflagged (confidence high) predictions and the share unflagged."""
        return set_summary(self.set_rows())

    # ------------------------------------------------------------------------------------------ tables
    def point_rows(self) -> list[dict]:
        """One row per computed point: I, V, status, the exact class, reason, period and observables, the
        regime label, each approximation's status."""
        rows = []
        for rec in self.records:
            row: dict[str, Any] = {"I": rec["I"], "V": rec["V"], "status": rec["status"],
                                   "exact_class": rec.get(_exact_key("class"), "failed" if failed(rec) else ""),
                                   "exact_reason": rec.get(_exact_key("reason")),
                                   "regime": rec.get(_approx_key("regime"))}
            row.update({f"exact_{f}": rec.get(_exact_key(f)) for f in ("period", "n_slips")})
            row.update({f"exact_{f}": v for f, v in zip(OBSERVABLES, _slice(rec, _exact_key("observables"),
                                                                             len(OBSERVABLES)))})
            row.update({f"{name}_status": v for name, v in zip(self.approximations, _slice(
                rec, _approx_key("prediction_status"), len(self.approximations)))})
            rows.append(row)
        return rows

    def error_rows(self) -> list[dict]:
        """One row per computed point, approximation and observable: exact and predicted values, the signed
        relative error (None where undefined) and why it is undefined ("" where defined)."""
        why = {(n, o): self.undefined(n, o) for n in self.approximations for o in OBSERVABLES}
        err = {(n, o): self.relative_error(n, o, signed=True) for n in self.approximations for o in OBSERVABLES}
        rows = []
        for rec, ij in zip(self.records, self._ij):
            exact = _slice(rec, _exact_key("observables"), len(OBSERVABLES))
            predicted = _slice(rec, _approx_key("predicted"), len(self.approximations))
            for name, values in zip(self.approximations, predicted):
                for k, obs in enumerate(OBSERVABLES):
                    e, a = _number(exact[k]), _number(None if values is None else values[k])
                    w = why[name, obs][ij]
                    rows.append({"I": rec["I"], "V": rec["V"], "approximation": name, "observable": obs,
                                 "unit": UNITS[obs], "exact": e, "predicted": a,
                                 "rel_error": None if w else float(err[name, obs][ij]), "undefined": w})
        return rows

    def segment_rows(self) -> list[dict]:
        """One row per computed point and reduction: the stays solved and failed, median and worst |Δt| and
        |ΔF| relative errors (None where the point has none)."""
        return [{"I": rec["I"], "V": rec["V"], "reduction": red, "exact_class": rec.get(_exact_key("class")),
                 **dict(zip(SEGMENT_STATS, stats or [None] * len(SEGMENT_STATS)))}
                for rec in self.records
                for red, stats in zip(self.reductions, _slice(rec, record_key("atlas_segments", "stats"),
                                                              len(self.reductions)))]

    def tables(self) -> dict[str, list[dict]]:
        """Every table of the atlas by name (:data:`TABLES`): ``points``, ``errors``, ``segments``,
        ``summary``, ``regimes`` (:meth:`by_regime`); with sets also ``sets`` and ``set_summary``."""
        tables = {"points": self.point_rows(), "errors": self.error_rows(), "segments": self.segment_rows(),
                  "summary": self.summary(), "regimes": self.by_regime()}
        if self.has_sets:
            tables.update(sets=self.set_rows(), set_summary=self.set_summary())
        return tables

    def write_tables(self, directory, formats: tuple[str, ...] = ("csv", "json"),
                     progress: Any = None) -> list[str]:
        """Write each table as ``atlas_<name>.<format>`` into ``directory`` (created); returns the paths.
        ``progress(i, n, path)`` is called after each file is written."""
        bad = [f for f in formats if f not in ("csv", "json")]
        if bad or not formats:
            raise ValueError(f"formats must be a non-empty tuple of 'csv' and/or 'json', got {formats!r}")
        os.makedirs(directory, exist_ok=True)
        tables = self.tables()
        n = len(tables) * len(formats)
        paths = []
        for name, rows in tables.items():
            for fmt in formats:
                paths.append(write_rows(os.path.join(directory, f"atlas_{name}.{fmt}"), rows))
                if progress is not None:
                    progress(len(paths), n, paths[-1])
        return paths

    def to_xarray(self) -> Any:
        """The atlas as an :class:`xarray.Dataset` on dimensions ``I``, ``V`` (and ``approximation``,
        ``observable``, ``reduction``, ``stat``): ``exact`` [I, V, observable], ``predicted`` and
        ``rel_error`` (signed) [approximation, I, V, observable], ``segment_error`` [reduction, I, V, stat],
        ``exact_class``, ``regime``, ``status`` [I, V] (str); with sets ``n_attractors`` and ``confidence``
        [I, V].  NaN is xarray's mark of an undefined value
        here; ``undefined`` [approximation, I, V, observable] says why.

        Raises
        ------
        ImportError
            If xarray is not installed (``pip install 'peelapprox[data]'``).
        """
        xr = optional_import("xarray", "AtlasResult.to_xarray")

        def filled(m: np.ma.MaskedArray) -> np.ndarray:
            return m.filled(np.nan)

        names = list(self.approximations)
        stats = ("dt_median", "dt_worst", "dF_median", "dF_worst")
        data: dict[str, Any] = {
            "exact": (("I", "V", "observable"), np.stack([filled(self.exact(o)) for o in OBSERVABLES], -1)),
            "exact_class": (("I", "V"), self.exact_class().astype(str)),
            "regime": (("I", "V"), self.regime().astype(str)),
            "status": (("I", "V"), self.status().astype(str)),
        }
        if names:
            data["predicted"] = (("approximation", "I", "V", "observable"), np.stack(
                [np.stack([filled(self.prediction(n, o)) for o in OBSERVABLES], -1) for n in names]))
            data["rel_error"] = (("approximation", "I", "V", "observable"), np.stack(
                [np.stack([filled(self.relative_error(n, o, signed=True)) for o in OBSERVABLES], -1) for n in names]))
            data["undefined"] = (("approximation", "I", "V", "observable"), np.stack(
                [np.stack([self.undefined(n, o).astype(str) for o in OBSERVABLES], -1) for n in names]))
        if self.has_sets:
            data["n_attractors"] = (("I", "V"), filled(self.multistability()))
            data["confidence"] = (("I", "V"), self.confidence().astype(str))
        if self.reductions:
            data["segment_error"] = (("reduction", "I", "V", "stat"), np.stack(
                [np.stack([filled(self.segment_error(r, s)) for s in stats], -1) for r in self.reductions]))
        coords = {"I": ("I", self.I_values, {"units": "kg m²"}), "V": ("V", self.V_values, {"units": "m/s"}),
                  "observable": list(OBSERVABLES), "approximation": names, "reduction": list(self.reductions),
                  "stat": list(stats)}
        attrs = {"options": json.dumps(jsonable(self.options)), "force": repr(self.force), "out": self.out or "",
                 "units": json.dumps(UNITS), "skipped": json.dumps(self.skipped),
                 "points": len(self.sweep.records), "total": int(np.prod(self.shape))}
        return xr.Dataset(data, coords=coords, attrs=attrs)

    # ------------------------------------------------------------------------------------------ figures
    def plot_error(self, name: str, observable: str, path=None, **kwargs: Any) -> Any:
        """:func:`comparisons.atlas.plots.plot_error_map` of this atlas."""
        from .plots import plot_error_map

        return plot_error_map(self, name, observable, path, **kwargs)

    def plot_dynamics(self, path=None, **kwargs: Any) -> Any:
        """:func:`comparisons.atlas.plots.plot_dynamics_map` of this atlas."""
        from .plots import plot_dynamics_map

        return plot_dynamics_map(self, path, **kwargs)

    def write_maps(self, directory, progress: Any = None) -> list[str]:
        """:func:`comparisons.atlas.plots.write_maps` of this atlas: every map as a PNG in ``directory``
        (``progress(i, n, path)`` after each)."""
        from .plots import write_maps

        return write_maps(self, directory, progress)

    # ------------------------------------------------------------------------------------------ display
    def _summary(self) -> dict:
        n = int(np.prod(self.shape))
        return {"grid": f"{self.shape[0]} I x {self.shape[1]} V", "points": f"{len(self.sweep.records)}/{n}",
                "stick-slip": int(self.stick_slip().sum()), "failed": len(self.failed()),
                "approximations": ", ".join(self.approximations) or "–",
                "skipped": ", ".join(self.skipped) or "–", "reductions": len(self.reductions),
                "window": f"{fmt_number(self.options.get('t_transient'), 4)} + "
                          f"{fmt_number(self.options.get('t_window'), 4)} s", "out": self.out}

    def _repr_html_(self) -> str:
        return html_table("AtlasResult", self._summary())

    def __repr__(self) -> str:
        s = self._summary()
        return (f"AtlasResult({s['grid']}, {s['points']} points, {s['stick-slip']} stick-slip, approximations="
                f"{list(self.approximations)}, out={self.out!r})")


def load_atlas(out) -> AtlasResult:
    """Read an atlas directory (finished or not) without changing it.

    Raises
    ------
    ValueError
        No manifest, a malformed file (:func:`comparisons.sweep.load_sweep`), or a sweep that is not an atlas.
    """
    return AtlasResult(load_sweep(out))
