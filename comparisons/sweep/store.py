"""The on-disk format of a sweep: the output directory ``out`` and its three files.

``out/sweep.json``, the manifest: grid values, measures, options, each measure's import reference, package
versions, creation time; written once, atomically, before the first point.  ``out/results.jsonl``: one JSON
object per finished point, in completion order: ``I``, ``V``, ``status``, then the measures' keys (no timings
or host names: the same inputs give the same records; non-finite floats as ``NaN``/``Infinity``).
``status`` is ``"ok"`` when every measure is, else the first ``"error: <Type>: <message>"`` of a measure that
raised (recorded as ``"<name>_status"`` too; the others still run), else the first non-ok status a measure
reported (e.g. ``"breakdown:no_root"``, a result).  Error points count as finished on resume;
``retry_failed`` drops their records (rewriting the file atomically) and computes them again.
``out/.lock`` is held (``flock``) while a sweep writes, so two sweeps cannot share ``out``.

Every file is opened without following a symbolic link (``os.O_NOFOLLOW``) and must be a regular file, so
a link planted in the output directory cannot redirect a write (or a read) out of it.  Whatever is read is
checked before use: a crafted or corrupted manifest or record is one ``ValueError`` saying which file (and
line) is malformed and why, never another exception further on.  A directory this process cannot write is
read only: a complete sweep there is returned, computing anything there is a ValueError.
"""

from __future__ import annotations

import errno
import json
import math
import os
import stat
import sys
import warnings
from collections.abc import Iterable, Mapping, Sequence
from typing import IO, Any

from peelapprox import PeelForce
from peelapprox.io import fmt_number, jsonable
from peelapprox.validate import reals

from .law import describe, manifest_law

__all__ = [
    "MANIFEST", "RESULTS", "LOCK", "FORMAT", "RESERVED", "TEMPORARY", "GRID_RTOL",
    "versions", "is_read_only", "check_axis", "compare_manifest",
    "read_manifest", "write_manifest", "read_records", "append_records", "write_record", "truncate_records",
    "rewrite_records",
    "lock", "failed", "point_key", "Plan",
]

MANIFEST = "sweep.json"
RESULTS = "results.jsonl"
LOCK = ".lock"
FORMAT = "peelapprox.sweep/1"
#: Files being replaced atomically (``os.replace``); a leftover one is ignored.
TEMPORARY = (MANIFEST + ".tmp", RESULTS + ".tmp")
#: Reserved record keys (set by the engine, not by measures).
RESERVED = ("I", "V", "status")
#: Grid values of a resumed sweep may differ from the manifest's by this relative amount (a grid rebuilt by
#: ``geomspace`` on another machine); the manifest's values are then used, so record keys stay exact.
GRID_RTOL = 1e-12

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_EXTRA = _NOFOLLOW | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NONBLOCK", 0)  # NONBLOCK: never hang on a FIFO


def versions() -> dict:
    """Versions of Python and the packages whose changes could change a record."""
    from importlib import metadata

    v: dict[str, str | None] = {"python": sys.version.split()[0]}
    for pkg in ("peelapprox", "numpy", "scipy", "numba"):
        try:
            v[pkg] = metadata.version(pkg)
        except Exception:
            v[pkg] = None
    return v


def is_read_only(exc: OSError) -> bool:
    """Whether ``exc`` means "this process may not write there" (permissions, a read-only file system)."""
    return isinstance(exc, PermissionError) or exc.errno in (errno.EROFS, errno.EACCES, errno.EPERM)


# --------------------------------------------------------------------------------------------- opening files

def _open(out: str, name: str, flags: int, mode: int = 0o644) -> int:
    """``os.open(out/name)`` without following a symbolic link; ValueError unless it is a regular file."""
    path = os.path.join(out, name)
    try:
        fd = os.open(path, flags | _EXTRA, mode)
    except OSError:
        if os.path.islink(path):
            raise ValueError(f"out={out!r}: {name} is a symbolic link ({path} -> {os.readlink(path)}); sweep files "
                             "are never opened through a link, which could lead out of the directory: "
                             "replace it by the file itself") from None
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise ValueError(f"out={out!r}: {name} is not a regular file ({path})")
    return fd


def _read(out: str, name: str) -> bytes:
    fd = _open(out, name, os.O_RDONLY)
    with os.fdopen(fd, "rb") as fh:
        return fh.read()


def _fsync_dir(path: str) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # pragma: no cover - e.g. Windows
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


