"""The warm-up's records and ``peelapprox doctor``'s verdicts (in this process; the warm-up itself, a new process's
first calls after it, and the CLI are tested in tests/test_cold_start.py)."""

from __future__ import annotations

import json
import os

import pytest

import peelapprox.kernels as K
from peelapprox._compiled._jit import SOURCE_TAG


@pytest.fixture
def root(tmp_path, monkeypatch):
    import numba

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "nb"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("PEELAPPROX_CACHE_DIR", str(tmp_path / "laws"))
    return tmp_path / "nb"


def _record(root, name: str, **change) -> None:
    import platform

    import numba

    rec = dict(source_tag=SOURCE_TAG, numba=numba.__version__, python=platform.python_version(), cpu=K.cpu_name(),
               written="2026-01-01T00:00:00Z", jobs=[dict(name="simulate")])
    rec.update(change)
    path = root / name
    path.write_text(json.dumps(rec))
    os.chmod(path, 0o600)


def test_record_warmup_is_private_and_read_back(root):
    """Hypothesis: ``record_warmup`` writes ``warmup-<cpu>.json`` mode 0600 in the private root, and the status reads
    it back as fresh and for this CPU (the verdict "warm").  Exact: modes, names and fields compared."""
    path = K.record_warmup([dict(name="simulate", seconds=1.0, compiled=3, loaded=0, error=None)])
    assert path is not None and path.parent == root and path.name.startswith("warmup-")
    assert (path.stat().st_mode & 0o777) == 0o600
    s = K.cache_status()
    assert s["kernel_root"] == str(root) and s["kernel_root_from"] == "NUMBA_CACHE_DIR"
    assert [(w["fresh"], w["this_cpu"], w["jobs"]) for w in s["warmups"]] == [(True, True, ["simulate"])]
    assert s["verdict"].startswith("warm for this CPU")


@pytest.mark.parametrize("change, says", [
    (dict(source_tag="0" * 16), "stale"),
    (dict(numba="0.0.1"), "stale"),
    (dict(cpu="some-other-cpu"), "this process compiles for"),
])
def test_a_stale_or_other_cpu_record_is_not_called_warm(root, change, says):
    """Hypothesis: a record of other kernel sources or another numba is stale (numba discards those kernels and
    compiles anew), one of another CPU is not this process's: neither gives the verdict "warm"."""
    K.cache_status()  # makes the root
    _record(root, "warmup-x.json", **change)
    s = K.cache_status()
    assert says in s["verdict"] and not s["verdict"].startswith("warm for")


def test_a_record_others_can_write_is_ignored(root):
    """Hypothesis: a record file writable by others (or not valid JSON) is not read: no warm-up is reported."""
    K.cache_status()
    _record(root, "warmup-a.json")
    os.chmod(root / "warmup-a.json", 0o666)
    (root / "warmup-b.json").write_text("{not json")
    os.chmod(root / "warmup-b.json", 0o600)
    s = K.cache_status()
    assert s["warmups"] == [] and s["verdict"].startswith("not warmed up")


def test_compile_kernels_checks_its_arguments():
    """Hypothesis: a blank or non-string CPU and a max_wall outside (0, 86400] s are ValueErrors naming them."""
    from exact import compile_kernels

    for bad in ("", " generic", 3):
        with pytest.raises(ValueError, match="cpu must be"):
            compile_kernels(cpu=bad)  # type: ignore[arg-type]
    for bad in (0, -1.0, float("nan"), 1e9):
        with pytest.raises(ValueError, match="max_wall must be"):
            compile_kernels(max_wall=bad)


def test_compile_kernels_refuses_unknown_calls():
    """Hypothesis: a call name outside FIRST_CALLS, an empty or repeated selection, or a list instead of a tuple is a
    ValueError listing the valid names."""
    from exact import compile_kernels

    for bad in (("nope",), (), ("simulate", "simulate"), ["simulate"]):
        with pytest.raises(ValueError, match="calls must be a tuple of distinct names from"):
            compile_kernels(calls=bad)  # type: ignore[arg-type]


def test_warmup_max_wall_defaults_to_600_seconds():
    """``peelapprox warmup --max-wall`` defaults to 600 s, as every subcommand's (tests/test_bounded.py), and says so
    in its help (exact value and text)."""
    import argparse

    from peelapprox.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices["warmup"]
    action = next(a for a in sub._actions if "--max-wall" in a.option_strings)
    assert action.default == 600.0 and "(default: 600)" in " ".join(sub.format_help().split())


def test_a_spent_budget_skips_the_jobs(monkeypatch):
    """Hypothesis: with the budget already spent (a clock that jumps 10 s per reading against max_wall=1 s) no job
    is started: every row says so, status 1, nothing recorded; the call returns (never hangs)."""
    import itertools

    import exact._warmup as W

    clock = itertools.count(0.0, 10.0)
    monkeypatch.setattr(W, "_clock", lambda: float(next(clock)))
    monkeypatch.setattr(W, "_DONE", {})
    r = W.compile_kernels(max_wall=1.0)
    assert r.status == 1 and r.record is None
    assert all(j["error"].startswith("TimeoutError: not run") and j["compiled"] == 0 for j in r.jobs)
