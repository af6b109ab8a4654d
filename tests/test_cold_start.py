"""A job compiles only the kernels it runs (a fast first call).

The tests run fresh interpreters on one numba cache of their own (``NUMBA_CACHE_DIR`` and ``PEELAPPROX_CACHE_DIR``
in a temporary directory), empty at the start, so the repository's own cache is neither used nor touched, and read
numba's own record of what was compiled: a dispatcher's ``signatures`` (empty: never compiled nor loaded), its
``stats.cache_hits``/``cache_misses`` and the ``numba:compile`` events.  Three processes in all, one after another
on that cache (the module's fixtures): a plain hybrid ``simulate`` on the empty cache (:data:`PROBE`), ``peelapprox
warmup``, then a user's first calls (:data:`FIRST_CALLS`, which repeats the first process's records at other
parameters).  No timing: the times are measured by ``python -m comparisons.benchmark.cold_start``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Prints, as JSON, which of the kernels a plain hybrid simulate must not need were compiled (or loaded), and
#: which of :data:`LAZY_MODULES` were imported after ``import peelapprox``, ``import exact``, the simulate, and
#: after the lazy public names were read; ``{then}``: more calls in the same process (:data:`FIRST_CALLS`), after
#: these records.
PROBE = """
import json, sys
from numba.core import event
rec = event.RecordingListener()
event.register("numba:compile", rec)
lazy = {lazy!r}
import peelapprox
after_peelapprox = sorted(m for m in lazy if m in sys.modules)
import exact
after_exact = sorted(m for m in lazy if m in sys.modules)
at_import = sum(1 for _, e in rec.buffer if e.is_start)
{job}
after_simulate = sorted(m for m in lazy if m in sys.modules)
import peelapprox.law._abi as A, peelapprox.law._table_jit as T, peelapprox._reduced._segment_kernel as SK
import peelapprox.kernels as K
import exact._hybrid_driver as HL, exact._tangent as TG
others = dict(paper_law=A.paper_law, table_law=T.table_law, pull_force_law=HL.pull_force_law,
              hybrid_law_driver=HL._DRIVERS[True], field_law=HL._field_law,
              segment_inlined=SK._RUNS[False], segment_law=SK._RUNS[True],
              tangent_inlined=TG._TO_FOLD[False], tangent_law=TG._TO_FOLD[True],
              regularized_field=K.regularized_field, regularized_field_jacobian=K.regularized_field_jacobian,
              regularized_law_field=K._regularized_field_law)
d = HL._DRIVERS[False]
compiled = {{k: len(f.signatures) for k, f in others.items()}}
names = (exact.periodic_orbit, peelapprox.burst_catalogue, peelapprox.attractors,  # the lazy names still resolve
         peelapprox.approximate_attractor)
