"""Reading a trajectory file (:meth:`exact.Trajectory.from_npz`): every field checked against its schema.

A ``.npz`` written by :meth:`exact.Trajectory.to_npz` holds the arrays ``t, alpha, omega, F, v`` (float, one length
n, 0 for a run saved with ``save="jumps"``, finite, ``t`` non-decreasing), ``branch`` (n integer codes into
:data:`peelapprox.BRANCHES`), optionally ``Vp`` (n finite floats, under a load), ``jumps`` (m rows of 8 finite
floats, the branch codes 0 or 1), ``atol`` (finite floats >= 0) and ``meta``, a JSON object (at most
:data:`MAX_META` characters) of exactly the fields of :data:`META_FIELDS`: ``params`` (a
:class:`peelapprox.PeelParams` as ``dataclasses.asdict`` writes it, checked by PeelParams itself), ``stats`` (the
counters of :class:`exact.SolverStats`: integers >= 0, times finite >= 0), ``method`` and ``solver`` (names:
letters, digits, ``_.-``, at most 64 characters; solver may be null), ``rtol`` in (0, 1), ``eps`` null or > 0,
``initial_state`` and ``final_state`` (the fields of :class:`exact.State`, finite, a branch name), ``t_end`` and
``t_transient`` finite >= 0 with ``t_transient <= t_end``, ``status`` an integer in [-99, 99] and ``message`` a
string of at most 2,000 characters (a JSON integer beyond the floats is not finite).  Before any array is loaded
the file's members are sized from their ``.npy`` headers and the zip's sizes: together at most
:data:`MAX_ARRAY_BYTES` (1 GiB), else refused, naming the array that passes it (a 1.9 MB file of 250,000,000
compressed zeros cost 2.3 GB before).  Nothing is unpickled (``allow_pickle=False``) and the JSON is parsed, never
evaluated.

A path that cannot be opened raises what :func:`open` raises (``FileNotFoundError``, ``PermissionError``,
``IsADirectoryError``, naming the path).  Every violation of the file's content is a ``ValueError`` beginning
``Trajectory.from_npz(<file>): field <name>``: a file that is not an ``.npz`` (truncated, another format), a
missing or unknown field, a wrong type, shape or length, a value out of its range.  What the probe found before:
``KeyError``, ``TypeError`` (unexpected keyword), ``RecursionError``, ``EOFError``, ``JSONDecodeError`` and
reshape errors naming no file, and ``t`` of 2 samples beside ``F`` of 150, a
payload string as branch, method or status, or ``t_end = -1`` accepted.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import zipfile
from typing import Any

import numpy as np

from peelapprox import BRANCHES, PeelParams
from peelapprox.validate import shown

__all__ = ["MAX_ARRAY_BYTES", "MAX_META", "META_FIELDS", "read_trajectory"]

#: The arrays of a trajectory file (``Vp`` only under a load).
ARRAYS = ("t", "alpha", "omega", "F", "v", "branch", "jumps", "atol", "meta")
#: The fields of its ``meta`` JSON object.
META_FIELDS = ("params", "stats", "method", "solver", "rtol", "eps", "initial_state", "final_state", "t_end",
               "t_transient", "status", "message")
#: The longest ``meta`` text [characters]: the parameters of a smoothed law with thousands of knots fit in 1 MB.
MAX_META = 4_000_000
#: The most bytes the arrays of a file may take once loaded, all together [bytes]: a run at the default
#: ``max_points`` (5e6) stores ~250 MB (49 bytes a point); a larger file is refused before it is read.
MAX_ARRAY_BYTES = 1 << 30
#: The longest message kept in a file [characters].
MAX_MESSAGE = 2_000
_NAME_CHARS = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-")


class _Bad(ValueError):
    """A field of the file that breaks its schema (the loader adds the file's name)."""

    def __init__(self, field: str, what: str) -> None:
        super().__init__(f"field {field}: {what}")


def read_trajectory(cls: Any, path: Any, parts: dict[str, Any]) -> Any:
    """:meth:`exact.Trajectory.from_npz`: the trajectory of the file ``path`` (module docstring), built by ``cls``
    from checked fields; ``parts`` holds the classes ``State``, ``SolverStats`` and ``Jumps``."""
    where = f"Trajectory.from_npz({shown(os.fspath(path) if isinstance(path, (str, os.PathLike)) else path)})"
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file path (str or os.PathLike), got {type(path).__name__}")
    try:
        arrays = _read_arrays(path)
        return cls(**_fields(arrays, parts))
    except _Bad as exc:
        raise ValueError(f"{where}: {exc}") from None
    except (FileNotFoundError, PermissionError, IsADirectoryError):  # the path, not the file's content: as open()
        raise
    except (OSError, EOFError, zipfile.BadZipFile, ValueError, OverflowError) as exc:  # not an npz, truncated, ...
        raise ValueError(f"{where}: not a trajectory file written by Trajectory.to_npz ({type(exc).__name__}: "
                         f"{shown(str(exc), 200)})") from None


def _read_arrays(path: Any) -> dict[str, np.ndarray]:
    """Every array of the file, each read on its own so that an error names it."""
    out = {}
    _check_sizes(path)
    with np.load(path, allow_pickle=False) as z:
        if not hasattr(z, "files"):
            raise _Bad("(file)", "a single .npy array, not an .npz of a trajectory's fields")
        unknown = sorted(set(z.files) - set(ARRAYS) - {"Vp"})
        missing = [n for n in ARRAYS if n not in z.files]
        if unknown or missing:
            name = (missing or unknown)[0]
            raise _Bad(name, "missing" if missing else f"unknown (a trajectory file holds {', '.join(ARRAYS)}, Vp)")
        for name in z.files:
            try:
                out[name] = z[name]
            except (OSError, EOFError, zipfile.BadZipFile, ValueError, KeyError) as exc:
                raise _Bad(name, f"unreadable ({type(exc).__name__}: {shown(str(exc), 120)})") from None
    return out


def _check_sizes(path: Any) -> None:
    """Refuse, before any array is loaded, a file whose trajectory arrays would take more than
    :data:`MAX_ARRAY_BYTES`: each member's size is the larger of the zip's uncompressed size and what its
    ``.npy`` header declares (the shape times the item size, which numpy allocates before reading)."""
    if not zipfile.is_zipfile(path):
        return  # not a zip: np.load names what it is (a single .npy is refused as such)
    total = 0
    with zipfile.ZipFile(path) as zf:
        for info in zf.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
            if name not in ARRAYS and name != "Vp":
                continue  # refused by name when the file is read
            size = info.file_size
            if info.filename.endswith(".npy"):
                with zf.open(info) as fh:
                    size = max(size, _npy_bytes(name, fh))
            total += size
            if total > MAX_ARRAY_BYTES:
                raise _Bad(name, f"the arrays take {total} bytes up to this one, more than MAX_ARRAY_BYTES = "
                                 f"{MAX_ARRAY_BYTES} (checked from the file's headers, before loading)")


def _npy_bytes(name: str, fh: Any) -> int:
    """The bytes the ``.npy`` array in ``fh`` declares (its header's shape times its item size)."""
    from numpy.lib import format as npy

    try:
        version = npy.read_magic(fh)
        if version == (1, 0):
            shape, _, dtype = npy.read_array_header_1_0(fh)
        elif version == (2, 0):
            shape, _, dtype = npy.read_array_header_2_0(fh)
        else:
            raise ValueError(f".npy format version {version[0]}.{version[1]} (Trajectory.to_npz writes 1.0)")
    except (ValueError, EOFError, OSError, zipfile.BadZipFile) as exc:
        raise _Bad(name, f"unreadable ({type(exc).__name__}: {shown(str(exc), 120)})") from None
    return math.prod(int(d) for d in shape) * int(dtype.itemsize)


def _fields(a: dict[str, np.ndarray], parts: dict[str, Any]) -> dict[str, Any]:
    """The constructor's keywords from the file's arrays, each checked (module docstring)."""
    n = None
    cols = {}
    for name in ("t", "alpha", "omega", "F", "v") + (("Vp",) if "Vp" in a else ()):
        x = _floats(name, a[name], ndim=1)
        if n is not None and x.size != n:
            raise _Bad(name, f"{x.size} values, but t has {n}: the columns of a trajectory have one length")
        n = x.size
        cols[name] = x
    if np.any(np.diff(cols["t"]) < 0):
        raise _Bad("t", "decreases: stored times never decrease")
    branch = a["branch"]
    if branch.dtype.kind not in "iub" or branch.shape != (n,) or np.any((branch < 0) | (branch > 1)):
        raise _Bad("branch", f"must be {n} integer codes 0 (AB) or 1 (CD), got dtype {branch.dtype}, shape "
                             f"{branch.shape}")
    jumps = _floats("jumps", a["jumps"], ndim=None)
    if jumps.ndim != 2 or jumps.shape[1] != 8:
        raise _Bad("jumps", f"must be rows of 8 numbers (t, from, to, alpha, omega, F, v_before, v_after), got "
                            f"shape {jumps.shape}")
    if np.any((jumps[:, 1:3] != 0) & (jumps[:, 1:3] != 1)):
        raise _Bad("jumps", "a jump's branches must be the codes 0 (AB) or 1 (CD)")
    atol = _floats("atol", a["atol"], ndim=None)
    if atol.ndim > 1 or np.any(atol < 0):
        raise _Bad("atol", "must be a number or a vector of numbers >= 0")
    meta = _meta(a["meta"])
    return dict(cols, branch=branch.astype(np.int8), jumps=parts["Jumps"].from_buffer(jumps), atol=atol,
                stats=_stats(meta["stats"], parts["SolverStats"]), params=_params(meta["params"]),
                method=_name("method", meta["method"]), solver=_name("solver", meta["solver"], none=True),
                rtol=_number("rtol", meta["rtol"], lo=0.0, hi=1.0, open_lo=True, open_hi=True),
                eps=None if meta["eps"] is None else _number("eps", meta["eps"], lo=0.0, open_lo=True),
                initial_state=_state("initial_state", meta["initial_state"], parts["State"]),
                final_state=_state("final_state", meta["final_state"], parts["State"]),
                **_times(meta), status=_status(meta["status"]), message=_message(meta["message"]))


def _floats(name: str, x: np.ndarray, ndim: int | None) -> np.ndarray:
    if x.dtype.kind not in "fiu" or (ndim is not None and x.ndim != ndim):
        raise _Bad(name, f"must be a {ndim or ''}{'-D ' if ndim else ''}array of numbers, got dtype {x.dtype}, "
                         f"shape {x.shape}")
    x = np.asarray(x, dtype=float)
    bad = np.flatnonzero(~np.isfinite(x.ravel()))
    if bad.size:
        raise _Bad(name, f"value {x.ravel()[bad[0]]!r} at index {int(bad[0])} is not finite")
    return x


def _meta(raw: np.ndarray) -> dict[str, Any]:
    if raw.dtype.kind != "U" or raw.shape != ():
        raise _Bad("meta", f"must be one JSON text, got dtype {raw.dtype}, shape {raw.shape}")
    text = str(raw)
    if len(text) > MAX_META:
        raise _Bad("meta", f"{len(text)} characters, more than the {MAX_META} a trajectory's metadata has")
    try:
        meta = json.loads(text)
    except RecursionError:
        raise _Bad("meta", "JSON nested too deeply") from None
    except ValueError as exc:
        raise _Bad("meta", f"not JSON ({exc})") from None
    if not isinstance(meta, dict):
        raise _Bad("meta", f"must be a JSON object, got {type(meta).__name__}")
    missing = [k for k in META_FIELDS if k not in meta]
    unknown = sorted(set(meta) - set(META_FIELDS))
    if missing or unknown:
        which = f"meta.{(missing or unknown)[0]}"
        raise _Bad(which, "missing" if missing else f"unknown (the metadata holds {', '.join(META_FIELDS)})")
    return meta


def _number(name: str, x: Any, *, lo: float = -math.inf, hi: float = math.inf, open_lo: bool = False,
            open_hi: bool = False, integer: bool = False) -> Any:
    ok = isinstance(x, int) if integer else isinstance(x, (int, float))
    if isinstance(x, bool) or not ok:
        raise _Bad(f"meta.{name}", f"must be {'an integer' if integer else 'a number'}, got {shown(x, 60)}")
    try:
        finite = math.isfinite(x)
    except OverflowError:  # a JSON integer beyond the floats
        finite = False
    if not (finite and (x > lo if open_lo else x >= lo) and (x < hi if open_hi else x <= hi)):
        raise _Bad(f"meta.{name}", f"must be finite and in {'(' if open_lo else '['}{lo:g}, {hi:g}"
                                   f"{')' if open_hi else ']'}, got {shown(x, 60)}")
    return x


def _name(field: str, x: Any, none: bool = False) -> Any:
    if x is None and none:
        return None
    if not isinstance(x, str) or not 0 < len(x) <= 64 or not set(x) <= _NAME_CHARS:
        raise _Bad(f"meta.{field}", f"must be a name (letters, digits, _ . -; at most 64 characters), got "
                                    f"{shown(x, 60)}")
    return x


def _message(x: Any) -> str:
    if not isinstance(x, str) or len(x) > MAX_MESSAGE:
        raise _Bad("meta.message", f"must be a string of at most {MAX_MESSAGE} characters, got {shown(x, 60)}")
    return x


def _status(x: Any) -> int:
    return int(_number("status", x, lo=-99, hi=99, integer=True))


def _times(meta: dict[str, Any]) -> dict[str, float]:
    t_end = float(_number("t_end", meta["t_end"], lo=0.0))
    t_transient = float(_number("t_transient", meta["t_transient"], lo=0.0, hi=t_end))
    return {"t_end": t_end, "t_transient": t_transient}


def _record(field: str, x: Any, cls: Any) -> dict[str, Any]:
    """``x`` as the keywords of the dataclass ``cls``: a JSON object of its fields, the required ones present."""
    if not isinstance(x, dict):
        raise _Bad(f"meta.{field}", f"must be a JSON object, got {type(x).__name__}")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(x) - set(fields))
    missing = [n for n, f in fields.items() if n not in x and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if unknown or missing:
        name = (missing or unknown)[0]
        raise _Bad(f"meta.{field}.{name}", "missing" if missing else f"unknown (a {cls.__name__} has "
                                           f"{', '.join(fields)})")
    return x


def _stats(x: Any, cls: Any) -> Any:
    d = _record("stats", x, cls)
    for name, value in d.items():
        if name == "n_rejected" and value is None:
            continue
        _number(f"stats.{name}", value, lo=0.0, integer=name.startswith("n_"))
    return cls(**d)


def _state(field: str, x: Any, cls: Any) -> Any:
    d = _record(field, x, cls)
    for name, value in d.items():
        if name == "branch":
            if value not in BRANCHES:
                raise _Bad(f"meta.{field}.branch", f"must be one of {', '.join(BRANCHES)}, got {shown(value, 60)}")
        elif not (name == "Vp" and value is None):
            _number(f"{field}.{name}", value)
    return cls(**d)


def _params(x: Any) -> PeelParams:
    d = _record("params", x, PeelParams)
    try:
        return PeelParams(**d)
    except (TypeError, ValueError) as exc:
        raise _Bad("meta.params", shown(str(exc), 300)) from None
    except RecursionError:
        raise _Bad("meta.params", "nested too deeply") from None
