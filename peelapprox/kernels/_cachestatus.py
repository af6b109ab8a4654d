"""What the kernel cache holds, where, for which CPU, whether it is private and fresh (``peelapprox doctor``), and the
warm-up records that say so (``exact.compile_kernels``, ``peelapprox warmup``).

A warm-up record is a small JSON file, ``<kernel root>/warmup-<cpu>.json``, written by the process that ran the
warm-up (0600, by a new file renamed over the old): the kernel sources' tag
(:data:`peelapprox._compiled._jit.SOURCE_TAG`), the
numba and Python versions, the CPU name numba compiled for and what the warm-up compiled and loaded.  It is data,
read as JSON and only from a private file; numba's own files are never read here.  A record whose tag or versions
differ from this process's is *stale*: numba discards those kernels on load (their stamps differ) and compiles them
anew, so ``peelapprox warmup`` rebuilds them.
"""

from __future__ import annotations

import json
import os
import platform
import tempfile
import time
from pathlib import Path
from typing import Any

import numba
from numba.core import config as numba_config

from .._compiled._jit import SOURCE_TAG, caching_enabled
from .._compiled._kcache import kernel_root, root_problem
from .._compiled._private import dir_problem, file_problem, open_private

__all__ = ["cache_status", "cpu_name", "record_warmup"]

_MAX_RECORD = 1 << 16


def cpu_name() -> str:
    """The CPU numba compiles for in this process: ``NUMBA_CPU_NAME`` (``generic``: any machine of the
    architecture), else the host's."""
    name = getattr(numba_config, "CPU_NAME", None)
    if name:
        return str(name)
    import llvmlite.binding as ll  # type: ignore[import-untyped]

    return str(ll.get_host_cpu_name())


def _versions() -> dict[str, str]:
    return dict(source_tag=SOURCE_TAG, numba=numba.__version__, python=platform.python_version(),
                machine=platform.machine())


def record_warmup(jobs: list[dict[str, Any]]) -> Path | None:
    """Write this process's warm-up record (module docstring) with ``jobs`` (name, seconds, compiled, loaded,
    error of each); its path, or None when there is no private kernel cache."""
    root = kernel_root()
    if root is None or not caching_enabled():
        return None
    cpu = cpu_name()
    rec = dict(_versions(), cpu=cpu, written=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), jobs=jobs)
    path = root / f"warmup-{''.join(c if c.isalnum() or c in '-_.' else '_' for c in cpu)}.json"
    fd, tmp = tempfile.mkstemp(dir=root, prefix=".warmup-", suffix=".tmp")  # 0600
    try:
        with os.fdopen(fd, "w") as fh:
            json.dump(rec, fh, indent=1)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _read_record(path: Path) -> dict[str, Any] | None:
    fd, _ = open_private(path)
    if fd is None:
        return None
    with os.fdopen(fd, "rb") as fh:
        try:
            rec = json.loads(fh.read(_MAX_RECORD))
        except (ValueError, UnicodeDecodeError):
            return None
    return rec if isinstance(rec, dict) else None


def _folders(root: Path) -> list[dict[str, Any]]:
    rows = []
    for d in sorted(root.iterdir()):
        if d.name.startswith(".") or not d.is_dir() or d.is_symlink():
            continue
        index = data = size = bad = 0
        for f in d.iterdir():
            st = f.lstat()
            index += f.suffix == ".nbi"
            data += f.suffix == ".nbc"
            size += st.st_size
            bad += file_problem(st) is not None
        rows.append(dict(folder=d.name, problem=dir_problem(d.lstat()), kernels=index, data_files=data,
                         bytes=size, not_private=bad))
    return rows


def cache_status() -> dict[str, Any]:
    """What ``peelapprox doctor`` reports (module docstring): the kernel root and whether it is private (and what
    was refused), the law directory, the folders with their numbers of kernels and files (and files that would
    be refused), this process's CPU, tag and versions, the warm-up records with whether each is fresh and for
    this CPU, and a one-line ``verdict``."""
    from ..law._cache import cache_dir, law_dir

    root = kernel_root()
    env = getattr(numba_config, "CACHE_DIR", "") or ""
    out: dict[str, Any] = dict(_versions(), cpu=cpu_name(), kernel_root=str(root) if root else None,
                               kernel_root_from="NUMBA_CACHE_DIR" if env and root == Path(env) else "default",
                               refused=root_problem(), caching=caching_enabled() and root is not None,
                               law_dir=str(cache_dir()), law_dir_used=str(law_dir()), folders=[], warmups=[])
    if root is None:
        out["verdict"] = f"no private kernel cache ({out['refused']}): every new process compiles its kernels"
        return out
    out["folders"] = _folders(root)
    now = _versions()
    for path in sorted(root.glob("warmup-*.json")):
        rec = _read_record(path)
        if rec is None:
            continue
        fresh = all(rec.get(k) == now[k] for k in ("source_tag", "numba", "python"))
        out["warmups"].append(dict(file=path.name, cpu=rec.get("cpu"), written=rec.get("written"), fresh=fresh,
                                   this_cpu=rec.get("cpu") == out["cpu"],
                                   jobs=[j.get("name") for j in rec.get("jobs", []) if isinstance(j, dict)]))
    out["verdict"] = _verdict(out)
    return out


def _verdict(s: dict[str, Any]) -> str:
    w = s["warmups"]
    if any(r["fresh"] and r["this_cpu"] for r in w):
        return f"warm for this CPU ({s['cpu']}): the first calls load their kernels"
    other = [r["cpu"] for r in w if r["fresh"]]
    if other:
        return (f"warmed up for CPU {', '.join(map(str, other))}, but this process compiles for {s['cpu']}: set "
                f"NUMBA_CPU_NAME={other[0]} (or run peelapprox warmup)")
    if w:
        return "stale: peelapprox, numba or Python changed since the warm-up; run peelapprox warmup"
    return "not warmed up: the first call of each kind compiles; run peelapprox warmup"