out = dict(at_import=at_import, compiled=compiled, driver=len(d.signatures),
           hits=sum(d.stats.cache_hits.values()), misses=sum(d.stats.cache_misses.values()),
           n_jumps=int(tr.stats.n_jumps), n=len(tr.t), after_peelapprox=after_peelapprox, after_exact=after_exact,
           after_simulate=after_simulate, lazy_now=sorted(m for m in lazy if m in sys.modules))
{then}
print(json.dumps(out))
"""

JOB = "tr = exact.simulate(peelapprox.PeelParams(V=1.0, I=1e-2), 0.5)"


def _run(tmp: Path, args: list[str], extra: dict | None = None) -> str:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp / "numba"), PEELAPPROX_CACHE_DIR=str(tmp / "laws"),
               XDG_CACHE_HOME=str(tmp / "xdg"), PYTHONDONTWRITEBYTECODE="1", **(extra or {}))
    r = subprocess.run([sys.executable, *args], cwd=tmp, env=env, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    return r.stdout


def _last_json(stdout: str) -> dict:
    return json.loads(stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def shared(tmp_path_factory):
    """One temporary cache for the module, empty: the first probe compiles into it, the warm-up goes on from there
    (it then loads the driver the probe compiled instead of compiling it again), the first calls read it."""
    return tmp_path_factory.mktemp("cold")


@pytest.fixture(scope="module")
def first(shared):
    """:data:`PROBE` (a plain hybrid ``simulate``) on the empty :func:`shared` cache: it compiles."""
    return _last_json(_run(shared, ["-c", PROBE.format(job=JOB, lazy=LAZY_MODULES, then="")]))


@pytest.fixture(scope="module")
def after_warmup(first, shared):
    """``peelapprox warmup --format json`` on the cache :func:`first` left, then :data:`FIRST_CALLS` in a new
    process: ``(the warm-up's report, the first calls' records)``."""
    report = json.loads(_run(shared, ["-m", "peelapprox", "warmup", "--format", "json"]))
    return report, _last_json(_run(shared, ["-c", FIRST_CALLS]))


def test_plain_hybrid_simulate_compiles_only_the_hybrid_driver(first):
    """Hypothesis: importing ``peelapprox`` and ``exact`` compiles nothing (no numba compile event), and a plain
    hybrid ``simulate`` of the paper's law on an empty cache compiles its own driver only (one cache miss, no hit):
    the regularised fields, the tangent and segment drivers, the law-argument copies of the hybrid driver and the
    compiled laws (fvV as a law argument, the table) keep no signature.  Exact counts (numba's dispatcher records);
    the run itself is a real one (V = 1, I = 1e-2 jumps every ~0.1 s: at least one jump in 0.5 s).  That a later
    process loads this driver (a cache hit) and compiles nothing is checked on the first calls' process
    (:func:`test_first_simulate_imports_only_what_it_needs`), not in a process of its own (~2.5 s of CPU less)."""
    assert first["at_import"] == 0
    assert first["compiled"] == dict.fromkeys(first["compiled"], 0), first["compiled"]
    assert (first["driver"], first["misses"], first["hits"]) == (1, 1, 0)
    assert first["n_jumps"] >= 1


#: Modules a first hybrid ``simulate`` does not need, imported lazily by the code that does need them
#: (docs/performance.md, "After `peelapprox warmup`"): scipy's optimize (the folds' Brent search is
#: ``peelapprox/_brentq.py``), integrate and special, the rooms of ``exact`` other than solving, the burst statistics,
#: the reduced equations and a measured force trace, the regularised scheme, the pools, sympy, matplotlib and the
#: optional packages.  (``scipy.linalg`` is not listed: numba's own first cache load imports it, the BLAS check of
#: ``numba/np/arraymath.py``.)
LAZY_MODULES = ("scipy.optimize", "scipy.integrate", "scipy.special", "scipy.interpolate", "scipy.stats",
                "scipy.signal", "sympy", "matplotlib", "pandas", "loky", "hypothesis", "cloudpickle", "threadpoolctl",
                "exact.dynamics", "exact.orbits", "exact.front", "exact._regularized", "peelapprox.bursts",
                "peelapprox._reduced._approximate", "peelapprox._reduced._alpha", "peelapprox._measured._series",
                "peelapprox.parallel", "peelapprox.plotting", "comparisons")

#: A user's first calls after the README's set-up, other parameters than the warm-up's own (V = 1, I = 1e-5) and the
#: first probe's: :data:`PROBE`'s records of a plain hybrid ``simulate`` at V = 1.2, I = 1e-4 (6 jumps in 0.05 s),
#: then, in the same process, ``approximate_attractor``, ``attractor_observables`` and ``peelapprox doctor``
#: (through ``peelapprox.cli.main``, after the calls: it reads the cache); ``compile_events``: every function numba
#: compiled in the process.
FIRST_CALLS = PROBE.format(lazy=LAZY_MODULES, job="tr = exact.simulate(peelapprox.PeelParams(V=1.2, I=1e-4), 0.05)",
                           then="""
a = peelapprox.approximate_attractor(peelapprox.PeelParams(V=1.0, I=1e-2))
o = exact.attractor_observables(peelapprox.PeelParams(V=1.0, I=1e-5), t_transient=0.3, t_window=0.3)
import contextlib, io
from peelapprox.cli import main
with contextlib.redirect_stdout(io.StringIO()) as doctor:
    status = main(["doctor", "--format", "json"])
out.update(compile_events=[e.data["dispatcher"].py_func.__qualname__ for _, e in rec.buffer if e.is_start],
           doctor_status=status, doctor=json.loads(doctor.getvalue()))""")


def test_first_simulate_imports_only_what_it_needs(after_warmup):
    """Hypothesis: in a new process on a cache holding the driver, ``import peelapprox``, ``import exact`` and a
    first plain hybrid ``simulate`` import none of :data:`LAZY_MODULES`; reading a lazy public name
    (``exact.periodic_orbit``, ``peelapprox.burst_catalogue``, ``peelapprox.attractors``,
    ``peelapprox.approximate_attractor``) then imports its module.  The same process loads the driver the first
    probe compiled (one cache hit, no miss) and compiles nothing at import; the kernels a plain simulate does not
    need keep no signature (the cache now holds the warm-up's kernels too: none is loaded).  Structural, exact (the
    names in ``sys.modules``, numba's records); the time this saves is measured, not tested (docs/performance.md).
    Read in the first calls' process (numba's event module imported first, as the probe needs it: it imports none
    of them), before its other calls, rather than in a process of its own: one interpreter's start and imports,
    ~2.5 s of CPU, less."""
    got = after_warmup[1]
    assert got["after_peelapprox"] == got["after_exact"] == got["after_simulate"] == [], got
    assert got["n_jumps"] >= 1
    assert {"exact.orbits", "exact.dynamics", "peelapprox.bursts", "scipy.optimize",
            "peelapprox._reduced._approximate"} <= set(got["lazy_now"]), got
    assert got["at_import"] == 0
    assert (got["driver"], got["misses"], got["hits"]) == (1, 0, 1)
    assert got["compiled"] == dict.fromkeys(got["compiled"], 0), got["compiled"]


def test_after_warmup_the_first_calls_compile_nothing(after_warmup, shared):
    """Hypothesis: after ``peelapprox warmup`` (the README's set-up), a new process's first ``simulate``,
    ``approximate_attractor`` and ``attractor_observables`` (other parameters than the warm-up's) compile no
    function at all: every kernel they need is loaded from the private cache.  ``peelapprox doctor`` then says the
    cache is warm for this CPU, with a fresh record (run through ``peelapprox.cli.main`` in the first calls'
    process, after them: one interpreter's start, ~2 s of CPU, less).  The cache is the one the first probe left
    (holding its driver only): the warm-up's simulate loads that driver and compiles nothing, its other jobs compile.
    Exact counts (numba's compile events); no timing (measured by ``python -m comparisons.benchmark.cold_start``)."""
    report, out = after_warmup
    assert report["status"] == 0 and report["cache"] == str(shared / "numba"), report
    assert [j["name"] for j in report["jobs"]] == ["simulate", "approximate_attractor", "attractor_observables"]
    assert report["jobs"][0]["compiled"] == 0 and report["jobs"][0]["loaded"] >= 1, report["jobs"][0]
    assert sum(j["compiled"] for j in report["jobs"][1:]) > 0  # the rest of the cache was empty: it compiled
    assert out["compile_events"] == [] and out["n"] > 10, out["compile_events"]
    assert out["doctor_status"] == 0
    doc = out["doctor"]
    assert doc["verdict"].startswith("warm for this CPU"), doc["verdict"]
    assert [w["fresh"] and w["this_cpu"] for w in doc["warmups"]] == [True]
    assert doc["folders"] and all(f["problem"] is None and f["not_private"] == 0 for f in doc["folders"])


@pytest.mark.slow
def test_a_generic_warmup_serves_generic_processes(tmp_path):
    """Hypothesis: ``peelapprox warmup --cpu generic`` (compiled in a child with NUMBA_CPU_NAME=generic) makes a new
    process run with NUMBA_CPU_NAME=generic compile nothing for its first calls, and ``doctor`` in a process
    compiling for the host CPU says the warm-up is for another CPU (never "warm").  Exact counts.  Slow: a full
    compilation of the first calls."""
    report = json.loads(_run(tmp_path, ["-m", "peelapprox", "warmup", "--cpu", "generic", "--format", "json"]))
    assert report["status"] == 0 and report["cpu"] == "generic", report
    out = _last_json(_run(tmp_path, ["-c", FIRST_CALLS], {"NUMBA_CPU_NAME": "generic"}))
    assert out["compile_events"] == [], out["compile_events"]
    doc = json.loads(_run(tmp_path, ["-m", "peelapprox", "doctor", "--format", "json"]))
    assert doc["cpu"] != "generic" and "NUMBA_CPU_NAME=generic" in doc["verdict"], doc["verdict"]
