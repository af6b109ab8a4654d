"""The refactor oracle: bitwise reference outputs of the public functions, and their comparison.

A refactor that should not change numbers is proved by running this before and after and comparing::

    git worktree add /tmp/ref <base>
    cd /tmp && PYTHONPATH=/tmp/ref python /path/to/comparisons/oracle.py write /tmp/before
    cd /tmp && PYTHONPATH=<tree> python -m comparisons.oracle write /tmp/after
    python -m comparisons.oracle compare /tmp/before /tmp/after      # exit 0: IDENTICAL

(run from a directory outside both trees, with ``PYTHONPATH`` naming the tree, so that an editable install
of another checkout is not what gets imported; the module imports only public names of ``peelapprox`` and
``exact``, so the same file can be run against an older tree).

What it records (:func:`write`): six hybrid runs (both geometries, ``t_eval``, ``save="jumps"``, a transient,
loose and tight rtol) with every stored array, every jump field and the solver counters; two regularised runs
(Radau and BDF, both geometries); the two-trajectory, tangent and return-map Lyapunov exponents; attractors;
the return map, force drops and periodicity of a run; a reduced segment, ``estimate`` and
``alpha_numerical``; an in-process two-point sweep; and ``peelapprox compare --format json``.  Wall and
compile times are left out.  :func:`compare` is exact: ``ndarray.tobytes()`` equality (sign of zero and NaN
payloads included) and equality of the JSON documents without their timing fields.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["write", "compare", "main"]

_TIMING = ("wall", "time_s", "seconds", "elapsed", "timing", "compile", "started", "finished", "host", "pid")


def _trajectory(arrays: dict, name: str, tr) -> None:
    import exact

    for a in ("t", "alpha", "omega", "F", "v", "branch"):
        arrays[f"{name}.{a}"] = np.asarray(getattr(tr, a))
    for a in exact.Jumps.FIELDS:
        arrays[f"{name}.jumps.{a}"] = np.asarray(getattr(tr.jumps, a))
    for a in ("n_steps", "n_rejected", "n_rhs", "n_jumps", "n_jac", "n_lu"):
        value = getattr(tr.stats, a)  # None where the solver does not count it: NaN in the file (no pickle)
        arrays[f"{name}.stats.{a}"] = np.asarray(np.nan if value is None else value)


def write(out: str | os.PathLike) -> int:
    """Run the reference calls and write ``arrays.npz``, ``sweep.json`` and ``compare.json`` into ``out``.

    Returns the number of arrays written.  Takes ~20 s on one core.
    """
    import exact
    import peelapprox as p

    P = p.PeelParams
    d = Path(out)
    d.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, np.ndarray] = {}
    runs = {
        "h1": (P(I=1e-5, V=1.0), 5.0, {}),
        "h2": (P(I=1e-3, V=1.0), 20.0, {"rtol": 1e-10}),
        "h3": (P(I=1e-4, V=2.0, geometry="exact"), 5.0, {"alpha0": 0.1}),
        "h4": (P(I=1e-5, V=1.0), 2.0, {"t_eval": np.linspace(0, 2, 501)}),
        "h5": (P(I=1e-5, V=1.0), 2.0, {"save": "jumps"}),
        "h6": (P(I=1e-2, V=0.5), 3.0, {"t_transient": 1.0, "rtol": 1e-6}),
        "r1": (P(I=1e-3, V=1.0), 2.0, {"method": "regularized", "eps": 1e-4}),
        "r2": (P(I=1e-3, V=1.0, geometry="exact"), 2.0, {"method": "regularized", "eps": 1e-4, "solver": "BDF"}),
    }
    for name, (params, t_end, kw) in runs.items():
        _trajectory(arrays, name, exact.simulate(params, t_end, **kw))
    pp = P(I=1e-3, V=1.0)
    r = p.lyapunov(pp, t_transient=5.0, n=300, n_discard=20)
    arrays["lyapunov.two_trajectory"] = np.asarray([r.per_s, r.bits_per_s, r.stderr_bits, r.n_jumps])
    r = p.lyapunov_tangent(pp, t_transient=5.0, T=5.0)
    arrays["lyapunov.tangent"] = np.asarray([r.per_s, r.stderr_bits])
    r = p.lyapunov_return_map(pp, t_transient=5.0, n_returns=100)
    arrays["lyapunov.return_map"] = np.asarray([r.per_s, r.stderr_bits])
    atts = p.attractors(pp, (0.0, 0.2), t_transient=5.0, window=5.0)
    arrays["attractors"] = np.asarray([[a.period if a.period is not None else -1, len(a.starts), *a.F_range,
                                        *a.signature[:3]] for a in atts], dtype=float)
    tr = exact.simulate(pp, 20.0, t_transient=5.0, rtol=1e-10)
    arrays["return_map"] = np.asarray(p.return_map(tr))
    arrays["force_drops"] = np.asarray(p.force_drops(tr))
    per = p.periodicity(p.return_map(tr))
    arrays["periodicity"] = np.asarray([per.period if per.period else -1])
    seg = p.reduced_segment(P(I=1e-5, V=1.0), "AB", F_in=30.0, alpha_in=0.0, alphadot_in=0.0)
    for a in ("t", "v", "F", "alpha", "alphadot", "dt", "dF"):
        arrays[f"segment.{a}"] = np.asarray(getattr(seg, a))
    e = p.estimate(P(I=1e-5, V=1.0))
    arrays["estimate"] = np.asarray([x for x in vars(e).values() if isinstance(x, float)])
    arrays["alpha_numerical"] = np.asarray(p.alpha_numerical(P(I=1e-5, V=1.0), np.linspace(0, 0.01, 11),
                                                             F_in=30.0, alpha_in=0.01, alphadot_in=0.0))
    np.savez(d / "arrays.npz", **arrays)
    with tempfile.TemporaryDirectory() as tmp:
        res = p.sweep([1e-4, 1e-3], [1.0], ("regime", "period"), out=os.path.join(tmp, "s"), max_workers=0,
                      progress=False, options={"t_transient": 5.0, "window": 5.0})
        rows = [{k: v for k, v in rec.items() if not any(s in k for s in _TIMING)} for rec in res.records]
    (d / "sweep.json").write_text(json.dumps(rows, sort_keys=True, default=str))
    cp = subprocess.run([sys.executable, "-m", "peelapprox.cli", "compare", "--format", "json"],
                        capture_output=True, text=True, check=True)
    (d / "compare.json").write_text(cp.stdout)
    return len(arrays)


def _strip(o):
    if isinstance(o, dict):
        return {k: _strip(v) for k, v in o.items() if not any(s in k.lower() for s in _TIMING)}
    if isinstance(o, list):
        return [_strip(v) for v in o]
    return o


def compare(a: str | os.PathLike, b: str | os.PathLike) -> list[str]:
    """The differences between two :func:`write` outputs (empty: bitwise identical)."""
    A, B = Path(a), Path(b)
    diffs = []
    with np.load(A / "arrays.npz") as x, np.load(B / "arrays.npz") as y:
        if set(x.files) != set(y.files):
            diffs.append(f"array names differ: {sorted(set(x.files) ^ set(y.files))}")
        for k in sorted(set(x.files) & set(y.files)):
            u, w = x[k], y[k]
            if u.dtype != w.dtype or u.shape != w.shape or u.tobytes() != w.tobytes():
                diffs.append(f"array {k}")
    for f in ("compare.json", "sweep.json"):
        if _strip(json.loads((A / f).read_text())) != _strip(json.loads((B / f).read_text())):
            diffs.append(f)
    return diffs


def main(argv: list[str] | None = None) -> int:
    """``write OUT`` or ``compare A B``; exit status 1 when ``compare`` finds a difference."""
    import argparse

    ap = argparse.ArgumentParser(prog="python -m comparisons.oracle", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("write", help="run the reference calls into a directory").add_argument("out")
    c = sub.add_parser("compare", help="compare two written directories bitwise")
    c.add_argument("a")
    c.add_argument("b")
    args = ap.parse_args(argv)
    if args.cmd == "write":
        import peelapprox

        print(f"{write(args.out)} arrays written from {Path(peelapprox.__file__).parent}", file=sys.stderr)
        return 0
    diffs = compare(args.a, args.b)
    for line in diffs:
        print("DIFFERS:", line)
    print("IDENTICAL" if not diffs else f"{len(diffs)} differences")
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
