"""An atlas's records and the arrays read from them: the record schema, the conversion of the first format, and
:class:`AtlasArrays`, every map of an atlas built in one pass over its records.

The schema is :class:`peelapprox.StickSlipObservables`': the observables are its fields
(``StickSlipObservables.OBSERVABLES``, ``SPREADS``), in field order.  A point's record (format
:data:`RECORD_FORMAT`, the manifest's option ``schema``, :func:`schema`) holds, besides the sweep's ``I``, ``V``
and ``status``, a slice of each array of the grid:

* ``atlas_exact_``: ``status``, ``class``, ``reason``, ``period``, ``n_slips`` (``t_breakdown`` after a
  breakdown), ``observables`` [observable] and ``spreads`` [spread] (absent where the exact run has none);
* ``atlas_segments_``: ``status``, ``n_AB``, ``n_CD``, ``stats`` [reduction][:data:`SEGMENT_STATS`];
* ``atlas_approx_``: ``status``, ``regime``, ``prediction_status``, ``prediction_reason``, ``prediction_period``
  [approximation] and ``predicted`` [approximation][observable].

The approximations and reductions are in the order of the options ``approximations`` and ``reductions``.  The
first format (before the schema; no option ``schema``) had one key per number, the approximation's name folded into
the key (``atlas_approx_approx_default_slip_interval``): :func:`upgrade` reads such a record into this format, so an
old atlas loads; it cannot be resumed (:func:`check_resumable`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from peelapprox import StickSlipObservables

from ..sweep import record_key
from ..sweep.store import MANIFEST, failed, read_manifest
from .approximations import OBSERVABLES, key_of

__all__ = ["RECORD_FORMAT", "SPREADS", "SEGMENT_STATS", "NOT_COMPUTED", "schema", "upgrade", "check_resumable",
           "AtlasArrays", "grid_index", "is_none"]

#: The record format this version writes (module docstring).
RECORD_FORMAT = 2
#: The spreads recorded with the exact means (fields of :class:`peelapprox.StickSlipObservables`).
SPREADS = StickSlipObservables.SPREADS
#: The per-reduction summaries of ``atlas_segments``, the last axis of its ``stats``.
SEGMENT_STATS = ("dt_median", "dt_worst", "dF_median", "dF_worst", "n", "failed")
#: The value of a categorical map at a point still to run.
NOT_COMPUTED = "not computed"


def schema() -> dict:
    """The option ``schema`` of an atlas written by this version: the format and the labels of the arrays' last
    axes."""
    return {"format": RECORD_FORMAT, "observables": list(OBSERVABLES), "spreads": list(SPREADS),
            "segment_stats": list(SEGMENT_STATS)}


def _exact(field: str) -> str:
    return record_key("atlas_exact", field)


def _approx(field: str) -> str:
    return record_key("atlas_approx", field)


def _segments(field: str) -> str:
    return record_key("atlas_segments", field)


def _relabel(rec: dict, written: Mapping[str, Any]) -> dict:
    """A record of this format written under another schema (``written``: its option ``schema``, e.g. before an
    observable was added) with its lists' last axes in this schema's order, by label (None where it had none)."""
    new = dict(rec)
    for key, axis, ours, nested in ((_exact("observables"), "observables", OBSERVABLES, False),
                                    (_exact("spreads"), "spreads", SPREADS, False),
                                    (_approx("predicted"), "observables", OBSERVABLES, True),
                                    (_segments("stats"), "segment_stats", SEGMENT_STATS, True)):
        labels = list(written.get(axis, ours))
        if key not in rec or labels == list(ours):
            continue
        def pick(values: list, labels: list = labels, ours: tuple = ours) -> list:
            return [values[labels.index(x)] if x in labels else None for x in ours]
        new[key] = [pick(v) for v in rec[key]] if nested else pick(rec[key])
    return new


def upgrade(rec: dict, approximations: Sequence[str], reductions: Sequence[str],
            written: Mapping[str, Any] | None = None) -> dict:
    """A record in this format and schema: one of the first format (module docstring) as a new dict, its keys of
    the first format replaced by the arrays' slices (the values themselves, unchanged); one of this format written
    under another schema (``written``, the atlas's option ``schema``) with its lists relabelled to this one's; one
    of this format and schema as it is."""
    if written is not None and written != schema():
        return _relabel(rec, written)
    if _exact("observables") in rec or _approx("predicted") in rec or failed(rec):
        return rec
    old: dict[str, Any] = dict(rec)
    new = {k: v for k, v in rec.items() if not k.startswith(("atlas_exact_", "atlas_approx_", "atlas_segments_"))}
    for field in ("status", "class", "reason", "period", "n_slips", "t_breakdown"):
        if _exact(field) in old:
            new[_exact(field)] = old[_exact(field)]
    if _exact(OBSERVABLES[0]) in old:
        new[_exact("observables")] = [old.get(_exact(o)) for o in OBSERVABLES]
        new[_exact("spreads")] = [old.get(_exact(s)) for s in SPREADS]
    for field in ("status", "n_AB", "n_CD"):
        if _segments(field) in old:
            new[_segments(field)] = old[_segments(field)]
    if any(_segments(f"{r}_n") in old for r in reductions):
        new[_segments("stats")] = [[old.get(_segments(f"{r}_{s}")) for s in SEGMENT_STATS] for r in reductions]
    for field in ("status", "regime"):
        if _approx(field) in old:
            new[_approx(field)] = old[_approx(field)]
    if _approx("status") in old:
        for field in ("status", "reason", "period"):
            new[_approx(f"prediction_{field}")] = [old.get(_approx(f"{key_of(n)}_{field}")) for n in approximations]
        new[_approx("predicted")] = [[old.get(_approx(f"{key_of(n)}_{o}")) for o in OBSERVABLES]
                                     for n in approximations]
    return new


def check_resumable(out: Any) -> None:
    """ValueError unless ``out`` holds no atlas or one of this record format (an atlas of the first format is read
    by :func:`~comparisons.atlas.load_atlas`, but its records cannot be continued in this format)."""
    out = os.fspath(out)
    if not os.path.isfile(os.path.join(out, MANIFEST)):
        return
    options = read_manifest(out).get("options", {})
    if "approximations" in options and "schema" not in options:
        raise ValueError(f"out={out!r} holds an atlas of the first record format (one key per number, before "
                         f"format {RECORD_FORMAT}): load_atlas reads it, but it cannot be resumed; run the atlas again "
                         "into a new directory to regenerate it")


def _floats(rows: Any, shape: tuple[int, ...]) -> np.ma.MaskedArray:
    """The float array of ``rows`` (nested lists, None where a value is missing), masked where None, 0 under the
    mask."""
    data = np.array(rows, dtype=float).reshape(shape)  # None -> NaN (JSON holds no NaN: only None is)
    mask = np.isnan(data)
    data[mask] = 0.0
    return np.ma.MaskedArray(data, mask=mask)


def _last_first(m: np.ma.MaskedArray) -> np.ma.MaskedArray:
    """``[i, j, a, k]`` as ``[a, i, j, k]``."""
    return np.ma.MaskedArray(np.moveaxis(m.data, 2, 0), mask=np.moveaxis(np.ma.getmaskarray(m), 2, 0))


def is_none(arr: np.ndarray) -> np.ndarray:
    """Where the object array ``arr`` holds None (elementwise, in numpy)."""
    return np.equal(arr, np.array(None, dtype=object))


def _number(v: Any) -> float | None:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


class AtlasArrays:
    """Every map of an atlas, built once from its records (format :data:`RECORD_FORMAT`, :func:`upgrade`\\ d).

    Arrays are indexed ``[i, j]`` for ``I_values[i], V_values[j]``; per approximation ``[a, i, j]``, per reduction
    ``[r, i, j]``, then the observable (or stat) last.  Float arrays are :class:`numpy.ma.MaskedArray` masked where
    the value is missing (0 under the mask); categorical ones object arrays of str (None where the record has
    no value).

    Attributes
    ----------
    index : list of (int, int)
        The grid position of each record.
    computed, failed : ndarray of bool
        The point has a record; its record is an error (a measure raised).
    status, exact_status, exact_class, regime : ndarray of object
        The record's ``status``, the exact measure's status and class, the regime label.
    exact, spreads : MaskedArray
        ``[i, j, observable]``, ``[i, j, spread]``.
    period, n_slips : MaskedArray
        The exact return map's period and the slips of the window.
    prediction_status, prediction_period, predicted
        ``[a, i, j]`` (object), ``[a, i, j]``, ``[a, i, j, observable]``.
    segment_stats : MaskedArray
        ``[r, i, j, stat]``.
    """

    def __init__(self, records: Sequence[dict], index: Sequence[tuple[int, int]], shape: tuple[int, int],
                 n_approximations: int, n_reductions: int) -> None:
        self.index = list(index)
        self.shape = shape
        self._rows = (np.array([i for i, _ in self.index], dtype=int), np.array([j for _, j in self.index], dtype=int))
        self.computed = self._place([True] * len(records), False, bool)
        self.failed = self._place([failed(r) for r in records], False, bool)
        self.status = self._place([r["status"] for r in records], None)
        self.exact_status = self._place([r.get(_exact("status")) for r in records], None)
        self.exact_class = self._place([r.get(_exact("class")) for r in records], None)
        self.regime = self._place([r.get(_approx("regime"), "failed") for r in records], None)
        self.period = self._numbers([r.get(_exact("period")) for r in records])
        self.n_slips = self._numbers([r.get(_exact("n_slips")) for r in records])
        n_obs, n_a, n_r = len(OBSERVABLES), n_approximations, n_reductions
        self.exact = self._lists(records, _exact("observables"), (n_obs,))
        self.spreads = self._lists(records, _exact("spreads"), (len(SPREADS),))
        self.predicted = _last_first(self._lists(records, _approx("predicted"), (n_a, n_obs)))
        self.prediction_period = self._per(records, _approx("prediction_period"), n_a, numbers=True)
        self.prediction_status = self._per(records, _approx("prediction_status"), n_a)
        self.segment_stats = _last_first(self._lists(records, _segments("stats"), (n_r, len(SEGMENT_STATS))))

    def _place(self, values: list, fill: Any, dtype: Any = object) -> np.ndarray:
        """``values`` (one per record) on the grid, ``fill`` where a point has no record."""
        arr = np.full(self.shape, fill, dtype=dtype)
        if values:
            vals = np.empty(len(values), dtype=dtype)
            vals[:] = values
            arr[self._rows] = vals
        return arr

    def _numbers(self, values: list) -> np.ma.MaskedArray:
        return _floats([[None if v is None else _number(v)] for v in self._place(values, None).ravel()], self.shape)

    def _lists(self, records: Sequence[dict], key: str, inner: tuple[int, ...]) -> np.ma.MaskedArray:
        """``key``'s lists on the grid, ``[i, j, *inner]``, masked where a record has none."""
        missing = np.full(inner, None, dtype=object).tolist()
        grid = np.full((*self.shape, *inner), np.nan)
        if records:
            grid[self._rows] = np.array([r.get(key) or missing for r in records], dtype=float).reshape(
                (len(records), *inner))
        return _floats(grid, grid.shape)

    def _per(self, records: Sequence[dict], key: str, n: int, numbers: bool = False) -> Any:
        """``key``'s list (one value per approximation) as ``[a, i, j]``: object (None where absent), or masked
        floats with ``numbers``."""
        arr = np.full((n, *self.shape), None, dtype=object)
        for (i, j), rec in zip(self.index, records):
            vals = rec.get(key)
            if vals is not None:
                arr[:, i, j] = vals
        if numbers:
            return _floats([None if v is None else _number(v) for v in arr.ravel()], arr.shape)
        return arr

    def grid(self, records: Sequence[dict], fn: Callable[[dict | None], Any]) -> np.ndarray:
        """An object array of ``fn(record)`` over the grid, ``fn(None)`` at the points without one (one pass)."""
        arr = np.full(self.shape, fn(None), dtype=object)
        for (i, j), rec in zip(self.index, records):
            arr[i, j] = fn(rec)
        return arr

    def undefined(self, a: int, k: int) -> np.ndarray:
        """Why the relative error of approximation ``a``'s observable ``k`` is undefined at each point ("" where it
        is defined): ``not computed``, ``failed: <status>``, ``exact: <class>``, ``predicted: <status>``, ``no
        exact value``, ``not predicted``, ``exact value 0``."""
        status = self.status
        cls = np.where(is_none(self.exact_class), status, self.exact_class)
        pred = self.prediction_status[a].astype(str).astype(object)
        e, p = self.exact[..., k], self.predicted[a, ..., k]
        conds = [~self.computed, self.failed, self.exact_status != "ok", self.prediction_status[a] != "stick-slip",
                 np.ma.getmaskarray(e), np.ma.getmaskarray(p), e.data == 0]
        choices = [NOT_COMPUTED, "failed: " + status.astype(str).astype(object),
                   "exact: " + cls.astype(str).astype(object), "predicted: " + pred, "no exact value",
                   "not predicted", "exact value 0"]
        out = np.select(conds, [np.broadcast_to(np.asarray(c, dtype=object), self.shape) for c in choices],
                        default="")
        return out.astype(object)

    def relative_error(self, a: int, k: int, signed: bool) -> np.ma.MaskedArray:
        """``(predicted - exact) / |exact|`` (its absolute value unless ``signed``), masked where
        :meth:`undefined`."""
        ok = self.undefined(a, k) == ""
        e, p = self.exact.data[..., k], self.predicted.data[a, ..., k]
        d = np.zeros(self.shape)
        d[ok] = (p[ok] - e[ok]) / np.abs(e[ok])
        return np.ma.MaskedArray(d if signed else np.abs(d), mask=~ok)


def grid_index(records: Sequence[Mapping], I_values: np.ndarray, V_values: np.ndarray) -> list[tuple[int, int]]:
    """The ``(i, j)`` of each record on the grid (the sweep's records are all on it)."""
    iI = {float(x): i for i, x in enumerate(I_values)}
    iV = {float(x): j for j, x in enumerate(V_values)}
    return [(iI[float(r["I"])], iV[float(r["V"])]) for r in records]
