"""Compiled kernels are never stale and never need a writable cache (a stale kernel once gave wrong numbers silently).

Both tests run the package from a temporary copy in a subprocess, so the
repository's own numba cache is neither used nor touched.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import peelapprox._compiled._jit as J

ROOT = Path(__file__).resolve().parent.parent

#: Kernel pull force vs the numpy peel force and closure, for V = 1 at v = 0.1 m/s, alpha = 0.2; and the cache record
#: of a kernel compiled for an explicit signature with the law as a first-class function argument: with
#: ``{driver}`` the hybrid driver taking the law (``exact._hybrid_driver.driver(True)``, ~20 s to compile), else
#: ``pull_force_law`` (the same kind of kernel, compiled and cached by the same code path, in a second or two).
PROBE = """
import json, warnings
import numpy as np
warnings.simplefilter("always")
with warnings.catch_warnings(record=True) as w:
    import peelapprox, exact
    from peelapprox import PeelParams
    from peelapprox.law._paper import peel_force
    from peelapprox.kernels import paper_coefficients, paper_law
    from exact._hybrid import pull_force
    from exact._hybrid_driver import driver, pull_force_law
    if {driver}:
        run = driver(True)  # the driver taking the law as an argument: compiled or loaded from the cache here
    from exact._hybrid_driver import param_vector as _param_vector
    p = PeelParams(V=1.0, I=1e-5)
    kern = float(pull_force(0.2, 0.1, _param_vector(p, 1e-9)))
    kern_law = float(pull_force_law(0.2, 0.1, _param_vector(p, 1e-9), paper_law, paper_coefficients(1.0)))
    if not {driver}:
        run = pull_force_law  # compiled (or loaded) for its one signature by the call above
    run_hits, run_misses = sum(run.stats.cache_hits.values()), sum(run.stats.cache_misses.values())
    ref = float(peel_force(0.1, 1.0)) / (1.0 + float(p.closure(0.2)[0]))
    extra = {{}}
    if {simulate}:
        tr = exact.simulate(p, 0.01)
        extra = dict(res=float(np.max(np.abs(tr.constraint_residual(relative=True)))), n=len(tr.t))
print(json.dumps(dict(file=peelapprox.__file__, kern=kern, ref=ref, kern_law=kern_law, run_hits=run_hits,
                      run_misses=run_misses, n_run=len(run.signatures),
                      warnings=[type(x.message).__name__ for x in w], **extra)))
