"""(I, V) parameter sweeps that scale from a laptop to a cluster.

A sweep evaluates named *measures* at every point of a grid of roller
inertias ``I`` and pull speeds ``V``, one task per point, on any
:class:`concurrent.futures.Executor`: a local process pool by default, a dask
cluster by passing ``executor=Client(...).get_executor()``.  Each finished
point is appended to ``out/results.jsonl`` and forced to disk at once, so a
killed sweep loses only the points that were running, and calling
:func:`sweep` again with the same arguments finishes the rest.

Measures
--------
A measure is ``fn(params: PeelParams, options: Mapping) -> dict`` returning a
flat dict of JSON scalars (``float, int, str, bool, None``; numpy scalars are
converted).  Keys are prefixed ``"<name>_"`` by the engine unless they already
equal ``name`` or start with ``"<name>_"``.  Register with
:func:`register_measure`; the built-ins are ``"regime"`` (closed-form regime
estimate, milliseconds), ``"jumps"`` (statistics of the stick-slip jumps of
the exact solution) and, registered by :mod:`peelapprox._dynamics`,
``"period"`` (period of the return map) and ``"lyapunov"`` (largest Lyapunov
exponent, bits/s).

Options
-------
``options`` is one JSON-serialisable dict passed to every measure.  The engine
itself reads ``k, R, l, geometry`` (the :class:`PeelParams` fields other than
I and V; defaults as there); ``jumps`` and ``period`` share one windowed run
(:func:`peelapprox._dynamics.window_run`) and read ``t_transient`` (30 s),
``t_end`` (t_transient + 20 s), ``rtol`` (1e-10) and ``alpha0`` (0);
``lyapunov`` reads ``t_transient`` and ``lyapunov_time`` (50 s).  Every option
the chosen measures read is checked before the first point (a measure
registered with ``check_options`` checks its own), so invalid options raise
ValueError naming the option and nothing is written.

Workers
-------
Pool and cluster workers import each measure by ``module:qualname``.  A
measure they cannot import (defined in a notebook or ``__main__``, a lambda, a
local function) is shipped by value with cloudpickle when it is installed;
without it, such a measure is a ValueError before the first point.
``max_workers=0`` (``--workers 0``) runs every point in this process.

Output directory
----------------
``out/sweep.json``
    Manifest: grid values, measures, options, how to import each measure,
    package versions, creation time.  Written once, atomically.
``out/results.jsonl``
    One JSON object per finished point, in completion order: ``I``, ``V``,
    ``status``, then the measures' keys.  ``status`` is ``"ok"`` when every
    measure is; else ``"error: <Type>: <message>"`` of the first measure that
    raised, or else the first non-ok status a measure reported (e.g.
    ``"breakdown:no_root"``, a result, not a failure).  A failing measure
    records ``"<name>_status": "error: ..."`` and the others still run.
    Error points count as finished on resume; ``retry_failed=True``
    (``--retry-failed``) drops their records (the file is rewritten
    atomically) and computes them again.  Non-finite floats are written as
    ``NaN``/``Infinity`` (Python's JSON extension).  Records hold no timings
    or host names, so the same inputs give the same records.
``out/.lock``
    Held (``flock``) while a sweep writes, so two sweeps cannot share ``out``.

Files are opened without following symbolic links (``os.O_NOFOLLOW``) and
must be regular files; a manifest or record that is not what the engine
writes (wrong types, missing keys, non-finite ``I``/``V``) is a ValueError
naming the file (and line) as malformed.  A directory this process cannot
write is read only: a complete sweep there is returned (and reported by the
CLI); computing anything there is a ValueError.  The format itself lives in
:mod:`peelapprox._sweep_store`.
"""

from __future__ import annotations

import datetime as _dt
import importlib
import math
import numbers
import os
import re
import sys
import threading
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from types import MappingProxyType, ModuleType
from typing import Any, cast

import numpy as np

from ._params import PARAM_RANGES, PeelParams
from ._sweep_store import (
    FORMAT,
    RESERVED,
    RESULTS,
    Plan,
    append_records,
    check_axis,
    failed,
    is_read_only,
    json_norm,
    read_manifest,
    read_records,
    rewrite_records,
    truncate_records,
    versions,
    write_manifest,
    write_record,
)
from ._sweep_store import lock as _lock
from ._validate import ArgumentTypeError
from ._validate import path as _path