def _replace(out: str, name: str, text: str) -> None:
    """Write ``out/name`` atomically: a fresh temporary file (never a link), fsync, rename, fsync the directory."""
    tmp = name + ".tmp"
    try:
        os.unlink(os.path.join(out, tmp))  # a leftover (or a planted link: unlink removes the link itself)
    except FileNotFoundError:
        pass
    fd = _open(out, tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(os.path.join(out, tmp), os.path.join(out, name))
    _fsync_dir(out)


def lock(out: str) -> IO:
    """Hold ``out/.lock`` (``flock``) for the caller's lifetime of the returned file; RuntimeError if held.

    OSError if the file cannot be opened for writing (see :func:`is_read_only`).
    """
    fh = os.fdopen(_open(out, LOCK, os.O_RDWR | os.O_CREAT), "a+")
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows: no protection against two writers
        return fh
    try:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        raise RuntimeError(f"out={out!r} is in use by another sweep (lock {os.path.join(out, LOCK)} is held)") \
            from None
    return fh


# --------------------------------------------------------------------------------------------- the grid

def check_axis(name: str, values, lo: float = 0.0, hi: float = math.inf) -> list[float]:
    """A grid axis as a list of floats: non-empty, finite, in ``(lo, hi]`` (``(0, inf)`` by default), no repeats.

    Raises ArgumentTypeError (a TypeError and ValueError) for values that are not real numbers (None,
    strings, bools), ValueError naming ``name`` otherwise (:func:`peelapprox.validate.reals`).
    """
    lo_open = lo == 0.0
    arr = reals(name, values, lo, hi, lo_open=lo_open).ravel()
    vals = [float(x) for x in arr]
    if len(set(vals)) != len(vals):
        dup = sorted({x for x in vals if vals.count(x) > 1})
        raise ValueError(f"{name} must not repeat a value, got duplicates {dup}")
    return vals


def _close(a: Sequence[float], b: Sequence[float]) -> bool:
    return len(a) == len(b) and all(abs(x - y) <= GRID_RTOL * max(abs(x), abs(y)) for x, y in zip(a, b))


def _describe(vals: Sequence[float]) -> str:
    return f"{len(vals)} values [{fmt_number(vals[0], 6)} .. {fmt_number(vals[-1], 6)}]" if len(vals) > 3 \
        else str(list(vals))


def compare_manifest(m: dict, I_vals, V_vals, measures, options, out: str, force: PeelForce | None = None,
                     coef: tuple[str, list[float]] | None = None) -> None:
    """ValueError naming every difference between a (checked) manifest and the requested sweep (its law
    ``force``, default the paper's, and coefficient axis ``coef`` included: :mod:`comparisons.sweep.law`)."""
    diffs = []
    old_force, old_coef = manifest_law(m)
    force = PeelForce.paper() if force is None else force
    if old_force != force:
        diffs.append(f"force: existing {old_force!r}, requested {force!r}")
    if (old_coef is None) != (coef is None) or (old_coef is not None and coef is not None and (
            old_coef[0] != coef[0] or not _close(old_coef[1], coef[1]))):
        diffs.append(f"coef: existing {describe(old_coef)}, requested {describe(coef)}")
    for name, old, new in (("I_values", m["I_values"], I_vals), ("V_values", m["V_values"], V_vals)):
        if not _close(old, new):
            diffs.append(f"{name}: existing {_describe(old)}, requested {_describe(new)}")
    if list(m["measures"]) != list(measures):
        diffs.append(f"measures: existing {list(m['measures'])}, requested {list(measures)}")
    old_o, new_o = m["options"], jsonable(options, keep_nonfinite=True)
    if old_o != new_o:
        keys = sorted(set(old_o) | set(new_o))
        parts = [f"{k!r}: existing {old_o.get(k, '<unset>')!r}, requested {new_o.get(k, '<unset>')!r}"
                 for k in keys if old_o.get(k, "<unset>") != new_o.get(k, "<unset>")]
        diffs.append("options differ in " + "; ".join(parts))
    if diffs:
        raise ValueError(f"out={out!r} holds a different sweep, cannot resume: " + "; ".join(diffs)
                         + ". Use another out directory (or delete this one).")


# --------------------------------------------------------------------------------------------- manifest

def _short(v: Any) -> str:
    r = repr(v)
    return r if len(r) <= 60 else r[:57] + "..."


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _manifest_problem(m: Any) -> str | None:
    """Why ``m`` is not a manifest this version can use, or None."""
    if not isinstance(m, dict):
        return f"not a JSON object but {type(m).__name__}"
    if m.get("format") != FORMAT:
        return f"format is {_short(m.get('format'))}, expected {FORMAT!r}"
    for axis in ("I_values", "V_values"):
        vals = m.get(axis)
        if not isinstance(vals, list) or not all(_is_number(x) for x in vals):
            return f"{axis} must be a list of numbers, got {_short(vals)}"
        try:
            check_axis(axis, vals)
        except ValueError as exc:
            return str(exc)
    ms = m.get("measures")
    if not isinstance(ms, list) or not ms or not all(isinstance(x, str) and x for x in ms) or len(set(ms)) != len(ms):
        return f"measures must be a non-empty list of distinct names, got {_short(ms)}"
    if not isinstance(m.get("options"), dict):
        return f"options must be a JSON object, got {_short(m.get('options'))}"
    refs = m.get("measure_refs", {})
    if not isinstance(refs, dict) or not all(isinstance(v, str) for v in refs.values()):
        return f"measure_refs must map names to strings, got {_short(refs)}"
    if not isinstance(m.get("versions", {}), dict):
        return f"versions must be a JSON object, got {_short(m.get('versions'))}"
    try:
        manifest_law(m)
    except (TypeError, ValueError) as exc:
        return str(exc)
    return None


def read_manifest(out: str) -> dict:
    """The manifest of ``out``, checked; ValueError if it is missing, unreadable or malformed."""
    path = os.path.join(out, MANIFEST)
    try:
        data = _read(out, MANIFEST)
    except OSError as exc:
        raise ValueError(f"out={out!r}: cannot read the manifest {path}: {exc}") from None
    try:
        m = json.loads(data)
    except (ValueError, RecursionError) as exc:
        why: str | None = f"not JSON ({exc})"
    else:
        why = _manifest_problem(m)
    if why:
        raise ValueError(f"out={out!r}: malformed manifest {path}: {why}; repair it or use another directory")
    return m


def write_manifest(out: str, manifest: dict) -> None:
    """Write the manifest atomically (it is written once, when a sweep starts)."""
    _replace(out, MANIFEST, json.dumps(manifest, indent=2) + "\n")


# --------------------------------------------------------------------------------------------- records

def point_key(rec: Mapping, coef: bool = False) -> tuple[float, ...]:
    """The grid point of a record: ``(I, V)``, or ``(I, V, coef)`` in a sweep with a coefficient axis."""
    return (float(rec["I"]), float(rec["V"]), float(rec["coef"])) if coef else (float(rec["I"]), float(rec["V"]))


def _scalar_problem(v: Any) -> bool:
    """Whether ``v`` is not a JSON scalar a float array can hold (float, int that fits a float, str, bool, null)."""
    if v is None or isinstance(v, (bool, str, float)):
        return False
    if isinstance(v, int):
        try:
            float(v)
            return False
        except OverflowError:
            pass
    return True


def _value_problem(v: Any) -> bool:
    """Whether ``v`` is neither a JSON scalar nor a list of them or of lists of them: a point's slice of an array
    (an atlas's observables per approximation, :mod:`comparisons.atlas`), at most two levels deep."""
    if not isinstance(v, list):
        return _scalar_problem(v)
    return any(any(isinstance(y, list) or _scalar_problem(y) for y in x) if isinstance(x, list) else
               _scalar_problem(x) for x in v)


def _record_problem(rec: Any, coef: bool = False) -> str | None:
    """Why ``rec`` is not a record, or None.  Values must be JSON scalars that a float array can hold, or lists
    of them (one or two levels: a measure's array at this point); with a coefficient axis (``coef``)
    ``rec["coef"]`` must be a finite number."""
    if not isinstance(rec, dict):
        return f"not a JSON object but {type(rec).__name__}"
    for key in ("I", "V", "coef") if coef else ("I", "V"):
        if key not in rec:
            return f"no {key}"
        v = rec[key]
        try:
            ok = _is_number(v) and math.isfinite(v)
        except OverflowError:
            ok = False
        if not ok:
            return f"{key} = {_short(v)} is not a finite number"
    if not isinstance(rec.get("status"), str):
        return f"status must be a string, got {_short(rec.get('status'))}"
    for key, v in rec.items():
        if _value_problem(v):
            return (f"{key} = {_short(v)} is not a JSON scalar (float, int, str, bool, null) or a list (of lists) "
                    "of them")
    return None


def read_records(out: str, coef: bool = False) -> tuple[list[dict], int, bool]:
    """Complete records of ``results.jsonl``, the byte length they span, and whether a partial tail follows.

    A last line without its newline (the process died while writing it) is ignored.  A malformed complete
    line raises ValueError naming the line (``coef``: the sweep has a coefficient axis, each record its value).
    """
    path = os.path.join(out, RESULTS)
    try:
        data = _read(out, RESULTS)
    except FileNotFoundError:
        return [], 0, False
    end = data.rfind(b"\n") + 1
    recs = []
    for n, line in enumerate(data[:end].splitlines(), start=1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
        except (ValueError, RecursionError) as exc:
            why: str | None = f"not JSON: {exc}"
        else:
            why = _record_problem(rec, coef)
        if why:
            raise ValueError(f"{path}, line {n}: malformed record ({why}); repair or remove the line to resume")
        recs.append(rec)
    return recs, end, end < len(data)


def failed(rec: Any) -> bool:
    """Whether a record's point failed (a measure raised), as opposed to ok or a reported non-ok result."""
    return str(rec.get("status", "")).startswith("error")


def _line(rec: dict) -> str:
    return json.dumps(rec, separators=(",", ":")) + "\n"


def append_records(out: str) -> IO:
    """``results.jsonl`` open for appending (created if absent); write lines with :func:`write_record`."""
    return os.fdopen(_open(out, RESULTS, os.O_WRONLY | os.O_APPEND | os.O_CREAT), "a")


def write_record(fh: IO, rec: dict) -> None:
    """Append one record and force it to disk."""
    fh.write(_line(rec))
    fh.flush()
    os.fsync(fh.fileno())


def truncate_records(out: str, end: int) -> None:
    """Cut ``results.jsonl`` to ``end`` bytes (drop a partial last line, so appends start on a clean line)."""
    fd = _open(out, RESULTS, os.O_RDWR)
    try:
        os.ftruncate(fd, end)
        os.fsync(fd)
    finally:
        os.close(fd)


def rewrite_records(out: str, recs: Iterable[dict]) -> None:
    """Replace ``results.jsonl`` atomically by ``recs`` (used to drop failed points before retrying them)."""
    _replace(out, RESULTS, "".join(_line(r) for r in recs))


# --------------------------------------------------------------------------------------------- a directory's state

class Plan:
    """What ``out`` holds and what is left to compute; reads only (so it also serves a read-only ``out``).

    ValueError if ``out`` holds another sweep (naming what differs), holds a sweep and ``resume`` is False,
    holds other files, or holds a malformed or linked file.  Attributes: ``manifest`` (None for a new sweep),
    ``I_vals, V_vals`` (the manifest's exact values), ``records, end, partial`` (:func:`read_records`),
    ``done`` (key -> record of the finished points), ``retry`` (keys of error points to compute again),
    ``todo`` (keys to compute, grid order), ``total``; ``force`` and ``coef`` the law and coefficient axis
    (:mod:`comparisons.sweep.law`; a key is ``(I, V)``, or ``(I, V, c)`` with a coefficient axis:
    :func:`point_key`).
    """

    def __init__(self, out: str, I_vals: list[float], V_vals: list[float], measures: Sequence[str],
                 options: Mapping[str, Any], resume: bool, retry_failed: bool, force: PeelForce | None = None,
                 coef: tuple[str, list[float]] | None = None) -> None:
        self.out, self.measures, self.options = out, measures, options
        self.force = PeelForce.paper() if force is None else force
        others = [f for f in os.listdir(out) if f not in (LOCK, *TEMPORARY)]
        if os.path.lexists(os.path.join(out, MANIFEST)):
            if not resume:
                raise ValueError(f"out={out!r} already holds a sweep and resume=False: refusing to overwrite it; "
                                 "pass resume=True to continue it, or use another directory")
            m = read_manifest(out)
            compare_manifest(m, I_vals, V_vals, measures, options, out, self.force, coef)
            I_vals, V_vals = [float(x) for x in m["I_values"]], [float(x) for x in m["V_values"]]
            coef = manifest_law(m)[1]
            mine = {k: v for k, v in versions().items() if k != "python"}
            theirs = {k: v for k, v in m.get("versions", {}).items() if k in mine}
            if theirs and theirs != mine:
                warnings.warn(f"resuming a sweep made with {theirs} under {mine}: records may mix versions",
                              RuntimeWarning, stacklevel=3)
            self.manifest: dict | None = m
        elif others:
            raise ValueError(f"out={out!r} is not empty and holds no sweep manifest ({MANIFEST}): "
                             f"refusing to write into it (found {sorted(others)[:5]})")
        else:
            self.manifest = None
        self.I_vals, self.V_vals, self.coef = I_vals, V_vals, coef
        self.records, self.end, self.partial = read_records(out, coef is not None)
        grid: list[tuple[float, ...]] = [(I, V) for I in I_vals for V in V_vals] if coef is None else \
            [(I, V, c) for I in I_vals for V in V_vals for c in coef[1]]
        on_grid = set(grid)
        done: dict = {}
        for rec in self.records:
            key = point_key(rec, coef is not None)
            if key in on_grid and key not in done:
                done[key] = rec
        self.retry = {k for k, rec in done.items() if failed(rec)} if retry_failed else set()
        self.done = {k: rec for k, rec in done.items() if k not in self.retry}
        self.todo = [k for k in grid if k not in self.done]
        self.total = len(grid)
