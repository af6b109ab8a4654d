"""Cold and warm start of each entry point, each in fresh processes with a fresh numba cache (a new user's first call).

``python -m comparisons.benchmark.cold_start [--json F] [--only NAME ...]`` runs every entry point of
:data:`ENTRY_POINTS` twice, each time in a new Python process: **cold**, with ``NUMBA_CACHE_DIR`` and
``PEELAPPROX_CACHE_DIR`` pointed at new empty directories (every kernel it needs is compiled), then **warm**, a
second process reusing those directories (every kernel is loaded from numba's on-disk cache).  Each row reports

* ``wall`` -- the whole process (interpreter start, imports, the call) as the parent measures it [s];
* ``call`` -- the entry point's own call after its imports, as the child measures it [s];
* ``cpu`` -- user + system CPU time of the child [s] (on a shared machine the least disturbed by other load);
* ``compiled`` -- numba compilations in the child (``numba:compile`` events, one per function and signature
  compiled, callees and numba's own helpers included): 0 when warm means the second process only loaded;
* ``loaded`` -- kernels loaded from the on-disk cache (numba's dispatcher cache hits).

With ``--first-call [NAME]`` (default ``simulate hybrid``) it prints the first-call table instead: the entry point's
first call in a new process for a **fresh install without warm-up** (empty caches), **after warm-up** (new empty
caches, ``exact.compile_kernels()`` -- what ``peelapprox warmup`` runs -- in one process, then the entry point in a
new one) and **warm** (a second process after the first), with cold/warm and after-warm-up/warm ratios.

The children use Python's bytecode cache (``__pycache__``, written by the first process that imports a module, as
in a user's installation) even where this process runs with ``PYTHONDONTWRITEBYTECODE``; ``--no-bytecode`` runs them
without it.

With ``--detail NAME`` the cold run of one entry point prints which functions compiled and their exclusive
compile time (its own time, the nested compilations of its callees excluded), largest first.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["ENTRY_POINTS", "measure", "first_call", "detail", "main"]

#: name -> (imports, the call): the code a new user's first call runs.
ENTRY_POINTS: dict[str, tuple[str, str]] = {
    "import peelapprox": ("import peelapprox", "pass"),
    "simulate hybrid": ("import exact\nfrom peelapprox import PeelParams",
                        "exact.simulate(PeelParams(V=1.0, I=1e-5), 1.0)"),
    "simulate regularized": ("import exact\nfrom peelapprox import PeelParams",
                             "exact.simulate(PeelParams(V=1.0, I=1e-5), 0.05, method='regularized')"),
    "peelapprox compare": ("import tempfile\nfrom peelapprox.cli import main",
                           "main(['compare', '--out', tempfile.mkdtemp()])"),
    "periodic_orbit": ("import exact\nfrom peelapprox import PeelParams",
                       "exact.periodic_orbit(PeelParams(V=1.0, I=1e-2))"),
    "lyapunov tangent": ("import exact\nfrom peelapprox import PeelParams",
                         "exact.lyapunov(PeelParams(V=2.0, I=1e-4), 'tangent', t_transient=1.0, T=5.0)"),
}

_CHILD = '''
import json, resource, time, sys, io, contextlib
t0 = time.perf_counter()
from numba.core import event
compiled = []
class _Count(event.Listener):
    def on_start(self, e):
        compiled.append(e.data["dispatcher"].py_func.__qualname__)
    def on_end(self, e):
        pass
event.register("numba:compile", _Count())
{imports}
t1 = time.perf_counter()
with contextlib.redirect_stdout(io.StringIO()):
    {call}
t2 = time.perf_counter()
import gc
from numba.core.registry import CPUDispatcher
loaded = sum(sum(d.stats.cache_hits.values()) for d in gc.get_objects() if issubclass(type(d), CPUDispatcher))
ru = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps(dict(imports=t1 - t0, call=t2 - t1, cpu=ru.ru_utime + ru.ru_stime, compiled=len(compiled),
                      loaded=loaded, names=compiled)))
'''

_DETAIL = '''
import collections, time
from numba.core import event
_stack, _rows = [], collections.defaultdict(lambda: [0, 0.0])
class _Timer(event.Listener):
    def on_start(self, e):
        _stack.append([e.data["dispatcher"].py_func.__qualname__, time.perf_counter(), 0.0])
    def on_end(self, e):
        name, t, child = _stack.pop()
        dt = time.perf_counter() - t
        _rows[name][0] += 1
        _rows[name][1] += dt - child
        if _stack:
            _stack[-1][2] += dt
event.register("numba:compile", _Timer())
{imports}
{call}
for name, (n, s) in sorted(_rows.items(), key=lambda kv: -kv[1][1]):
    print(f"{{s:8.3f}} s  {{n:3d}} x  {{name}}")
'''


def _run_child(code: str, env: dict[str, str]) -> dict:
    """Run ``code`` in a new interpreter with ``env``; its last stdout line (JSON) plus the process wall time."""
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=env["_COLD_CWD"])
    wall = time.perf_counter() - t
    if r.returncode != 0:
        raise RuntimeError(f"entry point failed:\n{r.stderr[-3000:]}")
    out = json.loads(r.stdout.strip().splitlines()[-1])
    out["wall"] = wall
    return out


#: Whether the children may read and write Python's bytecode cache (``__pycache__`` beside the sources), as a user's
#: installation does; ``--no-bytecode`` sets ``PYTHONDONTWRITEBYTECODE=1`` instead, so that every process compiles the
#: sources of the modules it imports that have no bytecode yet (~0.35 s CPU for peelapprox's and exact's, measured
#: with ``python -X importtime``/``cProfile``: docs/performance.md, "After `peelapprox warmup`").
BYTECODE = True


def _env(tmp: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    if not BYTECODE:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
    root = str(Path(__file__).resolve().parents[2])
    env.update(NUMBA_CACHE_DIR=str(tmp / "numba"), PEELAPPROX_CACHE_DIR=str(tmp / "laws"), MPLBACKEND="Agg",
               PYTHONPATH=os.pathsep.join([root] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]),
               _COLD_CWD=str(tmp))
    return env


def measure(name: str) -> dict:
    """Cold and warm run of the entry point ``name`` (:data:`ENTRY_POINTS`) in fresh caches: a dict with
    ``cold`` and ``warm`` (each: wall, imports, call, cpu, compiled, loaded, names)."""
    imports, call = ENTRY_POINTS[name]
    code = _CHILD.format(imports=imports, call=call)
    with tempfile.TemporaryDirectory(prefix="cold-start-") as d:
        env = _env(Path(d))
        cold = _run_child(code, env)
        warm = _run_child(code, env)
    return dict(name=name, cold=cold, warm=warm)


_WARMUP = "import exact\nr = exact.compile_kernels()\nassert r.status == 0, r.message\nprint('{}')"


def first_call(name: str = "simulate hybrid") -> dict:
    """The first-call rows of ``name`` (module docstring): ``fresh``, ``after_warmup``, ``warm`` (each as a row of
    :func:`measure`), and ``warmup`` (the warm-up process itself)."""
    imports, call = ENTRY_POINTS[name]
    code = _CHILD.format(imports=imports, call=call)
    with tempfile.TemporaryDirectory(prefix="cold-start-") as d:
        env = _env(Path(d))
        fresh = _run_child(code, env)
        warm = _run_child(code, env)
    with tempfile.TemporaryDirectory(prefix="cold-start-") as d:
        env = _env(Path(d))
        t = time.perf_counter()
        _run_child(_WARMUP, env)
        warmup = dict(wall=time.perf_counter() - t)
        after = _run_child(code, env)
    return dict(name=name, fresh=fresh, after_warmup=after, warm=warm, warmup=warmup, bytecode=BYTECODE)


def _first_call_table(r: dict) -> str:
    lines = [f"first call of `{r['name']}` in a new process (warm-up itself: {r['warmup']['wall']:.1f} s wall; "
             f"bytecode cache {'on' if r.get('bytecode', True) else 'off'})", "",
             "| state | wall [s] | call [s] | CPU [s] | compiled | loaded | wall / warm wall |", "|" + "---|" * 7]
    for key, label in (("fresh", "fresh install, no warm-up"), ("after_warmup", "after `peelapprox warmup`"),
                       ("warm", "warm (second process)")):
        x = r[key]
        lines.append(f"| {label} | {x['wall']:.2f} | {x['call']:.2f} | {x['cpu']:.2f} | {x['compiled']} | "
                     f"{x['loaded']} | {x['wall'] / r['warm']['wall']:.2f} |")
    return "\n".join(lines)


def detail(name: str) -> str:
    """The functions compiled by a cold run of ``name`` with their exclusive compile times (module docstring)."""
    imports, call = ENTRY_POINTS[name]
    with tempfile.TemporaryDirectory(prefix="cold-start-") as d:
        env = _env(Path(d))
        r = subprocess.run([sys.executable, "-c", _DETAIL.format(imports=imports, call=call)], env=env,
                           capture_output=True, text=True, cwd=d)
    if r.returncode != 0:
        raise RuntimeError(r.stderr[-3000:])
    return "\n".join(line for line in r.stdout.splitlines() if " s  " in line)


def _table(rows: list[dict]) -> str:
    head = ("| entry point | cold wall [s] | cold call [s] | cold CPU [s] | compiled | warm wall [s] | warm call [s] "
            "| warm CPU [s] | compiled / loaded |")
    lines = [head, "|" + "---|" * 9]
    for r in rows:
        c, w = r["cold"], r["warm"]
        lines.append(f"| {r['name']} | {c['wall']:.2f} | {c['call']:.2f} | {c['cpu']:.2f} | {c['compiled']} | "
                     f"{w['wall']:.2f} | {w['call']:.2f} | {w['cpu']:.2f} | {w['compiled']} / {w['loaded']} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """The command line (module docstring)."""
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.cold_start", description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, help="also write the rows as JSON to this file")
    ap.add_argument("--only", action="append", choices=list(ENTRY_POINTS), help="measure only this entry point "
                    "(repeatable; default: all)")
    ap.add_argument("--first-call", nargs="?", const="simulate hybrid", choices=list(ENTRY_POINTS), default=None,
                    help="print the first-call table (fresh install, after warm-up, warm) of this entry point "
                         "(default: simulate hybrid) and exit")
    ap.add_argument("--detail", choices=list(ENTRY_POINTS), help="print what a cold run of this entry point "
                    "compiles, with exclusive compile times, and exit")
    ap.add_argument("--no-bytecode", action="store_true", help="run the children with PYTHONDONTWRITEBYTECODE=1 "
                    "(each compiles the sources it imports); default: Python's bytecode cache, as installed")
    args = ap.parse_args(argv)
    global BYTECODE
    BYTECODE = not args.no_bytecode
    if args.detail:
        print(detail(args.detail))
        return 0
    if args.first_call:
        r = first_call(args.first_call)
        print(_first_call_table(r))
        if args.json:
            args.json.write_text(json.dumps(r, indent=1))
        return 0
    rows = []
    for name in args.only or list(ENTRY_POINTS):
        print(f"{name} ...", file=sys.stderr, flush=True)
        rows.append(measure(name))
    print(_table(rows))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