__all__ = [
    "MEASURES",
    "register_measure",
    "sweep",
    "load_sweep",
    "SweepResult",
    "parse_grid",
]

#: Options the engine turns into :class:`PeelParams` fields.
PARAM_OPTIONS = ("k", "R", "l", "geometry")

Measure = Callable[[PeelParams, Mapping], dict]
OptionCheck = Callable[[Mapping], Any]

#: name -> measure function.  Add entries with :func:`register_measure`.
MEASURES: dict[str, Measure] = {}
#: name -> its options check (``check_options`` of :func:`register_measure`).
_OPTION_CHECKS: dict[str, OptionCheck] = {}

_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _ref(fn: Callable) -> str:
    return f"{getattr(fn, '__module__', '?')}:{getattr(fn, '__qualname__', '?')}"


def register_measure(name: str, fn: Measure | None = None, *, replace: bool = False,
                     check_options: OptionCheck | None = None):
    """Register ``fn(params, options) -> dict`` under ``name``.

    without ``fn`` it returns a decorator.

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
    if old is not None and old is not fn and _ref(old) != _ref(fn) and not replace:
        raise ValueError(f"measure {name!r} is already registered as {_ref(old)}; pass replace=True to replace it")
    MEASURES[name] = fn
    if check_options is None:
        _OPTION_CHECKS.pop(name, None)
    else:
        _OPTION_CHECKS[name] = check_options
    return fn


# --------------------------------------------------------------------------------------------- built-in measures

def _measure_regime(params: PeelParams, options: Mapping) -> dict:
    """Regime label of :func:`peelapprox.estimate` and its closed-form time scales (a few ms)."""
    from ._estimate import estimate

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
    (:func:`peelapprox._dynamics.window_run`: t_transient 30 s, t_end t_transient + 20 s, rtol 1e-10).

    ``count`` jumps in the window, ``n_slips`` of them AB→CD; ``mean_interval``
    = mean time between consecutive jumps (either kind), ``mean_period`` =
    mean time between consecutive AB→CD jumps (the stick-slip period);
    ``mean_force_drop`` = mean over AB→CD jumps of F there minus F at the next
    CD→AB jump [N].  Statistics that need more jumps than the window holds are
    None.  A :class:`ModelBreakdown` gives ``status = "breakdown:<reason>"``
    and the breakdown time ``t_breakdown``.
    """
    from ._dynamics import _window_options, force_drops, return_map, window_run
    from ._errors import ModelBreakdown

    try:  # the same windowed run (and defaults) as the `period` measure: computed once per point
        traj = window_run(params, **_window_options(options))
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


def _check_window_options(options: Mapping) -> None:
    """The options of the windowed run (:func:`peelapprox._dynamics._window_options` checks them)."""
    from ._dynamics import _window_options

    _window_options(options)


register_measure("regime", _measure_regime)
register_measure("jumps", _measure_jumps, check_options=_check_window_options)


# --------------------------------------------------------------------------------------------- the task

def _import_ref(ref: str) -> Callable:
    mod, _, qual = ref.partition(":")
    obj: Any = importlib.import_module(mod)
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


def _resolve(name: str, ref: None | str | bytes) -> Measure:
    """The measure function in this (worker) process: unpickled if shipped by value (bytes), else by import
    reference, else by registry name."""
    if isinstance(ref, bytes):
        import pickle

        try:
            return pickle.loads(ref)
        except Exception as exc:
            raise LookupError(f"measure {name!r} was shipped by value (cloudpickle) but cannot be unpickled in this "
                              f"process ({type(exc).__name__}: {exc}); install cloudpickle where the workers run, "
                              "or define the measure in an importable module") from None
    if ref is not None:
        fn = MEASURES.get(name)
        if fn is not None and _ref(fn) == ref:
            return fn
        try:
            return _import_ref(ref)
        except Exception:
            pass
    if name in MEASURES:
        return MEASURES[name]
    raise LookupError(f"measure {name!r} cannot be resolved in this process (import reference {ref!r}); "
                      "define it at module level in a module the workers can import")


