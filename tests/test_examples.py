"""The gallery docs/examples/ runs: every script exits 0, writes its figure and prints the numbers it promises.

Each example runs as a user would run it, ``python docs/examples/NAME.py --out DIR`` (in a temporary working
directory, so nothing lands in ./docs): as ``__main__`` with its own argv and a fresh namespace, several in
one process (``_DRIVER``, :data:`BATCHES`), and at least one printed number is checked against
an expectation that does not come from the code under test: the paper's numbers, closed forms, or the values
docs/*.md report (measured once and written down there).  The examples of this module's run are started
together when the first test needs one, batched in processes (:data:`BATCHES`), so a run pays the interpreter,
the imports and the kernel loads once per batch, not once per example.  The default tier runs the four cheap
examples (01-04) in one process; the four costly ones (05-08, 12-30 s of CPU each) are slow, each covered in the
default tier by the tests of the functions it shows (named in its test).
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "docs" / "examples"
TIMEOUT = 600  # s: a hang fails the test instead of the suite

# example -> figure it writes into --out
FIGURES = {
    "01_quickstart": "quickstart.png",
    "02_three_regimes": "three_regimes.png",
    "03_approx_vs_exact": "approx_vs_exact.png",
    "04_your_own_tape": "your_own_tape.png",
    "05_sweep_phase_diagram": "sweep_phase_diagram.png",
    "06_orbits_bifurcation": "orbits_bifurcation.png",
    "07_your_data": "your_data.png",
    "08_peel_front": "peel_front.png",
}


def _env() -> dict[str, str]:
    """The environment of a run: this checkout first on the path, a file backend for matplotlib."""
    env = dict(os.environ, MPLBACKEND="Agg")
    env.pop("PEELAPPROX_EXAMPLES_OUT", None)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH")) if p)
    return env


#: Runs the examples named in argv[2] (JSON: name, output directory) one after another in this process, each
#: as ``python NAME.py --out DIR`` would (``__main__``, its own argv, the gallery's directory on the path, a
#: fresh namespace), and writes their exit statuses, stdout and stderr as JSON to argv[1].
_DRIVER = """
import json, os, sys
sys.path.insert(0, os.path.join(os.environ["PYTHONPATH"].split(os.pathsep)[0], "tests"))
from _run_script import run_script
path, jobs, examples, results = sys.argv[1], json.loads(sys.argv[2]), sys.argv[3], {}
sys.path.insert(0, examples)
for name, out in jobs:
    results[name] = list(run_script(os.path.join(examples, name + ".py"), ["--out", out]))
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")
with open(path, "w") as f:
    json.dump(results, f)
