"""The records of a sweep on its grid: :class:`SweepResult` and :func:`load_sweep` (read-only)."""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from peelapprox import PeelForce
from peelapprox.io import html_table, jsonable, optional_import
from peelapprox.validate import path as _path

from .law import manifest_law
from .store import RESERVED, failed, point_key, read_manifest, read_records

__all__ = ["SweepResult", "load_sweep"]


#: Units and descriptions of the built-in measures' record keys (the variables of :meth:`SweepResult.to_xarray`);
#: a registered measure's keys get a description naming their measure and no units.
_KEY_INFO: dict[str, tuple[str, str]] = {
    "status": ("", "ok, breakdown:<reason>, or error:<exception> (a measure raised)"),
    "regime_label": ("", "regime of peelapprox.estimate (closed form)"),
    "regime_inertia": ("", "inertia class of the regime (low/intermediate/high)"),
    "regime_velocity": ("", "velocity class of the regime"),
    "regime_fixed_point_stable": ("", "the steady state v = V is stable (1) or not (0)"),
    "regime_inertia_ratio": ("", "inertial period over the stick (AB) time"),
    "regime_period_at_mean": ("s", "inertial period of the roller at the mean force"),
    "regime_cd_damping_time": ("s", "damping time of the oscillation on CD"),
    "regime_t_ab_crude": ("s", "time on AB, crude estimate"),
    "regime_t_ab_quasi_static": ("s", "time on AB, quasi-static estimate"),
    "regime_t_cd_quasi_static": ("s", "time on CD, quasi-static estimate"),
    "regime_oscillations_per_ab": ("", "inertial oscillations per AB stay"),
    "regime_force_gap": ("", "relative gap between the force bounds"),
    "jumps_status": ("", "ok or breakdown:<reason> of the windowed exact run"),
    "jumps_t_breakdown": ("s", "time of the model breakdown"),
    "jumps_count": ("", "jumps in the window"),
    "jumps_n_slips": ("", "AB->CD jumps (slips) in the window"),
    "jumps_mean_interval": ("s", "mean time between consecutive jumps"),
    "jumps_mean_period": ("s", "mean time between consecutive AB->CD jumps (stick-slip period)"),
    "jumps_mean_force_drop": ("N", "mean force drop from an AB->CD jump to the next CD->AB jump"),
    "period_status": ("", "ok or breakdown:<reason>"),
    "period_label": ("", "period-n, aperiodic or too short (peelapprox.periodicity of the return map)"),
    "period": ("", "period n of the return map (AB->CD jumps per period)"),
    "period_mismatch": ("", "relative mismatch of the return map at the period found"),
    "period_n_returns": ("", "return-map values in the window"),
    "lyapunov_status": ("", "ok or breakdown:<reason>"),
    "lyapunov_bits_per_s": ("bit/s", "largest Lyapunov exponent"),
    "lyapunov_stderr_bits": ("bit/s", "standard error of the largest Lyapunov exponent"),
    "lyapunov_n_jumps": ("", "jumps while the exponent was measured"),
}


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, str)