def _scalar(v: Any) -> Any:
    if v is None or isinstance(v, (bool, str)):
        return v
    if isinstance(v, np.generic) or (isinstance(v, np.ndarray) and v.ndim == 0):
        v = v.item()
        return v if isinstance(v, (bool, str)) else _scalar(v)
    if isinstance(v, numbers.Integral):
        return int(v)
    if isinstance(v, numbers.Real):
        return float(v)
    raise TypeError(f"value {v!r} of type {type(v).__name__} is not a JSON scalar (float, int, str, bool, None)")


def _prefixed(name: str, out: Any) -> dict:
    if not isinstance(out, Mapping):
        raise TypeError(f"measure {name!r} must return a dict, got {type(out).__name__}")
    rec = {}
    for key, val in out.items():
        if not isinstance(key, str) or not key:
            raise TypeError(f"measure {name!r} returned a non-string key {key!r}")
        full = key if (key == name or key.startswith(name + "_")) else f"{name}_{key}"
        try:
            rec[full] = _scalar(val)
        except TypeError as exc:
            raise TypeError(f"measure {name!r}, key {key!r}: {exc}") from None
    return rec


def _error(exc: BaseException) -> str:
    msg = " ".join(str(exc).split())
    if len(msg) > 500:
        msg = msg[:497] + "..."
    return f"error: {type(exc).__name__}: {msg}"


def _make_params(I: float, V: float, options: Mapping) -> PeelParams:
    return PeelParams(V=V, I=I, **{k: options[k] for k in PARAM_OPTIONS if k in options})


def _run_point(I: float, V: float, measures: Sequence[str], options: Mapping,
               refs: Mapping[str, str | bytes] | None = None) -> dict:
    """Evaluate ``measures`` at one grid point; never raises for a measure's failure.

    Module level and plain-data in/out, so any executor can ship it.  ``refs``
    maps a measure's name to its import reference, or to its cloudpickle bytes.
    Returns the record ``{"I", "V", "status", <measure keys>...}``; ``status``
    as in the module docstring.
    """
    refs = refs or {}
    body: dict = {}
    error = reported = None
    try:
        params = _make_params(I, V, options)
    except Exception as exc:
        return {"I": I, "V": V, "status": _error(exc)}
    opts = MappingProxyType(dict(options))
    for name in measures:
        try:
            out = _prefixed(name, _resolve(name, refs.get(name))(params, opts))
            clash = (set(out) & set(body)) | (set(out) & set(RESERVED))
            if clash:
                raise ValueError(f"measure {name!r} returned keys that are already taken: {sorted(clash)}")
            body.update(out)
            own = out.get(f"{name}_status")
            if reported is None and isinstance(own, str) and own != "ok":
                reported = own
        except Exception as exc:
            err = _error(exc)
            body[f"{name}_status"] = err
            error = error or err
    return {"I": I, "V": V, "status": error or reported or "ok", **body}


def _cloudpickle() -> ModuleType | None:
    """The cloudpickle module, or None if it is not installed."""
    try:
        import cloudpickle
    except ImportError:
        return None
    return cloudpickle


def _importable(fn: Callable) -> bool:
    """Whether a worker process can import ``fn`` by its ``module:qualname`` (as this process resolves it)."""
    mod, _, qual = _ref(fn).partition(":")
    if mod in ("__main__", "__mp_main__", "?") or "<" in qual:
        return False
    try:
        return _import_ref(_ref(fn)) is fn
    except Exception:
        return False


def _worker_refs(measures: Sequence[str]) -> dict[str, str | bytes]:
    """What the workers get for each measure: its import reference, or its cloudpickle bytes if they could not
    import it.  ValueError (before any point runs) if such a measure cannot be shipped."""
    refs: dict[str, str | bytes] = {name: _ref(MEASURES[name]) for name in measures}
    lone = [name for name in measures if not _importable(MEASURES[name])]
    if not lone:
        return refs
    cp = _cloudpickle()
    if cp is None:
        raise ValueError(f"measure(s) {lone} ({[refs[n] for n in lone]}) cannot be imported by worker processes "
                         "(defined in a notebook or __main__, a lambda or a local function) and cloudpickle, which "
                         "would ship them, is not installed: define them in an importable module, "
                         "pip install cloudpickle, or run in this process with max_workers=0 (--workers 0)")
    for name in lone:
        try:
            refs[name] = cp.dumps(MEASURES[name])
        except Exception as exc:
            ref = cast(str, refs[name])  # still its import reference: dumps raised before the assignment
            raise ValueError(f"measure {name!r} ({ref}) cannot be pickled to ship it to the workers "
                             f"({type(exc).__name__}: {exc}): define it in an importable module, or run in this "
                             "process with max_workers=0 (--workers 0)") from None
    return refs