"""

#: The examples' processes.  The default tier runs the first group only, the four cheap examples (~20 s of CPU
#: together, warm, measured one by one: 01 4.6 s, 02 5.5 s, 03 4.5 s, 04 6.0 s, each with ~2.5 s of interpreter
#: and imports), in one process: under pytest-xdist the other worker has other tests to run, and a second process
#: would pay the imports again.  The slow ones (05 13 s, 06 12 s, 07 30 s, 08 12.5 s) run in two more processes,
#: balanced by CPU time, when ``-m slow`` selects them.
BATCHES = (("04_your_own_tape", "01_quickstart", "02_three_regimes", "03_approx_vs_exact"),
           ("07_your_data", "08_peel_front"), ("05_sweep_phase_diagram", "06_orbits_bifurcation"))


class _Batch:
    """One process running ``names`` in turn (output directories under ``base``), started at once, collected on
    first use: ``result(name)`` is that example's ``(status, stdout, stderr)``, or the process's own when it
    died."""

    def __init__(self, names: list[str], base: Path):
        self.path = base / f"results-{names[0]}.json"
        jobs = [(name, str(base / name)) for name in names]
        self.proc = subprocess.Popen([sys.executable, "-c", _DRIVER, str(self.path), json.dumps(jobs), str(EXAMPLES)],
                                     cwd=base, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self._done: tuple[int, str, str] | None = None

    def result(self, name: str) -> tuple[int, str, str]:
        if self._done is None:
            try:
                stdout, stderr = self.proc.communicate(timeout=TIMEOUT)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                stdout, stderr = self.proc.communicate()
            self._done = (self.proc.returncode, stdout, stderr)
        if self._done[0] != 0 or not self.path.is_file():
            return self._done
        status, stdout, stderr = json.loads(self.path.read_text())[name]
        return status, stdout, stderr


class _Run:
    """One example: its output directory and its batch."""

    def __init__(self, name: str, base: Path, batch: _Batch):
        self.name, self.out, self.batch = name, base / name, batch

    def result(self) -> tuple[int, str, str]:
        return self.batch.result(self.name)


@pytest.fixture(scope="module")
def runs(request, tmp_path_factory):
    """The examples whose tests are selected in this session, all started now in the processes of
    :data:`BATCHES`, each collected when asked for."""
    selected = [item.name for item in request.session.items if item.module is request.module]
    names = [name for name in FIGURES if any(name in test for test in selected)]
    base = tmp_path_factory.mktemp("examples")
    started, batches = {}, []
    batched = {name for group in BATCHES for name in group}
    for group in (*BATCHES, tuple(name for name in FIGURES if name not in batched)):  # a new example: a process
        mine = [name for name in group if name in names]
        if mine:
            for name in mine:
                (base / name).mkdir()
            batches.append(_Batch(mine, base))
            started.update({name: _Run(name, base, batches[-1]) for name in mine})
    yield started
    for batch in batches:  # a test that failed early leaves no process behind
        if batch.proc.poll() is None:
            batch.proc.kill()
            batch.proc.communicate()


def _output(runs, name: str) -> str:
    """Run ``name`` (or collect its run): exit status 0, its figure written and over 10 kB; its stdout."""
    status, stdout, stderr = runs[name].result()
    assert status == 0, f"{name} exited {status}\n{stdout}\n{stderr}"
    figure = runs[name].out / FIGURES[name]
    assert figure.is_file(), f"{name} wrote no {figure.name}: {sorted(os.listdir(runs[name].out))}"
    assert figure.stat().st_size > 10_000, f"{figure} is only {figure.stat().st_size} bytes"
    assert f"wrote {figure}" in stdout
    assert not (runs[name].out.parent / "docs").exists(), f"{name} wrote into ./docs of its working directory"
    return stdout


def _num(pattern: str, text: str) -> float:
    """The number captured by ``pattern`` (one group) in ``text``."""
    m = re.search(pattern, text)
    assert m, f"{pattern!r} not in the output:\n{text}"
    return float(m.group(1))


def test_every_example_is_tested():
    """The gallery and this module list the same scripts (a new example needs its test)."""
    assert sorted(p.stem for p in EXAMPLES.glob("[0-9]*.py")) == sorted(FIGURES)


def test_01_quickstart(runs):
    """The paper's Fig. 4 case (V = 1, I = 1e-2): period 8, F beyond both folds, folds at the paper's levels.

    Period 8 and "the maximum (and minimum) value of F is larger (or smaller) than that allowed by f" are the
    paper's own statements (Fig. 4 and Sec. III (ii)): exact.  f_max ~ 284 N and f_min ~ 200 N are the
    paper's readings of its Fig. 3(b): within 1 % (a reading off a plot; ours are 285.64 and 199.43).
    """
    out = _output(runs, "01_quickstart")
    assert _num(r"period n = (\d+)", out) == 8
    f_max, f_min = _num(r"f_max = ([\d.]+) N", out), _num(r"f_min = ([\d.]+) N", out)
    assert f_max == pytest.approx(284, rel=0.01) and f_min == pytest.approx(200, rel=0.01)
    assert _num(r"F over the window: max ([\d.]+) N", out) > f_max
    assert _num(r", min ([\d.]+) N \(f_min", out) < f_min
    assert _num(r"residual .* <= ([\d.e+-]+)", out) < 1e-12  # CONSTR holds to rounding at every stored point


def test_02_three_regimes(runs):
    """Low, intermediate, high inertia at V = 1: the paper's period 8 at I = 1e-2 and its α periods at I = 1e-5.

    * I = 1e-2 is period 8 (the paper's Fig. 4): exact.
    * The closed form printed at I = 1e-5 is 2π sqrt(I / (F R)) at the printed f_max (R = 0.1 m): recomputed
      here to 1e-3 (the printed digits); at f_min it is the paper's T = 4.44e-3 s (ν = 225 Hz, F ~ 200 N) to
      0.5 % (the paper rounds ν to three digits and F to 200 N).
    * The exact α period at the end of the AB stays at I = 1e-5 is the paper's 3.72e-3 s to 5 %: the paper's
      number was read from one stay of its own (aperiodic, ε-regularised) orbit; ours averages the stays of a
      period-3 orbit (3.81 ms measured).
    """
    out = _output(runs, "02_three_regimes")
    blocks = dict(re.findall(r"I = ([\d.e-]+) kg m\^2 \(([^)]*)\):", out))
    assert set(blocks) == {"1e-05", "0.001", "0.01"}
    low, high = out.split("I = 0.001")[0], out.split("I = 0.01 ")[1]
    assert _num(r"period n = (\d+)", high) == 8
    f_max = _num(r"f_max ([\d.]+) N", low)
    assert _num(r"([\d.]+) ms at f_max", low) == pytest.approx(2e3 * math.pi * math.sqrt(1e-5 / (f_max * 0.1)),
                                                               rel=1e-3)
    assert _num(r"([\d.]+) ms at f_min", low) == pytest.approx(4.44, rel=0.005)
    assert _num(r"exact: [\d.]+ ms at entry, ([\d.]+) ms at exit", low) == pytest.approx(3.72, rel=0.05)


def test_03_approx_vs_exact(runs):
    """The paper's Case II point a and its 10 % claim.

    * Seeded with the paper's quoted entry (α_in = 0.0599, α̇_in = 9.7, F_in = 186.95 N), approxalpha +
      approxvdot gives the paper's Δt = 0.117 s to within its last digit (±0.5 ms).
    * Our exact stretch ab lasts the paper's exact 0.114 s to 2 %: its entry is our orbit's (F_in = 186.29 N,
      α_in = 0.0706), not the paper's.
    * Every reduced model of the harness is within the paper's claimed 10 % of the exact Δt.
    """
    out = _output(runs, "03_approx_vs_exact")
    assert abs(_num(r"point a, approxalpha \+ approxvdot: dt = ([\d.]+) s", out) - 0.117) <= 5e-4
    assert _num(r"exact: +dt = ([\d.]+) s", out) == pytest.approx(0.114, rel=0.02)
    assert _num(r"largest \|dt error\| ([\d.]+) %", out) < 10


def test_04_your_own_tape(runs):
    """The cubic a + b v - c v² + d v³ (150, 300, 300, 80): folds in closed form, jumps at the fold levels.

    v_max,min = (c ∓ sqrt(c² - 3bd)) / (3d): the expression law's printed folds (6 decimals) to 2e-6 m/s, f_max and
    f_min (4 decimals) to 2e-4 N, and F (1 + sin α) at the AB→CD (CD→AB) jumps equals the closed-form f_max
    (f_min) to the same 2e-4 N (the solver locates each fold to ~1e-12).  The table (30 points per decade) puts
    its folds on data points: within one spacing (a factor 10^(1/30), 8 %) of the closed form.
    """
    out = _output(runs, "04_your_own_tape")
    a, b, c, d = 150.0, 300.0, 300.0, 80.0
    root = math.sqrt(c * c - 3 * b * d)
    v_max, v_min = (c - root) / (3 * d), (c + root) / (3 * d)
    f_max, f_min = (a + b * v - c * v**2 + d * v**3 for v in (v_max, v_min))
    expr, table = out.split("table:", 1)
    assert _num(r"v_max = ([\d.]+) m/s", expr) == pytest.approx(v_max, abs=2e-6)
    assert _num(r"v_min = ([\d.]+) m/s", expr) == pytest.approx(v_min, abs=2e-6)
    assert _num(r"\(f_max = ([\d.]+) N\)", expr) == pytest.approx(f_max, abs=2e-4)
    assert _num(r"\(f_min = ([\d.]+) N\)", expr) == pytest.approx(f_min, abs=2e-4)
    assert _num(r"at AB->CD jumps ([\d.]+) N", expr) == pytest.approx(f_max, abs=2e-4)
    assert _num(r"at CD->AB jumps ([\d.]+) N", expr) == pytest.approx(f_min, abs=2e-4)
    assert _num(r"v_max = ([\d.]+) m/s", table) == pytest.approx(v_max, rel=0.08)
    assert _num(r"v_min = ([\d.]+) m/s", table) == pytest.approx(v_min, rel=0.08)


def test_04_why_the_expression_and_the_table_differ_in_period(runs):
    """The same cubic gives period 5 as an expression and period 1 as a 30-per-decade table: the example's
    explanation, as measured (docs/your-own-tape.md, "Same law, another period").

    Periods are integers of a deterministic run (rtol 1e-10): exact.  The period-5 orbit is nearly period 1:
    its slip intervals spread by 2.7 ms (the printed 2 digits: to 1e-4 s), the table's period-1 intervals by
    less than 1e-6 s (rounding of the jump times).  The table differs from the cubic by 0.377 N at most over
    the orbit's v (PCHIP of fixed data: 3 decimals, to 2e-3 N), past the 0.05 N by which the cubic may be
    raised before it too settles on period 1; sampled at 120 points per decade (within 0.02 N) the table gives
    period 5 back.
    """
    out = _output(runs, "04_your_own_tape")
    expr, table = out.split("table:", 1)
    assert _num(r"period n = (\d+)", expr) == 5
    assert _num(r"period n = (\d+)", table) == 1
    assert _num(r"period n = 5; the intervals spread by ([\d.e-]+) s", out) == pytest.approx(2.7e-3, abs=1e-4)
    assert _num(r"period n = 1; the intervals spread by ([\d.e-]+) s", out) < 1e-6
    assert _num(r"differs from the expression by up to ([\d.]+) N", out) == pytest.approx(0.377, abs=2e-3)
    assert _num(r"a = 150.05\): period n = (\d+)", out) == 1
    assert _num(r"120-points-per-decade table: period n = (\d+)", out) == 5
    assert _num(r"\(it differs by up to ([\d.]+) N\)", out) < 0.02


@pytest.mark.slow
def test_05_sweep_phase_diagram(runs):
    """The 4 x 4 sweep: the paper's period 8 at (I, V) = (1e-2, 1) and the chaos of docs/dynamics.md.

    Exact labels: period-8 at I = 1e-2, V = 1 (the paper's Fig. 4); aperiodic at I = 1e-4, V = 1 and 2, where
    docs/dynamics.md reports chaos (λ = 3.1 and 4.7 bits/s) on the same window (t = 30-50 s, rtol 1e-10); and
    the row I = 1e-5 as that page's sweep table has it (P3, P7, P5, P1: periodic everywhere at low inertia).

    Slow (16 exact runs of 50 s, 13 s of CPU): covered in the default tier by tests/test_sweep.py (the sweep,
    its measures and records) and tests/test_parallel.py::test_sweep_records_identical_on_every_pool_kind.
    """
    out = _output(runs, "05_sweep_phase_diagram")
    rows = {m.group(1): m.group(2).split() for m in re.finditer(r"^(1e-05|0\.0001|0\.001|0\.01) +(\S.*)$", out, re.M)
            if "period" in m.group(2) or "aperiodic" in m.group(2)}
    assert rows["0.01"][0] == "period-8"
    assert rows["0.0001"][:2] == ["aperiodic", "aperiodic"]
    assert rows["1e-05"] == ["period-3", "period-7", "period-5", "period-1"]
    assert "16 points, 4 aperiodic, statuses: ['ok']" in out


@pytest.mark.slow
def test_06_orbits_bifurcation(runs):
    """The period-8 orbit at V = 1, I = 1e-2 and its branch in V, against docs/orbits.md.

    n = 8 is the paper's period (exact).  |μ| = 0.906 (the table of docs/orbits.md, 3 digits: to 1e-3); the
    branch's stable range there is 0.977-1.103 m/s, from a Neimark-Sacker bifurcation to the crest event that
    ends it: both ends to 2e-3 m/s (the page's 3 digits, plus the crest's linear extrapolation).  The long run
    at V = 1 lies on it: period-8.

    Slow (Newton on the period-8 orbit, its continuation and an 11-point diagram, 12 s of CPU): covered
    in the default tier by tests/test_orbits.py and tests/test_branch_events.py (the period-8 orbit, its
    multipliers, its branch and the bifurcations that end it).
    """
    out = _output(runs, "06_orbits_bifurcation")
    assert _num(r"period n = (\d+) slips", out) == 8
    assert _num(r"\|mu\| = ([\d.]+),", out) == pytest.approx(0.906, abs=1e-3)
    assert _num(r"neimark_sacker at V = ([\d.]+)", out) == pytest.approx(0.977, abs=2e-3)
    assert _num(r"ends: crest at V = ([\d.]+)", out) == pytest.approx(1.103, abs=2e-3)
    assert "long run at V = 1.000: period-8" in out


@pytest.mark.slow
def test_07_your_data(runs):
    """A synthetic experiment (V = 1, I = 1e-2, k = 1000 N/m, 20 s at 10 kHz, 0.5 N noise, 5 N drift) written in
    ms and kN and read back: every slip of the run found (the run's own count: exact), the slip interval to 1 %
    and the drop to 2 % of the run's (the detector's stated goals), period 8 (the paper's); λ within 0.1
    bits/s of 0 (a periodic orbit; the tolerance of tests/test_series_lyapunov.py); k within 5 % of the truth
    with its interval covering it (the inference's goal).

    Slow (50 s of a run sampled at 10 kHz and a 27-run inference, 30 s of CPU): covered in the default
    tier by tests/test_series.py, tests/test_series_lyapunov.py and tests/test_infer.py (slips, λ and k from
    a trace).
    """
    out = _output(runs, "07_your_data")
    found, made = _num(r"(\d+) slips found", out), _num(r"the run has (\d+)", out)
    assert found == made
    assert _num(r"slip interval ([\d.]+) s", out) == pytest.approx(_num(r"\(exact ([\d.]+) s\), force", out),
                                                                   rel=0.01)
    assert _num(r"force drop ([\d.]+) N", out) == pytest.approx(_num(r"\(exact ([\d.]+) N\)", out), rel=0.02)
    assert "period-8 (exact period-8)" in out
    assert abs(_num(r"Lyapunov exponent ([-\d.]+) bits/s", out)) < 0.1
    k = _num(r"k = ([\d.]+) \(truth", out)
    lo, hi = _num(r"95 % in \[([\d.]+),", out), _num(r"95 % in \[[\d.]+, ([\d.]+)\]", out)
    assert abs(k / 1000 - 1) < 0.05 and lo <= 1000 <= hi


@pytest.mark.slow
def test_08_peel_front(runs):
    """The front of docs/peel-front.md's "Use" and the bursts of a longer run.

    * N = 64 (V = 1, I = 1e-2, m = 1 g, γ = 0.05, κ = 0.1, δ₀ = 0.01, seed 0, 30 ms): stuck-peeled with ⟨W⟩ = 1.67,
      Φ_mix = 0.35 and ⟨n_dw⟩ = 12.9, as that page reports (its printed digits: to half a unit of the last).
    * E_AE, a state of the integration, equals the trapezoid integral of the stored AE power to 1e-3 relative
      (docs/peel-front.md, "Energy balance": the trapezoid rule's own error through the bursts at 2 µs).
    * N = 16 over 0.3 s: each slip of the front (an AB->CD jump of the mean front, half of its jumps) makes one
      AE burst above 5 % of the record's largest AE power, within one (a burst cut by the record's ends).

    Slow (a 64-strip front over 30 ms and a 16-strip one over 0.32 s, 12.5 s of CPU): covered in the
    default tier by tests/test_front.py and tests/test_bursts.py (the front, its patterns and its bursts).
    """
    out = _output(runs, "08_peel_front")
    assert "pattern stuck-peeled" in out
    assert _num(r"<W> = ([\d.]+)", out) == pytest.approx(1.67, abs=0.005)
    assert _num(r"Phi_mix = ([\d.]+)", out) == pytest.approx(0.35, abs=0.005)
    assert _num(r"<n_dw> = ([\d.]+)", out) == pytest.approx(12.9, abs=0.05)
    e_state, e_trap = _num(r"AE energy ([\d.]+) J", out), _num(r"trapezoid integral ([\d.]+) J", out)
    assert e_trap == pytest.approx(e_state, rel=1e-3)
    jumps, bursts = _num(r"0.3 s: (\d+) mean-front jumps", out), _num(r"jumps, (\d+) bursts", out)
    assert abs(bursts - jumps / 2) <= 1