class SweepResult:
    """Records of a sweep on its (I, V) grid, or its (I, V, coef) grid with a coefficient axis.

    Attributes
    ----------
    I_values, V_values : ndarray
        The grid axes, in the order given (``values()`` arrays are indexed
        ``[i, j]`` for ``I_values[i], V_values[j]``; ``[i, j, k]`` with a
        coefficient axis, ``coef_values[k]``).
    measures : tuple of str
    options : dict
    records : list of dict
        Finished points, in grid order (I major); see :mod:`comparisons.sweep`.
    manifest : dict
    out : str or None
    force : peelapprox.PeelForce
        The sweep's law (:mod:`comparisons.sweep.law`; the paper's by default).
    coef_name : str or None
        The coefficient of ``force`` swept as a third axis, if any.
    coef_values : ndarray or None
        Its values.
    """

    def __init__(self, I_values, V_values, measures, options, records: Iterable[dict], *,
                 manifest: dict | None = None, out: str | None = None, force: PeelForce | None = None,
                 coef: tuple[str, Sequence[float]] | None = None):
        self.I_values = np.asarray(I_values, dtype=float)
        self.V_values = np.asarray(V_values, dtype=float)
        self.measures = tuple(measures)
        self.options = dict(options)
        self.manifest = manifest or {}
        self.out = out
        self.force = PeelForce.paper() if force is None else force
        self.coef_name = None if coef is None else str(coef[0])
        self.coef_values = None if coef is None else np.asarray(coef[1], dtype=float)
        index: dict = {(float(I), float(V)): (i, j) for i, I in enumerate(self.I_values)
                       for j, V in enumerate(self.V_values)}
        if self.coef_values is not None:
            index = {(*key, float(c)): (*ij, k) for key, ij in index.items() for k, c in enumerate(self.coef_values)}
        by_key: dict = {}
        for rec in records:
            key = point_key(rec, self.coef_values is not None)
            if key in index and key not in by_key:
                by_key[key] = rec
        self._index = index
        self._by_key = by_key
        self.records = [by_key[k] for k in sorted(by_key, key=index.__getitem__)]

    @property
    def shape(self) -> tuple[int, ...]:
        """``(len(I_values), len(V_values))``, and ``len(coef_values)`` with a coefficient axis."""
        base = (self.I_values.size, self.V_values.size)
        return base if self.coef_values is None else (*base, self.coef_values.size)

    @property
    def complete(self) -> bool:
        """Every grid point has a record."""
        return len(self.records) == int(np.prod(self.shape))

    def missing(self) -> list[tuple[float, ...]]:
        """(I, V) of the points without a record (``(I, V, coef)`` with a coefficient axis), in grid order."""
        return [k for k in self._index if k not in self._by_key]

    def failed(self) -> list[tuple[float, ...]]:
        """(I, V) of the points whose record is an error (a measure raised), in grid order (``(I, V, coef)`` with a
        coefficient axis); see ``retry_failed`` of :func:`sweep`."""
        return [point_key(r, self.coef_values is not None) for r in self.records if failed(r)]

    def record(self, I: float, V: float, coef: float | None = None) -> dict | None:
        """The record at exactly (I, V) (and ``coef``, with a coefficient axis), or None."""
        return self._by_key.get((float(I), float(V)) if coef is None else (float(I), float(V), float(coef)))

    def keys(self) -> list[str]:
        """All record keys, ``I, V, status`` first, then in order of first appearance."""
        seen = dict.fromkeys(RESERVED)
        for rec in self.records:
            seen.update(dict.fromkeys(rec))
        return list(seen)

    def describe(self, key: str) -> tuple[str, str]:
        """``(unit, description)`` of a record key ("" and a short description for a registered measure's keys
        or an unknown key), as :meth:`to_xarray` labels its variables."""
        if key in _KEY_INFO:
            return _KEY_INFO[key]
        return "", key.replace("_", " ")

    def values(self, key: str) -> np.ndarray:
        """``key`` over the grid as a 2-D array, shape ``(len(I_values), len(V_values))`` (3-D with a coefficient
        axis: :attr:`shape`).

        A float array when every present value is a number (bools become 0/1);
        NaN marks only the points that have no such value: not computed yet,
        the key absent from the record (e.g. ``jumps_count`` after a model
        breakdown, or a failed measure) or None (a statistic that needs more
        jumps than the window has).  Otherwise (e.g. ``regime_label``, or a
        list-valued key such as an atlas's ``atlas_exact_observables``) an
        object array with None at those points (:meth:`to_csv` and
        :meth:`to_xarray` write a list as its text; ``AtlasResult`` reads an
        atlas's lists as arrays).

        Raises
        ------
        KeyError
            If no record has ``key`` (the message lists the keys that exist).
        """
        if not any(key in rec for rec in self.records):
            raise KeyError(f"no record has key {key!r}; keys: {self.keys()}")
        present = [rec[key] for rec in self.records if rec.get(key) is not None]
        numeric = all(_is_number(v) for v in present)
        arr = np.full(self.shape, np.nan if numeric else None, dtype=float if numeric else object)
        for rec in self.records:
            v = rec.get(key)
            if v is not None:
                arr[self._by_key_index(rec)] = float(v) if numeric else v
        return arr

    def _by_key_index(self, rec: dict) -> tuple[int, ...]:
        return self._index[point_key(rec, self.coef_values is not None)]

    def rows(self) -> list[dict]:
        """The records as a list of dicts (copies), in grid order."""
        return [dict(r) for r in self.records]

    def to_csv(self, path) -> None:
        """One row per finished point; columns :meth:`keys`; None/absent as an empty cell; floats in full precision."""
        from peelapprox.io import write_rows

        if not str(path).endswith(".csv"):
            raise ValueError(f"path must end in .csv, got {str(path)!r}")
        write_rows(path, self.records, fields=self.keys())

    def to_xarray(self) -> Any:
        """The sweep as an :class:`xarray.Dataset` over the grid: dimensions ``I`` [kg m²] and ``V`` [m/s] (and
        ``coef``, the law coefficient :attr:`coef_name`, with a coefficient axis), one variable per record key
        (:meth:`values`: float with NaN where a point has no value, else str with ``""``), each with ``units``
        and ``description`` (the built-in measures' from a table in this module); attrs: ``measures``, ``force``,
        ``force_key``, ``coef_name``,
        ``options`` and ``manifest`` (JSON text), ``out``, ``points``/``total``.  Missing points (an unfinished
        sweep) are NaN / ``""``.

        Raises
        ------
        ImportError
            If xarray is not installed (``pip install 'peelapprox[data]'``).
        """
        xr = optional_import("xarray", "SweepResult.to_xarray")
        dims: tuple[str, ...] = ("I", "V") if self.coef_values is None else ("I", "V", "coef")
        coords: dict = {"I": ("I", self.I_values, {"units": "kg m²", "description": "moment of inertia of the roller"}),
                        "V": ("V", self.V_values, {"units": "m/s", "description": "pull speed"})}
        if self.coef_values is not None:
            coords["coef"] = ("coef", self.coef_values, {"units": "", "description": f"coefficient "
                                                         f"{self.coef_name} of the law {self.force!r}"})
        data = {}
        for key in self.keys():
            if key in ("I", "V", "coef", "law", "law_key") or not any(key in r for r in self.records):
                continue
            a = self.values(key)
            if a.dtype == object:
                a = np.array([("" if x is None else str(x)) for x in a.ravel()], dtype=str).reshape(a.shape)
            units, what = _KEY_INFO.get(key, ("", f"measure {key.split('_', 1)[0]}: {key}"))
            data[key] = (dims, a, {"units": units, "description": what})
        n = int(np.prod(self.shape))
        attrs = {"measures": " ".join(self.measures), "force": repr(self.force), "force_key": self.force.key,
                 "coef_name": self.coef_name or "", "options": json.dumps(jsonable(self.options)),
                 "manifest": json.dumps(jsonable(self.manifest)), "out": self.out or "",
                 "points": len(self.records), "total": n}
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def _summary(self) -> dict:
        n = int(np.prod(self.shape))
        lo_hi = [f"{a.min():.4g} … {a.max():.4g}" if a.size else "–" for a in (self.I_values, self.V_values)]
        d = {"grid": " x ".join(str(x) for x in self.shape), "I [kg m²]": lo_hi[0], "V [m/s]": lo_hi[1],
             "measures": ", ".join(self.measures), "points": f"{len(self.records)}/{n}",
             "failed": len(self.failed()), "force": repr(self.force), "out": self.out}
        if self.coef_values is not None:
            d["coef"] = f"{self.coef_name}: {self.coef_values.min():.4g} … {self.coef_values.max():.4g}"
        return d

    def _repr_html_(self) -> str:
        return html_table("SweepResult", self._summary())

    def __repr__(self) -> str:
        n = int(np.prod(self.shape))
        c = "" if self.coef_values is None else f" x {self.coef_values.size} {self.coef_name}"
        law = "" if self.force.kind == "paper" and self.coef_values is None else f", force={self.force!r}"
        return (f"SweepResult({self.I_values.size} I x {self.V_values.size} V{c}, measures={list(self.measures)}, "
                f"{len(self.records)}/{n} points{law}, out={self.out!r})")


def load_sweep(out) -> SweepResult:
    """Read a sweep directory (finished or not) without changing it.

    A truncated last line of ``results.jsonl`` is ignored; if a point occurs
    twice (only possible if the file was edited) the first record is used.
    Works in a directory this process cannot write.

    Raises
    ------
    ValueError
        No manifest, a file that is a symbolic link, or a malformed manifest
        or record (the message names the file and line).
    """
    out = _path("out", out)
    m = read_manifest(out)
    force, coef = manifest_law(m)  # checked by read_manifest
    recs, _, _ = read_records(out, coef is not None)
    return SweepResult(m["I_values"], m["V_values"], m["measures"], m["options"], recs, manifest=m, out=out,
                       force=force, coef=coef)