def _worker_init(parent_pid: int) -> None:  # pragma: no cover - runs in the workers
    """Exit when the sweeping process dies (e.g. SIGKILL), instead of idling as an orphan."""

    def watch() -> None:
        while True:
            time.sleep(0.5)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="peelapprox-sweep-orphan-watch", daemon=True).start()


# --------------------------------------------------------------------------------------------- result

def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, str)


class SweepResult:
    """Records of a sweep on its (I, V) grid.

    Attributes
    ----------
    I_values, V_values : ndarray
        The grid axes, in the order given (``values()`` arrays are indexed
        ``[i, j]`` for ``I_values[i], V_values[j]``).
    measures : tuple of str
    options : dict
    records : list of dict
        Finished points, in grid order (I major); see the module docstring.
    manifest : dict
    out : str or None
    """

    def __init__(self, I_values, V_values, measures, options, records: Iterable[dict], *,
                 manifest: dict | None = None, out: str | None = None):
        self.I_values = np.asarray(I_values, dtype=float)
        self.V_values = np.asarray(V_values, dtype=float)
        self.measures = tuple(measures)
        self.options = dict(options)
        self.manifest = manifest or {}
        self.out = out
        index = {(float(I), float(V)): (i, j) for i, I in enumerate(self.I_values) for j, V in enumerate(self.V_values)}
        by_key: dict = {}
        for rec in records:
            key = (float(rec["I"]), float(rec["V"]))
            if key in index and key not in by_key:
                by_key[key] = rec
        self._index = index
        self._by_key = by_key
        self.records = [by_key[k] for k in sorted(by_key, key=index.__getitem__)]

    @property
    def shape(self) -> tuple[int, int]:
        return (self.I_values.size, self.V_values.size)

    @property
    def complete(self) -> bool:
        """Every grid point has a record."""
        return len(self.records) == self.I_values.size * self.V_values.size

    def missing(self) -> list[tuple[float, float]]:
        """(I, V) of the points without a record, in grid order."""
        return [k for k in self._index if k not in self._by_key]

    def failed(self) -> list[tuple[float, float]]:
        """(I, V) of the points whose record is an error (a measure raised), in grid order; see ``retry_failed``
        of :func:`sweep`."""
        return [(float(r["I"]), float(r["V"])) for r in self.records if failed(r)]

    def record(self, I: float, V: float) -> dict | None:
        """The record at exactly (I, V), or None."""
        return self._by_key.get((float(I), float(V)))

    def keys(self) -> list[str]:
        """All record keys, ``I, V, status`` first, then in order of first appearance."""
        seen = dict.fromkeys(RESERVED)
        for rec in self.records:
            seen.update(dict.fromkeys(rec))
        return list(seen)

    def values(self, key: str) -> np.ndarray:
        """``key`` over the grid as a 2-D array, shape ``(len(I_values), len(V_values))``.

        A float array when every present value is a number (bools become 0/1);
        NaN marks only the points that have no such value: not computed yet,
        the key absent from the record (e.g. ``jumps_count`` after a model
        breakdown, or a failed measure) or None (a statistic that needs more
        jumps than the window has).  Otherwise (e.g. ``regime_label``) an
        object array with None at those points.

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

    def _by_key_index(self, rec: dict) -> tuple[int, int]:
        return self._index[(float(rec["I"]), float(rec["V"]))]

    def rows(self) -> list[dict]:
        """The records as a list of dicts (copies), in grid order."""
        return [dict(r) for r in self.records]

    def to_csv(self, path) -> None:
        """One row per finished point; columns :meth:`keys`; None/absent as an empty cell; floats in full precision."""
        from ._io import write_rows

        if not str(path).endswith(".csv"):
            raise ValueError(f"path must end in .csv, got {str(path)!r}")
        write_rows(path, self.records, fields=self.keys())

    def __repr__(self) -> str:
        n = self.I_values.size * self.V_values.size
        return (f"SweepResult({self.I_values.size} I x {self.V_values.size} V, measures={list(self.measures)}, "
                f"{len(self.records)}/{n} points, out={self.out!r})")


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
    recs, _, _ = read_records(out)
    return SweepResult(m["I_values"], m["V_values"], m["measures"], m["options"], recs, manifest=m, out=out)


# --------------------------------------------------------------------------------------------- grid helpers

def parse_grid(spec: str, *, name: str = "values") -> np.ndarray:
    """Grid values from ``"start:stop:num"`` (linspace), ``"start:stop:num:log"`` (geometric, exact endpoints)
    or a comma list ``"0.4,1,2"``.

    Raises ValueError naming ``name`` on a malformed spec.
    """
    s = str(spec).strip()
    try:
        if ":" in s:
            parts = s.split(":")
            if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
                raise ValueError("expected start:stop:num or start:stop:num:log")
            a, b = float(parts[0]), float(parts[1])
            n = int(parts[2])
            if n < 1:
                raise ValueError(f"num must be >= 1, got {n}")
            if len(parts) == 4 and parts[3] == "log":
                if not (a > 0 and b > 0):
                    raise ValueError("a log range needs start > 0 and stop > 0")
                return np.geomspace(a, b, n)
            return np.linspace(a, b, n)
        vals = [float(x) for x in s.split(",") if x.strip()]
        if not vals:
            raise ValueError("empty list")
        return np.asarray(vals)
    except ValueError as exc:
        raise ValueError(f"{name}: cannot parse {spec!r} ({exc}); use start:stop:num[:log] or a comma list") \
            from None


# --------------------------------------------------------------------------------------------- the sweep

class _Stderr:
    def __init__(self, total: int, done0: int):
        self.t0 = time.perf_counter()
        self.done0 = done0
        self.total = total

    def __call__(self, done: int, total: int, rec: dict) -> None:
        el = time.perf_counter() - self.t0
        n = done - self.done0
        eta = el / n * (total - done) if n else float("nan")
        w = len(str(total))
        sys.stderr.write(f"sweep [{done:>{w}}/{total}] I={rec['I']:.4g} V={rec['V']:.4g} {rec['status'][:60]}  "
                         f"elapsed {_hms(el)}, ETA {_hms(eta)}\n")
        sys.stderr.flush()


def _hms(s: float) -> str:
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


def sweep(
    I_values: Sequence[float] | np.ndarray,
    V_values: Sequence[float] | np.ndarray,
    measures: str | Sequence[str] = ("regime",),
    *,
    out,
    executor: None | str | Executor = None,
    max_workers: int | None = None,
    options: Mapping[str, Any] | None = None,
    progress: bool | Callable[[int, int, dict], None] | None = True,
    resume: bool = True,
    retry_failed: bool = False,
) -> SweepResult:
    """Evaluate ``measures`` at every (I, V) grid point, writing each finished point to ``out`` at once.

    Parameters
    ----------
    I_values, V_values : sequence of float
        Grid axes (finite, > 0, no repeats); every pair is one task.
    measures : str or sequence of str
        Names in :data:`MEASURES` (``"regime,jumps"`` is split at commas).
    out : path
        Output directory (created); see the module docstring for its files.
    executor : None, "serial" or concurrent.futures.Executor
        ``None``: a local :class:`ProcessPoolExecutor` (``spawn`` start
        method, ``max_workers`` processes, shut down at the end).
        ``"serial"``: in this process, one point after another (debugging).
        Any Executor: used as is and left running, e.g.
        ``distributed.Client(...).get_executor()`` for a dask cluster.
    max_workers : int, optional
        Processes of the local pool (default: CPUs available, at most the
        number of points to compute); 0 runs in this process, as
        ``executor="serial"`` (the CLI's ``--workers 0``).  Only with
        ``executor=None``.
    options : mapping, optional
        JSON-serialisable settings passed to every measure (module
        docstring), checked before the first point.
    progress : bool or callable
        ``True``: one line per finished point on stderr, with an ETA.  A
        callable receives ``(done, total, record)`` (``done`` counts resumed
        points too).
    resume : bool
        With an existing sweep in ``out`` (same grid, measures and options,
        else ValueError naming what differs): skip its finished points.
        ``resume=False`` refuses a non-empty ``out`` (ValueError) rather than
        overwrite it.
    retry_failed : bool
        Also compute again the points of ``out`` whose status is an error
        (their records are dropped first); by default they count as finished.

    Returns
    -------
    SweepResult
        All records in ``out`` (the resumed and the new ones).

    Raises
    ------
    ValueError
        Invalid arguments or options (naming the argument or option and its
        valid range), unknown measures (listing the known ones), a measure
        the workers can neither import nor be sent, an ``out`` holding
        another sweep, a malformed or symbolically linked file in ``out``, an
        ``out`` this process cannot write while points remain to compute.
    RuntimeError
        ``out`` is locked by another sweep; or tasks were lost to the
        executor (a worker died): the records written stay, and calling
        :func:`sweep` again computes the lost points.

    Notes
    -----
    A point whose measure raises is recorded with ``status = "error: ..."``
    and the sweep goes on; such points count as finished on resume unless
    ``retry_failed=True``.  Nothing is written before every argument and
    option has been checked.
    """
    I_vals = check_axis("I_values", I_values, *PARAM_RANGES["I"])
    V_vals = check_axis("V_values", V_values, *PARAM_RANGES["V"])
    if isinstance(measures, str):
        measures = [m.strip() for m in measures.split(",") if m.strip()]
    if not isinstance(measures, (list, tuple)) or not all(isinstance(m, str) for m in measures):
        raise ArgumentTypeError(f"measures must be a str or a sequence of str (names in MEASURES), got {measures!r}")
    measures = list(measures)
    if not measures:
        raise ValueError(f"measures must name at least one measure; known: {sorted(MEASURES)}")
    if len(set(measures)) != len(measures):
        raise ValueError(f"measures must not repeat a name, got {measures}")
    unknown = [m for m in measures if m not in MEASURES]
    if unknown:
        raise ValueError(f"measures: unknown measure(s) {unknown}; known: {sorted(MEASURES)}")
    options = {} if options is None else options
    if not isinstance(options, Mapping) or not all(isinstance(k, str) for k in options):
        raise ValueError(f"options must be a mapping with str keys, got {options!r}")
    try:
        options = json_norm(dict(options))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"options must be JSON-serialisable (str, numbers, bools, None, lists, dicts): {exc}") \
            from None
    _check_options(measures, options)
    if max_workers is not None:
        if isinstance(max_workers, bool) or not isinstance(max_workers, numbers.Integral) or max_workers < 0:
            raise ValueError(f"max_workers must be an integer in [0, inf) (0: in this process) or None, "
                             f"got {max_workers!r}")
        if executor is not None:
            raise ValueError("max_workers applies only to the local process pool (executor=None); "
                             "size your executor instead")
    if executor is not None and not (isinstance(executor, str) and executor == "serial") \
            and not callable(getattr(executor, "submit", None)):
        raise ValueError(f"executor must be None, 'serial' or a concurrent.futures.Executor, got {executor!r}")
    if not (isinstance(progress, bool) or progress is None or callable(progress)):
        raise ValueError("progress must be a bool, None or a callable (done, total, record)")
    for name, flag in (("resume", resume), ("retry_failed", retry_failed)):
        if not isinstance(flag, bool):
            raise ValueError(f"{name} must be True or False, got {flag!r}")
    if max_workers == 0:
        executor = "serial"
    refs = {name: _ref(MEASURES[name]) for name in measures}
    task_refs = refs if executor == "serial" else _worker_refs(measures)

    out = _path("out", out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise ValueError(f"out={out!r} exists and is not a directory")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"out={out!r}: cannot create the directory ({exc})") from None
    plan = dict(out=out, I_vals=I_vals, V_vals=V_vals, measures=measures, options=options, resume=resume,
                retry_failed=retry_failed)
    try:
        lock = _lock(out)
    except OSError as exc:
        if not is_read_only(exc):
            raise
        return _sweep_read_only(exc, **plan)
    try:
        return _sweep_locked(Plan(**plan), refs, task_refs, executor, max_workers, progress)
    finally:
        lock.close()


def _check_options(measures: Sequence[str], options: Mapping) -> None:
    """Every option the engine and ``measures`` read, checked before any point (ValueError naming it)."""
    try:
        _make_params(1.0, 1.0, options)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"options: invalid PeelParams fields {[k for k in PARAM_OPTIONS if k in options]}: {exc}") \
            from None
    frozen = MappingProxyType(options)
    for name in measures:
        check = _OPTION_CHECKS.get(name)
        if check is not None:
            try:
                check(frozen)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"options (read by measure {name!r}): {exc}") from None


def _sweep_read_only(exc: OSError, **plan) -> SweepResult:
    """``out`` cannot be written: return its sweep if nothing is left to compute, else ValueError."""
    p = Plan(**plan)
    if p.manifest is not None and not p.todo:
        return _result(p)
    left = f"{len(p.todo)} of {p.total} points are still to compute" if p.manifest else "it holds no sweep yet"
    raise ValueError(f"out={p.out!r} is not writable ({exc}) and {left}: make it writable or use another directory")


def _sweep_locked(p: Plan, refs, task_refs, executor, max_workers, progress) -> SweepResult:
    out = p.out
    if p.manifest is None:
        p.manifest = {
            "format": FORMAT,
            "I_values": p.I_vals,
            "V_values": p.V_vals,
            "measures": p.measures,
            "options": p.options,
            "measure_refs": refs,
            "grid_order": "I major: results arrays are [i, j] for I_values[i], V_values[j]",
            "versions": versions(),
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        write_manifest(out, p.manifest)
    if p.retry:  # drop the failed points' records (and any partial tail) before computing them again
        rewrite_records(out, [r for r in p.records if (float(r["I"]), float(r["V"])) not in p.retry])
    elif p.partial:  # the last write was cut off: drop it so appends start on a clean line
        truncate_records(out, p.end)
    done, todo, total = p.done, p.todo, p.total
    report = _Stderr(total, len(done)) if progress is True else (progress or None)

    lost: list[tuple[tuple[float, float], str]] = []
    with append_records(out) as fh:
        def write(rec: dict) -> None:
            write_record(fh, rec)
            done[(rec["I"], rec["V"])] = rec
            if report:
                report(len(done), total, rec)

        if executor == "serial":
            for I, V in todo:
                write(_run_point(I, V, p.measures, p.options, task_refs))
        elif todo:
            own = executor is None
            if own:
                import multiprocessing

                n = max_workers or (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                                    else (os.cpu_count() or 1))
                ex = ProcessPoolExecutor(max_workers=max(1, min(n, len(todo))),
                                         mp_context=multiprocessing.get_context("spawn"),
                                         initializer=_worker_init, initargs=(os.getpid(),))
            else:
                ex = executor
            futs: dict[Future, tuple[float, float]] = {}
            try:
                for I, V in todo:
                    futs[ex.submit(_run_point, I, V, p.measures, p.options, task_refs)] = (I, V)
                for fut in as_completed(futs):
                    key = futs.pop(fut)
                    try:
                        rec = fut.result()
                    except Exception as exc:  # the executor lost the task (worker died, cancelled): not a result
                        lost.append((key, _error(exc)))
                        continue
                    if (float(rec["I"]), float(rec["V"])) != key:  # pragma: no cover - defensive
                        raise RuntimeError(f"executor returned the record of {rec['I'], rec['V']} for {key}")
                    write(rec)
            finally:
                for fut in futs:
                    fut.cancel()
                if own:
                    ex.shutdown(wait=not futs, cancel_futures=True)
    if lost:
        hint = ""
        if executor is None and any("BrokenProcessPool" in err for _, err in lost):
            hint = ("; a worker process died (crash, out of memory, killed) or could not start: with the 'spawn' "
                    "start method a script that calls sweep() must do so under `if __name__ == '__main__':`")
        raise RuntimeError(f"{len(lost)} of {len(todo)} points were lost by the executor (first: I={lost[0][0][0]}, "
                           f"V={lost[0][0][1]}: {lost[0][1]}); {len(done)}/{total} points are in "
                           f"{os.path.join(out, RESULTS)}; call sweep() again with the same arguments to compute "
                           "the rest" + hint)
    return _result(p)


def _result(p: Plan) -> SweepResult:
    return SweepResult(p.I_vals, p.V_vals, p.measures, p.options, p.done.values(), manifest=p.manifest, out=p.out)
