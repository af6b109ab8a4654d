"""README.md's code runs: every ```python block, and every `peelapprox ...` line of its shell blocks.

* Each ```python block runs as a script of its own (``__main__``, a fresh namespace), in a temporary working
  directory of its own, and must exit 0 (a block is self-contained: README shows it as something to paste);
  the blocks run one after another in one process, which pays the imports once.
* In ```bash / ```sh / ```console blocks, lines joined at a trailing backslash and split at ``&&``, every
  command that starts with ``peelapprox`` (or ``python -m peelapprox``, run as the same) must exit 0;
  ``pip install ...`` and ``python -m pytest`` are not run (installing is the environment's business; the
  tests do not run themselves).  The cheap commands (under ~5 s each) run in the default tier, one after
  another in one process (the Python blocks' own, after them) through ``peelapprox.cli.main``, the console
  script's own entry point (the import is paid once, not ten times); each is a test of its own.  The long
  ones are marked slow, each in its own process, with their measured cost in ``SLOW``.  The README's
  ``my_tape.csv`` (your own tape) is written first: the paper's f(v, 1.2) at 30 points per decade of v in
  [1e-6, 31.6] m/s, a curve the example command can run on.
* Nothing is written outside the temporary directory (relative outputs such as ``--out sweep/`` land there).

The default tier runs one process: the Python blocks, then the cheap commands.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
TIMEOUT = 900  # s

# Commands too long for the default tier: a prefix of the command -> why (measured wall time, warm, 2 cores).
SLOW = {
    "peelapprox benchmark": "work-precision runs of every solver and the ε study (--quick), ~40 s",
    "peelapprox bifurcation": "a 21-point brute-force diagram and continued branches, ~55 s",
    "peelapprox dynamics": "Lyapunov exponents over 50-200 s of orbit, 8-12 s each",
    "peelapprox sweep": "16 exact runs of 50 s, ~11 s",
    "peelapprox figures": "the paper's Figs. 2-9, ~11 s",
    "peelapprox basins": "54 starts of 60 s each with their orbits, ~24 s",
    "peelapprox warmup": "compiles the first calls' kernels when not cached (--cpu generic: always in CI), ~80 s",
    "peelapprox infer": "a least-squares fit of I and k over tens of exact runs, 1-2 min",
}


def _blocks(langs: tuple[str, ...]) -> list[str]:
    """The fenced code blocks of README.md in those languages, in order."""
    return [body for lang, body in re.findall(r"^```(\w*)\n(.*?)^```", README.read_text(), re.S | re.M)
            if lang in langs]


def _commands() -> list[str]:
    """Every ``peelapprox ...`` command of the shell blocks (continuations joined, comments dropped)."""
    commands = []
    for block in _blocks(("bash", "sh", "console")):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.removeprefix("$ ")
            for part in line.split("&&"):
                words = shlex.split(part, comments=True)
                if words[:3] == ["python", "-m", "peelapprox"]:  # the same command as a module
                    words = words[2:]
                if words and words[0] == "peelapprox":
                    commands.append(shlex.join(words))
    return commands


PYTHON_BLOCKS = _blocks(("python",))
COMMANDS = _commands()
CHEAP = [c for c in COMMANDS if not any(c.startswith(prefix) for prefix in SLOW)]

# Runs, in this one process, the Python blocks given as JSON pairs (script file, working directory) in argv[2],
# one after another, each as ``python FILE`` would (``__main__``, a fresh namespace, in its own directory), then,
# in the directory argv[4], the cheap commands of argv[3] one by one through the console script's entry point,
# each with its own stdout and stderr; writes ``{"blocks": {script: [status, stderr tail]}, "commands": {command:
# [status, stderr tail]}}`` as JSON to argv[1].
_DRIVER = """
import contextlib, io, json, os, shlex, sys
sys.path.insert(0, os.path.join(os.environ["PYTHONPATH"].split(os.pathsep)[0], "tests"))
from _run_script import run_script
path, jobs, commands, cwd = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3]), sys.argv[4]
results = {"blocks": {}, "commands": {}}
for script, block_cwd in jobs:
    os.chdir(block_cwd)
    status, _, err = run_script(script, [])
    results["blocks"][script] = [status, err[-3000:]]
if "matplotlib.pyplot" in sys.modules:
    sys.modules["matplotlib.pyplot"].close("all")
if commands:
    os.chdir(cwd)
    from peelapprox.cli import main
for command in commands:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            status = main(shlex.split(command)[1:])
        except SystemExit as exc:
            status = exc.code
    results["commands"][command] = [status, err.getvalue()[-2000:]]
with open(path, "w") as f:
    json.dump(results, f)