"""


def _copy_packages(dst: Path, keep_cache: bool = False) -> None:
    ignore = None if keep_cache else shutil.ignore_patterns("__pycache__")
    for pkg in ("peelapprox", "exact"):
        shutil.copytree(ROOT / pkg, dst / pkg, ignore=ignore)


def _probe(cwd: Path, env_extra: dict | None = None, simulate: bool = False, driver: bool = False) -> dict:
    import json

    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update({"PYTHONDONTWRITEBYTECODE": "1", "XDG_CACHE_HOME": str(cwd / "xdg"), **(env_extra or {})})
    code = PROBE.format(simulate=simulate, driver=driver)
    r = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert Path(out["file"]).resolve().is_relative_to(cwd.resolve()), out["file"]  # the copy, not the checkout
    return out


def test_every_kernel_source_is_hashed():
    """The tag covers every file compiled into kernels: a file of peelapprox/ or exact/ that calls the compiler
    (``kernel``/``njit``) or whose functions are wrapped by it must be listed.  Exact: a set comparison."""
    users = set()
    for pkg in ("peelapprox", "exact"):
        for f in (ROOT / pkg).rglob("*.py"):  # sub-packages too (a method named kernel, impl.kernel(...), is not one)
            text = f.read_text()
            if re.search(r"(?<![.\w])(?<!def )kernel\(|@kernel\b|\bnjit\b", text) and f.name != "_jit.py":
                users.add(f.relative_to(ROOT).as_posix())
    assert users <= set(J.KERNEL_SOURCES), users - set(J.KERNEL_SOURCES)
    assert {"peelapprox/_compiled/_generated.py", "peelapprox/_reduced/_alpha.py"} <= set(J.KERNEL_SOURCES)


def test_source_tag_changes_with_any_kernel_source(tmp_path):
    """Hypothesis: one changed byte in any kernel source changes the tag (SHA-256; a collision in 64 bits is
    not a tolerance but an impossibility for this test)."""
    _copy_packages(tmp_path)
    t0 = J.source_tag(tmp_path)
    assert t0 == J.SOURCE_TAG
    for rel in J.KERNEL_SOURCES:
        f = tmp_path / rel
        b = f.read_bytes()
        f.write_bytes(b + b"\n")
        assert J.source_tag(tmp_path) != t0, rel
        f.write_bytes(b)
    assert J.source_tag(tmp_path) == t0


@pytest.mark.parametrize("driver", [False, pytest.param(True, marks=pytest.mark.slow)], ids=["law_kernel", "driver"])
def test_changed_model_source_recompiles_the_kernel(tmp_path, driver):
    """after a change of one fvV coefficient in ``_generated.py`` the cached kernels used to be
    loaded unchanged (the pull force of the kernel then disagreed with the numpy law by ~37 N).  Hypothesis:
    the kernel follows the changed source.  The kernel and numpy evaluate the same expression, so they agree
    to rounding (1e-12 relative); the change of 400 v^0.35 -> 401 v^0.35 at v = 0.1 moves f by 0.447 N (F by 0.373 N),
    10^9 times that tolerance.  The same for the law passed as a function argument (``paper_law``
    and the driver taking it, ``exact._hybrid_driver.driver(True)``, compiled for an explicit signature): the driver is
    loaded from the cache by a second process (a cache hit, no miss, one signature) and compiled anew after the
    change (a miss).

    The default tier checks the cross-process hit and the recompilation on ``pull_force_law``, a kernel of the same
    kind as the driver (explicit signature, the law as a ``FunctionType`` argument, no reference counting),
    stamped and cached by the same code (``peelapprox._compiled._jit._dispatcher``); the driver itself
    (``driver=True``, two compilations of ~20 s) is slow: covered in the default tier by this test's
    ``law_kernel`` case, and its cross-process cache hit by
    tests/test_cold_start.py::test_first_simulate_imports_only_what_it_needs (the inlined driver, compiled by
    that module's first probe, loaded by a later process: the same rebound body and ``RUN_SIG``)."""
    _copy_packages(tmp_path)
    before = _probe(tmp_path, driver=driver)  # compiles, caches in $XDG_CACHE_HOME/peelapprox/numba (the private root)
    assert abs(before["kern"] - before["ref"]) <= 1e-12 * abs(before["ref"])
    assert before["kern_law"] == before["kern"]  # the paper law through the ABI is the inlined law, bitwise
    assert (before["run_hits"], before["run_misses"], before["n_run"]) == (0, 1, 1)
    assert list((tmp_path / "xdg" / "peelapprox" / "numba").glob("exact_*/*pull_force*.nbi")), "no cache written"
    assert not list(tmp_path.glob("*/__pycache__/*.nbi")), "numba wrote beside the package"
    again = _probe(tmp_path, driver=driver)
    assert (again["run_hits"], again["run_misses"], again["n_run"]) == (1, 0, 1)
    assert again["kern_law"] == before["kern_law"]
    gen = tmp_path / "peelapprox" / "_compiled" / "_generated.py"
    src = gen.read_text()
    assert src.count("400*x2") == 3  # f in peel_force_fp, peel_force_fpp, peel_force_lnv
    gen.write_text(src.replace("400*x2", "401*x2"))
    after = _probe(tmp_path, driver=driver)
    assert abs(after["ref"] - before["ref"]) > 0.3  # the numpy law did change ...
    assert abs(after["kern"] - after["ref"]) <= 1e-12 * abs(after["ref"])  # ... and so did the kernel
    assert after["kern_law"] == after["kern"]  # ... and the law of the ABI
    assert (after["run_hits"], after["run_misses"]) == (0, 1)  # the driver (pull_force_law) was compiled anew


@pytest.mark.parametrize("simulate", [False, pytest.param(True, marks=pytest.mark.slow)], ids=["kernels", "simulate"])
def test_import_and_simulate_without_writable_cache(tmp_path, simulate):
    """with no writable cache location (NUMBA_CACHE_DIR, HOME and XDG_CACHE_HOME unwritable,
    the packages' __pycache__ unusable) ``import peelapprox`` raised 'cannot cache function ...: no locator
    available'.  Hypothesis: import and a first simulate work, uncached, with exactly one KernelCacheWarning,
    and the result is right (CONSTR residual at rounding level, 1e-13 relative as in tests/test_exact.py).
    As root every directory is writable, so unwritability is made by paths that cannot be created: under
    /proc (procfs) and where a regular file stands in for ``__pycache__``.

    The default tier imports and compiles the probe's kernels uncached (``pull_force``, and ``pull_force_law``:
    an explicit signature with the law as a ``FunctionType`` argument, the drivers' kind), checks their value and
    the one warning; the first ``simulate`` (its hybrid driver compiled uncached, ~18 s of CPU) is slow: covered
    in the default tier by this test's ``kernels`` case (the uncached compilation of that kind of kernel) and by
    every default-tier ``simulate`` (the driver, compiled or loaded)."""
    _copy_packages(tmp_path)
    for pkg in ("peelapprox", "exact"):
        (tmp_path / pkg / "__pycache__").write_text("not a directory\n")
    nowhere = "/proc/peelapprox-no-such-dir"
    out = _probe(tmp_path, dict(NUMBA_CACHE_DIR=nowhere, HOME=nowhere, XDG_CACHE_HOME=nowhere), simulate=simulate)
    assert out["warnings"].count("KernelCacheWarning") == 1, out["warnings"]
    assert abs(out["kern"] - out["ref"]) <= 1e-12 * abs(out["ref"])
    assert out["kern_law"] == out["kern"]  # the law-argument kernel, compiled uncached, is the inlined law bitwise
    if simulate:
        assert out["n"] > 10 and out["res"] <= 1e-13


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs procfs for an uncreatable path")
def test_no_locator_is_really_unwritable():
    """Guard of the test above: numba cannot create a cache directory under /proc (else the test proves
    nothing).  Exact: the creation must raise OSError."""
    with pytest.raises(OSError):
        os.makedirs("/proc/peelapprox-no-such-dir/x", exist_ok=True)