"""


def _env() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH")) if p)
    return env


def _write_tape(directory: Path, seconds: float = 10.0) -> None:
    """The files the README's data lines read: ``my_tape.csv`` (``--force-table``: fvV at V = 1.2 m/s, 30 points
    per decade), ``pts.csv`` (``--smooth``: 60 points of fvV at V = 1.2 m/s over v in [1e-3, 31.6] m/s with 1 %
    seeded noise, as measured points would be) and ``trace.csv`` (``series``/``infer``: ``seconds`` of the pull
    force at V = 1 m/s, I = 1e-2 kg m², k = 1000 N/m after a 10 s transient, sampled at 10 kHz with 0.5 N of noise;
    10 s for the slow ``infer``, which fits I and k to it; 2 s for the default tier's ``series``, which reads it
    (65 slips, the period-8 return map) and writes its slips: ~1.4 s of CPU less than 10 s, run and read)."""
    import exact
    from peelapprox import PeelParams, peel_force

    v = np.logspace(-6, 1.5, 226)
    np.savetxt(directory / "my_tape.csv", np.c_[v, peel_force(v, 1.2)], delimiter=",", header="v,f", comments="")
    v = np.logspace(-3, 1.5, 60)
    f = peel_force(v, 1.2) * (1 + 0.01 * np.random.default_rng(36).standard_normal(v.size))
    np.savetxt(directory / "pts.csv", np.c_[v, f], delimiter=",", header="v,f", comments="")
    grid = 10.0 + np.arange(round(seconds * 1e4)) / 1e4
    tr = exact.simulate(PeelParams(V=1.0, I=1e-2), 10.0 + seconds, t_eval=grid)
    tr.as_series(1e4, noise=0.5, seed=7).to_csv(str(directory / "trace.csv"))


def _collect(proc: subprocess.Popen) -> tuple[int, str, str]:
    try:
        stdout, stderr = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        proc.kill()
        stdout, stderr = proc.communicate()
    return proc.returncode, stdout, stderr


@pytest.fixture(scope="module")
def started(request, tmp_path_factory):
    """The selected default-tier work of this module, all started at once in one process (:data:`_DRIVER`): the
    Python blocks (each in its own directory, one after another), then the cheap commands (in a directory of
    their own, with the README's data files).  ``started(key)`` waits for the process and gives ``(status,
    results, stderr)``: for ``"blocks"`` the results are ``{script: [status, stderr tail]}``, for ``"commands"``
    ``{command: [status, stderr tail]}``; the process's stdout in their place when it failed.  One process, not
    two: the interpreter and the imports are paid once (under pytest-xdist the other core runs other tests)."""
    selected = [item.name for item in request.session.items if item.module is request.module]
    blocks = []
    for i, block in enumerate(PYTHON_BLOCKS):
        if f"test_python_block[{i}]" in selected:
            d = tmp_path_factory.mktemp(f"block{i}")
            (d / f"block{i}.py").write_text(block)
            blocks.append((str(d / f"block{i}.py"), str(d)))
    commands = CHEAP if any(name.startswith("test_cheap_command") for name in selected) else []
    d = tmp_path_factory.mktemp("commands")
    if commands:
        _write_tape(d, seconds=2.0)
    proc = None
    if blocks or commands:
        proc = subprocess.Popen([sys.executable, "-c", _DRIVER, str(d / "results.json"), json.dumps(blocks),
                                 json.dumps(commands), str(d)], cwd=d, env=_env(), text=True,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    done: list[tuple] = []

    def get(key: str) -> tuple:
        if not done:
            status, stdout, stderr = _collect(proc)
            done.append((status, json.loads((d / "results.json").read_text()) if status == 0 else stdout, stderr))
        status, results, stderr = done[0]
        return status, results[key] if status == 0 else results, stderr

    yield get
    if proc is not None and proc.poll() is None:
        proc.kill()
        proc.communicate()


def test_readme_has_code():
    """The extraction finds what README shows (3 Python blocks and ~18 commands today): a change of fences
    that hid them from these tests would fail here."""
    assert len(PYTHON_BLOCKS) >= 3 and len(COMMANDS) >= 15 and len(CHEAP) >= 8
    assert all(any(c.startswith(prefix) for c in COMMANDS) for prefix in SLOW), "a SLOW entry matches nothing"


@pytest.mark.parametrize("index", range(len(PYTHON_BLOCKS)))
def test_python_block(started, index):
    """README's ``index``-th Python block runs to the end (exit status 0) as a script of its own."""
    status, results, stderr = started("blocks")
    assert status == 0, f"the driver failed:\n{stderr[-3000:]}"
    code, err = next(v for k, v in results.items() if k.endswith(f"block{index}.py"))
    assert code == 0, f"README python block {index} failed:\n{PYTHON_BLOCKS[index]}\n{err}"


@pytest.mark.parametrize("command", CHEAP)
def test_cheap_command(started, command):
    """A cheap README command exits 0 (run in the shared driver process; see the module docstring)."""
    status, results, stderr = started("commands")
    assert status == 0, f"the driver failed:\n{stderr[-3000:]}"
    code, err = results[command]
    assert code in (0, None), f"{command} exited {code}:\n{err}"


@pytest.mark.slow
@pytest.mark.parametrize("command", [c for c in COMMANDS if c not in CHEAP])
def test_slow_command(tmp_path, command):
    """A long README command exits 0 in its own process (``SLOW`` gives each one's cost)."""
    _write_tape(tmp_path)
    proc = subprocess.Popen([sys.executable, "-c", "import sys; from peelapprox.cli import main; sys.exit(main())",
                             *shlex.split(command)[1:]], cwd=tmp_path, env=_env(), text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    status, stdout, stderr = _collect(proc)
    assert status == 0, f"{command} exited {status}:\n{stderr[-3000:]}"
