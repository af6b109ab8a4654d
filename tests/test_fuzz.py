"""Fuzz test of every public entry point: no input, however odd, gives a silent wrong answer.

Each test starts from a valid, cheap baseline call of one entry point and replaces **one** argument by a
value drawn from a "nasty" strategy (None, bools, strings, NaN, ±inf, 0, -1, 1e-300, 1e300, huge integers,
``100.0`` for counts, lists and arrays of the wrong shape, values at and just beyond the documented range
edges, random floats of any magnitude), or, for :class:`PeelParams` + ``simulate``, draws every argument at
random inside its documented range.  The one classifier :func:`classify` then requires that the call ends in

* ``"result"``: a return value whose numbers are finite where the function promises them (trajectories:
  ``t, alpha, omega, F, v`` finite and ``v > 0``; the checks per result type are in :func:`check_result`);
* ``"arg_error"``: a ``ValueError``/``TypeError`` whose message names the argument that was perturbed; or
* ``"model_exc"``: a documented model exception (``ModelBreakdown``, ``SolverBudgetExceeded``,
  ``SolverFailure``) with a finite time and a finite state with ``v > 0`` (and a finite partial result).

Anything else fails the test: an exception of another type propagates (ZeroDivisionError, OverflowError,
numba errors, AttributeError, a plain RuntimeError ...), a misattributed error or a non-finite number is an
assertion.  The CLI (``peelapprox.cli.main``) is held to its own contract: exit status 0, 2 (usage error,
one line naming the option, no traceback) or 3 (the model or solver stopped).

Tiers (:data:`CASES`): ``-m slow`` draws the bulk, 5650 cases over the entry points' arguments; the default run
draws each *part* of an entry point (each argument, each CLI subcommand's option, each kind of case) a fixed
small number of times, so every argument's check is still reached on every run (a random draw of that size
would leave some out) at a small part of the cost.  Both are derandomised, so a run is reproducible.  Every
classified case is counted by entry point and outcome in :data:`COUNTS`; with
``PEELAPPROX_FUZZ_REPORT=<path>.md`` the table is written there (and the counts as JSON beside it): the commands
and the tables are in ``docs/robustness.md``, "Fuzz test of the public entry points".

Valid but expensive values are not drawn where the entry point has no wall-clock budget (durations above
:data:`MAX_FUZZ_TIME` for the Lyapunov and attractor functions, counts above :data:`MAX_FUZZ_COUNT` for
their intervals and returns, process pools for ``sweep``): they are bounded by the step budgets (tens of
seconds), not wrong, and would only make the fuzz slow.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import shutil
import tempfile
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import exact
import peelapprox as pa
from peelapprox import EPS_RANGE, PARAM_RANGES, STATE_RANGES, TIME_MAX, PeelForce, PeelParams
from peelapprox.cli import main as cli_main
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure

#: Per entry point: (default, slow) derandomised cases.  The slow tier draws its 5650 cases at random over the
#: arguments.  The default tier first draws each *part* (:func:`run_tier`: each argument, each CLI
#: subcommand's option, each kind of case) once, its simplest value (None or a bad type, which must be refused
#: naming that argument: the one check every argument has; the CLI also runs each subcommand's valid
#: baseline), then the number below at random over the whole,
#: which reaches the range checks, valid runs and model exceptions (about a tenth of the slow tier's
#: share: ~350 cases, ~5 s warm against ~20 s for the 565 random ones it replaces).
CASES: dict[str, tuple[int, int]] = {
    "PeelParams": (20, 800),
    "PeelParams+simulate (random valid)": (10, 400),
    "simulate": (25, 800),
    "initial_state": (10, 400),
    "reduced_segment": (15, 600),
    "estimate": (10, 400),
    "periodicity": (10, 400),
    "lyapunov": (6, 250),
    "lyapunov_tangent": (4, 150),
    "lyapunov_return_map": (5, 200),
    "attractors": (6, 250),
    "sweep": (5, 200),
    "load_sweep": (5, 200),
    "cli": (20, 600),
    "PeelForce.tabulated": (15, 600),
    "simulate with a law": (8, 300),
}
TIERS = [pytest.param(0, id="default"), pytest.param(1, id="slow", marks=pytest.mark.slow)]

#: Longest valid duration [s] drawn for entry points without a wall-clock budget (lyapunov*, attractors,
#: the sweep measures, the dynamics command): a 1e6 s run is bounded only by the step budget (~35 s).
MAX_FUZZ_TIME = 0.5
#: Largest valid count drawn for Lyapunov intervals and returns (each one is two short runs).
MAX_FUZZ_COUNT = 8

#: Outcome kinds; the last two are failures, counted before the test fails so that a report shows them.
OUTCOMES = ("result", "arg_error", "model_exc", "unhandled", "nonfinite")
COUNTS: Counter = Counter()

MODEL_EXCEPTIONS = (ModelBreakdown, SolverBudgetExceeded, SolverFailure)


# ---------------------------------------------------------------------------------------------- classifier
def _numbers(x: Any) -> Iterable[float]:
    """Every real number inside x (scalars, arrays, sequences, dicts); strings, None and bools skipped."""
    if x is None or isinstance(x, (str, bytes, bool, np.bool_)):
        return
    if isinstance(x, Mapping):
        for v in x.values():
            yield from _numbers(v)
    elif isinstance(x, (list, tuple)):
        for v in x:
            yield from _numbers(v)
    elif isinstance(x, np.ndarray):
        if x.dtype.kind in "iuf":
            yield from x.astype(float).ravel().tolist()
    elif isinstance(x, (int, float, np.integer, np.floating)):
        yield float(x)


def _all_finite(x: Any) -> bool:
    return all(math.isfinite(v) for v in _numbers(x))


def check_state(state: Mapping, where: str) -> None:
    """A reported state: every number finite, ``v > 0`` when it has one."""
    assert _all_finite(state), f"{where}: non-finite state {state}"
    if "v" in state:
        assert state["v"] > 0, f"{where}: v <= 0 in {state}"


def check_trajectory(tr: exact.Trajectory, where: str) -> None:
    """Stored points and jumps finite, v > 0, times within [0, t_end], a finite final state with v > 0."""
    for name in ("t", "alpha", "omega", "F", "v"):
        assert _all_finite(getattr(tr, name)), f"{where}: non-finite {name}"
    assert np.all(tr.v > 0), f"{where}: v <= 0 stored"
    assert np.all((tr.t >= 0) & (tr.t <= tr.t_end)), f"{where}: stored t outside [0, t_end]"
    J = tr.jumps
    for name in ("t", "alpha", "omega", "F", "v_before", "v_after"):
        assert _all_finite(getattr(J, name)), f"{where}: non-finite jumps.{name}"
    assert np.all(J.v_before > 0) and np.all(J.v_after > 0), f"{where}: v <= 0 at a jump"
    check_state(tr.final_state.as_dict(), f"{where} final_state")


def check_segment(seg: pa.ReducedSegment, where: str) -> None:
    """Δt >= 0, every scalar and curve finite, v > 0 on the curves."""
    scalars = {k: getattr(seg, k) for k in ("dt", "F_in", "F_exit", "dF", "v_in", "v_f", "alpha_in",
                                             "alphadot_in", "alpha_exit", "alphadot_exit")}
    assert _all_finite(scalars), f"{where}: non-finite {scalars}"
    assert seg.dt >= 0
    for name in ("t", "v", "F", "alpha", "alphadot"):
        assert _all_finite(getattr(seg, name)), f"{where}: non-finite curve {name}"
    assert np.all(seg.v > 0)


def check_lyapunov(r: pa.LyapunovResult, where: str) -> None:
    """Exponents finite (``stderr_bits`` may be NaN: documented for a single interval and the tangent method)."""
    assert math.isfinite(r.per_s) and math.isfinite(r.bits_per_s), f"{where}: {r.bits_per_s}"
    assert _all_finite(r.benettin.running) and _all_finite(r.benettin.local) and r.benettin.time > 0
    assert r.n_jumps >= 0


def check_periodicity(p: pa.Periodicity, where: str) -> None:
    """Documented semantics: ``kind`` one of three; ``period`` an int in [1, max] iff periodic; ``mismatch``
    >= 0, finite when a period was tried (``inf`` only for "too short" with no n tried)."""
    assert p.kind in ("periodic", "aperiodic", "too short"), where
    assert (p.period is not None) == (p.kind == "periodic")
    assert p.mismatch >= 0 and not math.isnan(p.mismatch), f"{where}: mismatch {p.mismatch}"
    if p.kind != "too short":
        assert math.isfinite(p.mismatch), f"{where}: mismatch {p.mismatch}"


def check_attractors(res: list, where: str) -> None:
    """Each entry: starts and settle times finite; a periodic/aperiodic entry has a finite signature and
    F range (NaN ranges are documented only for breakdowns, infeasible starts and "no stick-slip")."""
    assert res, f"{where}: no entries"
    for a in res:
        assert _all_finite(a.starts) and _all_finite([s for s in a.settle_times if s is not None])
        assert _all_finite(a.signature)
        if a.signature:
            assert _all_finite(a.F_range), f"{where}: {a}"


def check_sweep(res: pa.SweepResult, where: str, names: Sequence[str] = ()) -> str:
    """A computed sweep: every record ok or a reported breakdown.  A record of an error is an outcome of its
    own kind: ``"model_exc"`` for a documented model exception, ``"arg_error"`` for a ValueError naming one
    of ``names`` (an option valid by itself but infeasible at that point, e.g. an alpha0 without a root of
    CONSTR); anything else fails the test (an unhandled error swallowed into a record)."""
    check_loaded_sweep(res, where)
    kind = "result"
    for rec in res.records:
        status = rec["status"]
        if status.startswith("error: ValueError") and any(n in status for n in names):
            kind = "arg_error"
        elif status.startswith("error"):
            assert any(e.__name__ in status for e in MODEL_EXCEPTIONS), f"{where}: {status}"
            kind = "model_exc"
        else:
            assert status == "ok" or status.startswith("breakdown:"), f"{where}: {status}"
    return kind


def check_loaded_sweep(res: pa.SweepResult, where: str) -> None:
    """A sweep read back: finite grid axes, each record at a finite (I, V) with a status string (what a status
    says is the measures' business: any string a measure reports is valid)."""
    assert _all_finite(res.I_values) and _all_finite(res.V_values), where
    for rec in res.records:
        assert math.isfinite(rec["I"]) and math.isfinite(rec["V"]) and isinstance(rec["status"], str), where


def check_result(res: Any, where: str) -> str:
    """The checks of one return value, by type; returns the outcome kind (``"result"`` or, for a sweep
    with recorded model exceptions, ``"model_exc"``)."""
    if isinstance(res, exact.Trajectory):
        check_trajectory(res, where)
    elif isinstance(res, exact.State):
        check_state(res.as_dict(), where)
        assert res.branch in pa.BRANCHES
    elif isinstance(res, pa.ReducedSegment):
        check_segment(res, where)
    elif isinstance(res, pa.LyapunovResult):
        check_lyapunov(res, where)
    elif isinstance(res, pa.Periodicity):
        check_periodicity(res, where)
    elif isinstance(res, pa.SweepResult):
        check_loaded_sweep(res, where)
    elif isinstance(res, list):
        check_attractors(res, where)
    elif isinstance(res, PeelParams):
        for name, (lo, hi) in PARAM_RANGES.items():
            assert lo <= getattr(res, name) <= hi, f"{where}: {name}={getattr(res, name)}"
    elif isinstance(res, pa.RegimeEstimate):
        assert _all_finite(res.__dict__), f"{where}: non-finite field in {res}"
    else:
        raise AssertionError(f"{where}: unexpected result type {type(res).__name__}")
    return "result"


def check_model_exception(exc: BaseException, where: str) -> None:
    """A documented model exception: finite ``t``, a finite state with v > 0, a finite partial result."""
    assert exc.t is not None and math.isfinite(exc.t), f"{where}: t = {exc.t} ({exc})"
    check_state(exc.state, f"{where} ({type(exc).__name__}: {exc})")
    if exc.partial is not None:
        check_result(exc.partial, f"{where} partial")


def classify(entry: str, call: Callable[[], Any], names: Sequence[str], where: str = "",
             check: Callable[[Any, str], Any] = check_result) -> str:
    """Run ``call`` and return its outcome kind, or fail the test (module docstring for the contract).

    Parameters
    ----------
    entry : str
        The entry point, the row of :data:`COUNTS`.
    call : callable
        The call with one argument perturbed.
    names : sequence of str
        Names an argument error may give: the perturbed argument's, and the names of arguments it can
        conflict with when its value is valid by itself (e.g. ``v_f`` below ``v_in``).
    where : str
        Description of the case for failure messages.
    check : callable
        ``check(result, where)``: asserts on a returned value; may return the outcome kind (default
        :func:`check_result`).
    """
    where = where or entry
    try:
        try:
            res = call()
        except MODEL_EXCEPTIONS as exc:
            check_model_exception(exc, where)
            kind = "model_exc"
        except (ValueError, TypeError) as exc:
            msg = str(exc)
            assert any(n in msg for n in names), f"{where}: {type(exc).__name__} does not name {names}: {msg}"
            kind = "arg_error"
        else:
            kind = check(res, where) or "result"
    except AssertionError:
        COUNTS[entry, "nonfinite"] += 1
        raise
    except BaseException:
        COUNTS[entry, "unhandled"] += 1
        raise
    COUNTS[entry, kind] += 1
    return kind


# ---------------------------------------------------------------------------------------------- strategies
NASTY_FIXED = [
    None, True, False, np.bool_(True), "abc", "1", "", "nan", math.nan, math.inf, -math.inf, 0, 0.0, -0.0, -1,
    -1.0, 1e-300, -1e-300, 5e-324, 1e300, -1e300, 10**30, 2**63, 10**400, 100.0, 1.5, [1.0], [], [[1.0]],
    np.array([1.0, 2.0]), np.array([[0.5]]), np.array([]), 1 + 2j, np.float32(0.5), np.int64(3), object(),
    {"a": 1}, np.array(["a"]),
]
#: Any value: the fixed nasty ones, floats of every magnitude (NaN, inf), integers, short text.
NASTY = st.one_of(
    st.sampled_from(NASTY_FIXED),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(10**20), 10**20),
    st.text(max_size=4),
)


def edges(lo: float, hi: float) -> st.SearchStrategy:
    """Values at and just beyond the ends of ``[lo, hi]`` and log-uniform inside it (lo > 0) or uniform."""
    near = [lo, hi, np.nextafter(lo, -math.inf), np.nextafter(hi, math.inf), lo * (1 - 1e-12) if lo else -1e-300,
            hi * (1 + 1e-12)]
    inside = (st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0 ** e) if lo > 0
              else st.floats(lo, hi))
    return st.one_of(st.sampled_from([float(x) for x in near]), inside)


def nasty_or(*valid: st.SearchStrategy) -> st.SearchStrategy:
    """A nasty value, or one of the given valid/edge strategies (about half and half)."""
    return st.one_of(NASTY, *valid) if valid else NASTY


def short_time(x: Any) -> bool:
    """x is not a valid duration longer than :data:`MAX_FUZZ_TIME` (those are slow, not wrong)."""
    try:
        y = float(x)
    except (TypeError, ValueError, OverflowError):
        return True
    if isinstance(x, (bool, str, np.bool_)):
        return True
    return not (MAX_FUZZ_TIME < y <= TIME_MAX)


def small_count(x: Any) -> bool:
    """x is not a valid integer count above :data:`MAX_FUZZ_COUNT`."""
    return not (isinstance(x, (int, np.integer)) and not isinstance(x, (bool, np.bool_))
                and MAX_FUZZ_COUNT < x <= 10**15)


def one_of_args(args: Mapping[str, st.SearchStrategy]) -> st.SearchStrategy:
    """``(name, value)``: one argument of ``args`` and a value from its strategy."""
    return st.sampled_from(sorted(args)).flatmap(lambda n: st.tuples(st.just(n), args[n]))


def each_arg(args: Mapping[str, st.SearchStrategy]) -> list[st.SearchStrategy]:
    """The parts of :func:`one_of_args`: ``(name, value)`` for each argument in turn."""
    return [st.tuples(st.just(n), args[n]) for n in sorted(args)]


def run_tier(tier: int, entry: str, strategy: st.SearchStrategy, body: Callable[[Any], None],
             parts: Sequence[st.SearchStrategy] = ()) -> None:
    """Run ``body`` on ``CASES[entry][tier]`` derandomised examples of ``strategy``, and in the default tier
    first on one example of each of ``parts``, the pieces ``strategy`` draws from, so that none is left out."""
    runs = [(part, 1) for part in parts] if tier == 0 else []
    for part, count in [*runs, (strategy, CASES[entry][tier])]:
        @settings(max_examples=count, deadline=None, derandomize=True, database=None,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                         HealthCheck.data_too_large])
        @given(part)
        def inner(case):
            body(case)

        inner()


@pytest.fixture(scope="module", autouse=True)
def fuzz_report():
    """Write the case counts when ``PEELAPPROX_FUZZ_REPORT`` names a file (module docstring)."""
    yield
    path = os.environ.get("PEELAPPROX_FUZZ_REPORT")
    if path:
        write_report(path, COUNTS)


def write_report(path: str, counts: Counter) -> None:
    """The markdown table of ``counts`` (entry point × outcome, with totals) to ``path``, JSON beside it."""
    entries = [e for e in CASES if any(counts[e, o] for o in OUTCOMES)]
    head = "| entry point | cases | result | argument error | model exception | unhandled | NaN/inf |"
    lines = [head, "|---|---:|---:|---:|---:|---:|---:|"]
    tot = Counter()
    for e in entries:
        row = [counts[e, o] for o in OUTCOMES]
        tot.update(dict(zip(OUTCOMES, row)))
        lines.append(f"| `{e}` | {sum(row)} | " + " | ".join(str(x) for x in row) + " |")
    lines.append(f"| **total** | **{sum(tot.values())}** | " + " | ".join(f"**{tot[o]}**" for o in OUTCOMES) + " |")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    with open(os.path.splitext(path)[0] + ".json", "w") as fh:
        json.dump({e: {o: counts[e, o] for o in OUTCOMES} for e in entries}, fh, indent=1)


P = PeelParams(V=1.0, I=1e-5)
#: Valid PeelParams at the corners of PARAM_RANGES (and the paper's points), for the ``params`` argument.
PARAMS_VALID = st.sampled_from([
    P, PeelParams(V=2.0, I=1e-4), PeelParams(V=0.2, I=1e-2), PeelParams(V=6.0, I=1e-3),
    PeelParams(V=1e-6, I=1e-5), PeelParams(V=100.0, I=1e-5), PeelParams(V=1.0, I=1e6),
    PeelParams(V=1.0, I=1e-5, k=1e-3), PeelParams(V=1.0, I=1e-5, k=1e7), PeelParams(V=1.0, I=1e-5, R=1e-4),
    PeelParams(V=1.0, I=1e-5, R=10.0, l=1e3), PeelParams(V=1.0, I=1e-5, l=0.1001, geometry="exact"),
    PeelParams(V=0.05, I=1e-6, geometry="exact"),
])
PARAMS_ARG = nasty_or(PARAMS_VALID, st.sampled_from([{"V": 1.0, "I": 1e-5}, (1.0, 1e-5), "PeelParams"]))


def rng(key: str) -> st.SearchStrategy:
    return edges(*STATE_RANGES[key]) if key != "v" else edges(1e-300, STATE_RANGES["v"][1])


# ---------------------------------------------------------------------------------------------- PeelParams
PEEL_ARGS = {**{name: nasty_or(edges(lo, hi)) for name, (lo, hi) in PARAM_RANGES.items()},
             "geometry": nasty_or(st.sampled_from(["paper", "exact", "Paper", " exact"]))}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_peelparams(tier):
    """Hypothesis: PeelParams with one field set to anything builds with every field in PARAM_RANGES or
    raises ValueError/TypeError naming that field (``l`` out of its R-relative range also names ``l``)."""
    def body(case):
        name, value = case
        kw = dict(V=1.0, I=1e-5)
        kw[name] = value
        classify("PeelParams", lambda: PeelParams(**kw), [name], f"PeelParams({name}={value!r})")

    run_tier(tier, "PeelParams", one_of_args(PEEL_ARGS), body, each_arg(PEEL_ARGS))


def _log(lo: float, hi: float) -> st.SearchStrategy:
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0 ** e)


RANDOM_VALID = st.fixed_dictionaries({
    "V": _log(*PARAM_RANGES["V"]), "I": _log(*PARAM_RANGES["I"]), "k": _log(*PARAM_RANGES["k"]),
    "R": _log(*PARAM_RANGES["R"]), "l_over_R": _log(1.001, 1e4), "geometry": st.sampled_from(["paper", "exact"]),
    "alpha0": st.floats(-math.pi, math.pi), "rtol": _log(1e-14, 1e-2),
    "atol": st.one_of(st.none(), _log(1e-100, 1.0)), "save": st.sampled_from(["steps", "jumps"]),
    "t_end": _log(1e-6, 0.01),
})


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_random_valid_simulate(tier):
    """Hypothesis: PeelParams and simulate with every argument drawn inside its documented range (log-uniform
    over the decades of V, I, k, R, l/R, rtol, atol; any alpha0; 10 ms runs with a 0.25 s wall budget) end
    in a trajectory with finite values and v > 0, a model exception with a finite state, or an infeasible
    start (ValueError naming alpha0 or F0: the default F0 has no root at that alpha0).  No NaN anywhere."""
    def body(kw):
        R = kw["R"]
        l = min(R * kw["l_over_R"], PARAM_RANGES["l"][1])  # noqa: E741
        p = PeelParams(V=kw["V"], I=kw["I"], k=kw["k"], R=R, l=max(l, 1.001 * R), geometry=kw["geometry"])
        classify("PeelParams+simulate (random valid)",
                 lambda: exact.simulate(p, kw["t_end"], alpha0=kw["alpha0"], rtol=kw["rtol"], atol=kw["atol"],
                                        save=kw["save"], max_wall=0.25, max_points=200_000),
                 ["alpha0", "F0"], f"simulate({p}, **{kw})")

    run_tier(tier, "PeelParams+simulate (random valid)", RANDOM_VALID, body)


# ---------------------------------------------------------------------------------------------- simulate
SIM_BASE = dict(params=P, t_end=0.01, save="jumps", max_wall=0.3)
SIM_ARGS = {
    "params": PARAMS_ARG,
    "t_end": nasty_or(edges(1e-9, TIME_MAX)),
    "alpha0": nasty_or(rng("alpha")),
    "omega0": nasty_or(rng("omega")),
    "F0": nasty_or(rng("F"), st.floats(200.0, 400.0)),
    "branch0": nasty_or(st.sampled_from(["AB", "CD", "ab", "EF"])),
    "method": nasty_or(st.sampled_from(["hybrid", "regularized", "Hybrid", "radau"])),
    "solver": nasty_or(st.sampled_from(["Radau", "BDF", "LSODA", "RK45"])),
    "rtol": nasty_or(edges(1e-14, 1e-2)),
    "atol": nasty_or(edges(1e-100, 1.0), st.lists(st.floats(1e-10, 1.0), min_size=1, max_size=5)),
    "eps": nasty_or(edges(*EPS_RANGE)),
    "t_transient": nasty_or(edges(1e-9, 0.01)),
    "t_eval": nasty_or(st.lists(st.floats(-0.01, 0.02), max_size=6), st.just(np.linspace(0, 0.01, 5))),
    "save": nasty_or(st.sampled_from(["steps", "jumps", "none"])),
    "max_points": nasty_or(st.integers(1, 10), st.just(10**15)),
    "max_steps": nasty_or(st.integers(1, 100), st.just(10**15)),
    "max_jumps": nasty_or(st.integers(1, 3), st.just(10**15)),
    "max_wall": nasty_or(edges(1e-9, 0.3)),
    "v_floor": nasty_or(edges(1e-300, 1.0)),
    "progress": nasty_or(st.just(lambda t, t_end: None)),
}
#: Arguments of the regularised method, tried with method="regularized" (shorter runs: ~1 s per 10 ms).
REG_ARGS = ("solver", "eps")


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_simulate(tier):
    """Hypothesis: exact.simulate (10 ms, save="jumps", 0.3 s wall budget) with one argument set to anything
    returns a finite trajectory with v > 0, raises a documented model exception with a finite state, or a
    ValueError/TypeError naming that argument (a valid t_transient or t_eval can conflict with t_end, a
    valid max_points with t_eval, a valid F0/alpha0 with each other: those names are accepted too)."""
    also = {"t_transient": ["t_end"], "t_eval": ["t_transient", "t_end", "max_points"], "F0": ["alpha0"],
            "alpha0": ["F0"], "branch0": ["F0", "alpha0"], "omega0": [], "max_points": ["t_eval"],
            "params": ["F0", "alpha0"]}

    def body(case):
        name, value = case
        kw = dict(SIM_BASE)
        if name in REG_ARGS:
            kw.update(method="regularized", t_end=1e-3)
        kw[name] = value
        classify("simulate", lambda: exact.simulate(**kw), [name, *also.get(name, [])],
                 f"simulate({name}={value!r})")

    run_tier(tier, "simulate", one_of_args(SIM_ARGS), body, each_arg(SIM_ARGS))


INIT_ARGS = {k: SIM_ARGS[k] for k in ("params", "alpha0", "omega0", "F0", "branch0")}
INIT_ARGS["t0"] = nasty_or(edges(1e-9, TIME_MAX))


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_initial_state(tier):
    """Hypothesis: exact.initial_state with one argument set to anything returns a state with finite values,
    v > 0 and a branch name, or a ValueError/TypeError naming the argument (F0, alpha0 and branch0 can be
    infeasible together: the message then names F0 or alpha0)."""
    def body(case):
        name, value = case
        kw = {"params": P, name: value}
        classify("initial_state", lambda: exact.initial_state(**kw), [name, "F0", "alpha0"],
                 f"initial_state({name}={value!r})")

    run_tier(tier, "initial_state", one_of_args(INIT_ARGS), body, each_arg(INIT_ARGS))


# ---------------------------------------------------------------------------------------------- reduced segment
SEG_BASE = dict(params=P, branch="AB", F_in=250.0, alpha_in=0.01, alphadot_in=0.0, max_steps=20000, save="none")
SEG_ARGS = {
    "params": PARAMS_ARG,
    "branch": nasty_or(st.sampled_from(["AB", "CD", "BC"])),
    "F_in": nasty_or(rng("F")),
    "alpha_in": nasty_or(rng("alpha")),
    "alphadot_in": nasty_or(rng("omega")),
    "amplitude": nasty_or(rng("alpha")),
    "phase": nasty_or(st.floats(-10, 10)),
    "v_in": nasty_or(rng("v")),
    "v_f": nasty_or(rng("v")),
    "alpha_model": nasty_or(st.sampled_from(pa.ALPHA_MODELS + ("genalpha2",))),
    "v_equation": nasty_or(st.sampled_from(pa.V_EQUATIONS)),
    "F_rate": nasty_or(rng("F_rate")),
    "rtol": nasty_or(edges(1e-14, 1e-2)),
    "atol": nasty_or(edges(1e-100, 1e3), st.lists(st.floats(1e-10, 1.0), min_size=1, max_size=6)),
    "t_max": nasty_or(edges(1e-9, TIME_MAX)),
    "save": nasty_or(st.sampled_from(["steps", "none", "jumps"])),
    "t_eval": nasty_or(st.lists(st.floats(-1.0, 1.0), max_size=6)),
    "max_steps": nasty_or(st.integers(1, 100), st.just(10**15)),
}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_reduced_segment(tier):
    """Hypothesis: reduced_segment with one argument set to anything (each alpha model) returns a segment with
    finite Δt, state and curves, raises a model exception with a finite state, or a ValueError/TypeError
    naming the argument (or the velocities and alpha inputs a valid value conflicts with)."""
    also = ["v_in", "v_f", "alpha_in", "alphadot_in", "amplitude", "phase", "branch"]

    def body(case):
        (name, value), model = case
        kw = dict(SEG_BASE, alpha_model=model)
        kw[name] = value
        classify("reduced_segment", lambda: pa.reduced_segment(**kw), [name, *also],
                 f"reduced_segment({name}={value!r}, alpha_model={model!r})")

    models = st.sampled_from(pa.ALPHA_MODELS)
    run_tier(tier, "reduced_segment", st.tuples(one_of_args(SEG_ARGS), models), body,
             [st.tuples(part, models) for part in each_arg(SEG_ARGS)])


# ---------------------------------------------------------------------------------------------- estimate, periodicity
EST_ARGS = {"params": PARAMS_ARG, "alpha_min": nasty_or(edges(-1.5707, 1.5707)),
            "alpha_max": nasty_or(edges(-1.5707, 1.5707))}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_estimate(tier):
    """Hypothesis: estimate with one argument set to anything returns an estimate whose numbers are all finite
    or raises ValueError/TypeError naming it (a lone alpha bound names both)."""
    def body(case):
        name, value = case
        kw = {"params": P, name: value}
        if name != "params":
            kw.setdefault("alpha_min" if name == "alpha_max" else "alpha_max", 0.1)
        classify("estimate", lambda: pa.estimate(**kw), [name, "alpha_min", "alpha_max"],
                 f"estimate({name}={value!r})")

    run_tier(tier, "estimate", one_of_args(EST_ARGS), body, each_arg(EST_ARGS))


PER_ARGS = {
    "x": nasty_or(st.lists(st.floats(allow_nan=False, allow_infinity=False), max_size=80),
                  st.lists(st.sampled_from([0.0, 1.0, 2.0]), min_size=2, max_size=80),
                  st.just([0.0] * 10), st.just([1e308, -1e308] * 40)),
    "rtol": nasty_or(edges(1e-300, 1.0)),
    "max_period": nasty_or(st.integers(1, 40)),
    "min_repeats": nasty_or(st.integers(1, 5)),
}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_periodicity(tier):
    """Hypothesis: periodicity with one argument set to anything returns a Periodicity with its documented
    semantics (check_periodicity) or raises ValueError/TypeError naming the argument."""
    def body(case):
        name, value = case
        kw = {"x": [250.0, 260.0] * 40, name: value}
        classify("periodicity", lambda: pa.periodicity(**kw), [name], f"periodicity({name}={value!r})")

    run_tier(tier, "periodicity", one_of_args(PER_ARGS), body, each_arg(PER_ARGS))


# ---------------------------------------------------------------------------------------------- dynamics
def _time(lo: float = 1e-3) -> st.SearchStrategy:
    return nasty_or(edges(lo, MAX_FUZZ_TIME)).filter(short_time)


def _count(lo: int) -> st.SearchStrategy:
    return nasty_or(st.integers(lo, MAX_FUZZ_COUNT)).filter(small_count)


LY_BASE = dict(params=P, t_transient=0.02, tau=0.005, n=2, n_discard=0, rtol=1e-8)
LY_ARGS = {"params": PARAMS_ARG, "t_transient": _time(), "tau": _time(), "n": _count(2), "n_discard": _count(0),
           "d0": nasty_or(edges(1e-12, 1.0)), "alpha0": nasty_or(rng("alpha")), "rtol": nasty_or(edges(1e-14, 1e-2))}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_lyapunov(tier):
    """Hypothesis: lyapunov (two intervals of 5 ms after 20 ms) with one argument set to anything returns a
    finite exponent, raises a model exception with a finite state, or a ValueError/TypeError naming it."""
    def body(case):
        name, value = case
        kw = dict(LY_BASE)
        kw[name] = value
        classify("lyapunov", lambda: pa.lyapunov(**kw), [name, "alpha0", "d0"], f"lyapunov({name}={value!r})")

    run_tier(tier, "lyapunov", one_of_args(LY_ARGS), body, each_arg(LY_ARGS))


LT_BASE = dict(params=P, t_transient=0.005, T=0.01, rtol=1e-8)
LT_ARGS = {"params": PARAMS_ARG, "t_transient": _time(), "T": _time(), "rtol": nasty_or(edges(1e-14, 1e-2)),
           "alpha0": nasty_or(rng("alpha")), "max_steps": nasty_or(st.integers(1, 1000), st.just(10**15))}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_lyapunov_tangent(tier):
    """Hypothesis: lyapunov_tangent (10 ms after 5 ms) with one argument set to anything returns a finite
    exponent, raises a model exception with a finite state, or a ValueError/TypeError naming it."""
    def body(case):
        name, value = case
        kw = dict(LT_BASE)
        kw[name] = value
        classify("lyapunov_tangent", lambda: pa.lyapunov_tangent(**kw), [name, "alpha0"],
                 f"lyapunov_tangent({name}={value!r})")

    run_tier(tier, "lyapunov_tangent", one_of_args(LT_ARGS), body, each_arg(LT_ARGS))


LR_BASE = dict(params=P, t_transient=0.1, n_returns=2, h=1e-6, rtol=1e-8)
LR_ARGS = {"params": PARAMS_ARG, "t_transient": _time(), "n_returns": _count(2), "h": nasty_or(edges(1e-12, 1.0)),
           "rtol": nasty_or(edges(1e-14, 1e-2))}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_lyapunov_return_map(tier):
    """Hypothesis: lyapunov_return_map (2 returns after 0.1 s) with one argument set to anything returns a
    finite exponent, raises a model exception with a finite state, or a ValueError/TypeError naming it
    (no AB→CD return within t_transient names t_transient; a perturbation too large to return names h)."""
    def body(case):
        name, value = case
        kw = dict(LR_BASE)
        kw[name] = value
        classify("lyapunov_return_map", lambda: pa.lyapunov_return_map(**kw), [name, "t_transient", "h"],
                 f"lyapunov_return_map({name}={value!r})")

    run_tier(tier, "lyapunov_return_map", one_of_args(LR_ARGS), body, each_arg(LR_ARGS))


AT_BASE = dict(params=P, alpha0s=(0.0, 0.1), t_transient=0.02, window=0.1, rtol=1e-8)
AT_ARGS = {"params": PARAMS_ARG, "alpha0s": nasty_or(st.lists(rng("alpha"), max_size=3)),
           "t_transient": _time(), "window": _time(), "rtol": nasty_or(edges(1e-14, 1e-2)),
           "period_rtol": nasty_or(edges(1e-300, 1.0)), "match_rtol": nasty_or(edges(1e-300, 1.0)),
           "progress": nasty_or(st.just(lambda msg: None))}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_attractors(tier):
    """Hypothesis: attractors (two starts, 0.1 s window after 20 ms) with one argument set to anything returns
    a non-empty list with finite starts, signatures and (for orbits) F ranges, or raises ValueError/TypeError
    naming it (infeasible starts are entries, not errors)."""
    def body(case):
        name, value = case
        kw = dict(AT_BASE)
        kw[name] = value
        classify("attractors", lambda: pa.attractors(**kw), [name], f"attractors({name}={value!r})")

    run_tier(tier, "attractors", one_of_args(AT_ARGS), body, each_arg(AT_ARGS))


# ---------------------------------------------------------------------------------------------- sweeps
SW_OPTIONS = {"t_transient": 0.01, "t_end": 0.05, "rtol": 1e-8}
OPTION_KEYS = {"k": edges(*PARAM_RANGES["k"]), "R": edges(1e-4, 0.5), "l": edges(0.2, 1e3),
               "geometry": st.sampled_from(["paper", "exact"]), "t_transient": edges(1e-3, 0.1),
               "t_end": edges(0.02, 0.2), "rtol": edges(1e-14, 1e-2), "alpha0": rng("alpha"),
               "period_rtol": edges(1e-300, 1.0)}
SWEEP_ARGS = {
    "I_values": nasty_or(st.lists(edges(1e-12, 1e6), max_size=2)),
    "V_values": nasty_or(st.lists(edges(1e-6, 100.0), max_size=2)),
    "measures": nasty_or(st.sampled_from(["regime", "regime,period", "nosuch", ["regime", "regime"], [], ","])),
    "out": nasty_or(),
    "executor": nasty_or(st.sampled_from(["serial", "pool"])),
    "max_workers": nasty_or().filter(lambda x: not (x is None or (isinstance(x, (int, np.integer))
                                                                  and not isinstance(x, (bool, np.bool_))
                                                                  and x > 0))),
    "options": nasty_or(st.dictionaries(st.sampled_from(sorted(OPTION_KEYS)), NASTY, max_size=2),
                        st.sampled_from(sorted(OPTION_KEYS)).flatmap(
                            lambda k: st.fixed_dictionaries({k: OPTION_KEYS[k]}))),
    "progress": nasty_or(st.just(lambda done, total, rec: None)),
    "resume": NASTY,
    "retry_failed": NASTY,
}


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_sweep(tier):
    """Hypothesis: sweep (one point, regime and a 40 ms period window, in this process) with one argument set
    to anything returns records that are ok or reported breakdowns (a recorded error only of a documented
    model exception), or raises ValueError/TypeError naming the argument before writing anything.  Process
    pools (max_workers None or > 0) are not drawn: each spawn costs seconds."""
    def body(case):
        name, value = case
        d = tempfile.mkdtemp(prefix="fuzz_sweep_")
        try:
            kw = dict(I_values=[1e-5], V_values=[1.0], measures="regime,period", out=os.path.join(d, "s"),
                      max_workers=0, options=dict(SW_OPTIONS), progress=False)
            if name == "options" and isinstance(value, dict):
                value = {**SW_OPTIONS, **value}
            if name == "executor":
                kw.pop("max_workers")
            if name == "out" and isinstance(value, str) and value:  # a text path: inside the temporary directory
                value = os.path.join(d, value.replace(os.sep, "_"))
            kw[name] = value
            names = [name] + (list(value) if name == "options" and isinstance(value, dict) else [])
            classify("sweep", lambda: pa.sweep(**kw), names, f"sweep({name}={value!r})",
                     lambda r, w: check_sweep(r, w, names))
        finally:
            shutil.rmtree(d, ignore_errors=True)

    run_tier(tier, "sweep", one_of_args(SWEEP_ARGS), body, each_arg(SWEEP_ARGS))


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory):
    """A finished two-point regime sweep to corrupt."""
    out = str(tmp_path_factory.mktemp("fuzz") / "sweep")
    pa.sweep([1e-5], [1.0, 2.0], "regime", out=out, max_workers=0, progress=False)
    return out


def _corrupt(src: str, dst: str, what: str, key: str, value: Any) -> None:
    """Copy the sweep ``src`` to ``dst`` and set ``key`` of its manifest (or of its first record) to
    ``value``; ``what="truncate"`` cuts results.jsonl at byte ``value``."""
    shutil.copytree(src, dst)
    if what == "manifest":
        path = os.path.join(dst, "sweep.json")
        with open(path) as fh:
            m = json.load(fh)
        m[key] = value
        with open(path, "w") as fh:
            json.dump(m, fh, default=repr)
    elif what == "record":
        path = os.path.join(dst, "results.jsonl")
        with open(path) as fh:
            lines = fh.read().splitlines()
        rec = json.loads(lines[0])
        rec[key] = value
        lines[0] = json.dumps(rec, default=repr)
        with open(path, "w") as fh:
            fh.write("\n".join(lines) + "\n")
    else:
        path = os.path.join(dst, "results.jsonl")
        with open(path, "rb") as fh:
            data = fh.read()
        with open(path, "wb") as fh:
            fh.write(data[: int(value) % (len(data) + 1)])


LOAD_PARTS = [
    st.tuples(st.just("out"), st.just(""), NASTY),
    st.tuples(st.just("manifest"), st.sampled_from(["format", "I_values", "V_values", "measures", "options",
                                                     "measure_refs", "versions", "nosuch"]), NASTY),
    st.tuples(st.just("record"), st.sampled_from(["I", "V", "status", "regime_label", "nosuch"]), NASTY),
    st.tuples(st.just("truncate"), st.just(""), st.integers(0, 10**6)),
]
LOAD_CASES = st.one_of(*LOAD_PARTS)


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_load_sweep(tier, sweep_dir):
    """Hypothesis: load_sweep on a path of any kind, or on a copy of a finished sweep with one manifest or
    record field set to anything or its results cut anywhere, returns the sweep or raises ValueError/TypeError
    naming ``out`` or the malformed file (never a KeyError, a traceback from json, a wrong result)."""
    def body(case):
        what, key, value = case
        d = tempfile.mkdtemp(prefix="fuzz_load_")
        try:
            if what == "out":
                arg = value
            else:
                arg = os.path.join(d, "s")
                try:
                    _corrupt(sweep_dir, arg, what, key, value)
                except (ValueError, TypeError, OverflowError):  # json cannot write the value: nothing to test
                    return
            names = ["out", "sweep.json", "results.jsonl"]
            classify("load_sweep", lambda: pa.load_sweep(arg), names, f"load_sweep({what} {key}={value!r})")
        finally:
            shutil.rmtree(d, ignore_errors=True)

    run_tier(tier, "load_sweep", LOAD_CASES, body, LOAD_PARTS)


# ---------------------------------------------------------------------------------------------- CLI
CLI_BASE = {
    "simulate": ["--V", "1", "--I", "1e-5", "--t-end", "0.01", "--jumps-only", "--quiet", "--max-wall", "0.3"],
    "folds": ["--V", "1"],
    "estimate": ["--V", "1", "--I", "1e-5"],
    "segment": ["--V", "1", "--I", "1e-5", "--branch", "AB", "--F-in", "250", "--alpha-in", "0.01",
                "--alphadot-in", "0"],
    "dynamics": ["--V", "1", "--I", "1e-5", "--t-transient", "0.02", "--window", "0.1", "--rtol", "1e-8"],
    "sweep": ["--I", "1e-5", "--V", "1", "--workers", "0", "--quiet"],
}
CLI_OPTIONS = {
    "simulate": ["--V", "--I", "--k", "--R", "--l", "--geometry", "--t-end", "--alpha0", "--omega0", "--F0",
                 "--branch0", "--method", "--solver", "--rtol", "--eps", "--max-wall", "--t-transient", "--format"],
    "folds": ["--V", "--format"],
    "estimate": ["--V", "--I", "--k", "--R", "--alpha-min", "--alpha-max", "--format"],
    "segment": ["--V", "--I", "--k", "--R", "--branch", "--F-in", "--alpha-in", "--alphadot-in", "--amplitude",
                "--phase", "--v-in", "--v-f", "--alpha-model", "--v-equation", "--rtol", "--format"],
    "dynamics": ["--V", "--I", "--k", "--R", "--alpha0", "--t-transient", "--window", "--rtol", "--max-period",
                 "--attractors", "--format"],
    "sweep": ["--I", "--V", "--measure", "--workers", "--t-end", "--t-transient", "--rtol", "--alpha0", "--k", "--R",
              "--format"],
}
#: Options whose valid large values mean long runs without a wall budget (see MAX_FUZZ_TIME).
CLI_DURATIONS = {"--t-transient", "--window", "--t-end"}
CLI_TEXT = st.one_of(
    st.sampled_from(["abc", "nan", "inf", "-inf", "0", "-1", "1e-300", "1e300", "", "1e999", "100.0", "True",
                     "None", "-0", "1,2", "0.5", "3", "paper", "AB", "CD", "regularized", "json", "md", "1:2:3",
                     "1e-5:1e-4:2:log", "regime,period", "--V"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-10**6, 10**6).map(str),
    st.text(max_size=4),
)


def _number(text: str) -> Any:
    """The number a command line reads from ``text`` (``float(text)``), else ``text`` itself."""
    try:
        return float(text)
    except (ValueError, OverflowError):
        return text


def _option_names(opt: str) -> list:
    """How an error may name option ``--t-end``: ``--t-end``, ``t-end``, ``t_end`` (and V/I for grids)."""
    bare = opt.lstrip("-")
    names = [opt, bare, bare.replace("-", "_")]
    if opt == "--measure":
        names += ["measure"]
    if opt in ("--t-transient", "--window", "--t-end"):  # the window [t_transient, t_end] is one constraint
        names += ["t_transient", "t_end", "window"]
    if opt in ("--alpha0", "--F-in", "--alpha-in", "--alphadot-in", "--v-in", "--v-f", "--amplitude", "--phase",
               "--branch", "--alpha-model", "--alpha-min", "--alpha-max"):
        names += ["alpha0", "F0", "v_in", "v_f", "alpha_in", "alphadot_in", "amplitude", "phase", "alpha_min",
                  "alpha_max", "branch"]
    return names


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_cli(tier):
    """Hypothesis: every subcommand (except the long compare/benchmark/figures) with one option set to any
    text exits 0, 2 with one error line naming the option and no traceback, or 3 (the model or solver
    stopped); never another status, an exception or a traceback."""
    def body(case):
        cmd, opt, text = case
        d = tempfile.mkdtemp(prefix="fuzz_cli_")
        try:
            argv = list(CLI_BASE[cmd]) + (["--out", os.path.join(d, "s")] if cmd == "sweep" else [])
            if opt in argv:
                argv[argv.index(opt) + 1] = text
            else:
                argv += [opt, text]
            if opt in CLI_DURATIONS:
                assume(short_time(_number(text)))
            where = f"peelapprox {cmd} {' '.join(argv)}"
            err = io.StringIO()

            def call():
                with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
                    try:
                        return cli_main([cmd, *argv])
                    except SystemExit as exc:
                        return exc.code

            try:
                status = call()
                assert "Traceback" not in err.getvalue(), f"{where}: {err.getvalue()}"
                assert status in (0, 2, 3), f"{where}: exit status {status}: {err.getvalue()}"
                if status == 2:
                    assert any(n in err.getvalue() for n in _option_names(opt)), f"{where}: {err.getvalue()}"
            except AssertionError:
                COUNTS["cli", "nonfinite" if "Traceback" not in err.getvalue() else "unhandled"] += 1
                raise
            except BaseException:
                COUNTS["cli", "unhandled"] += 1
                raise
            COUNTS["cli", {0: "result", 2: "arg_error", 3: "model_exc"}[status]] += 1
        finally:
            shutil.rmtree(d, ignore_errors=True)

    cases = st.sampled_from(sorted(CLI_OPTIONS)).flatmap(
        lambda c: st.tuples(st.just(c), st.sampled_from(CLI_OPTIONS[c]), CLI_TEXT))
    parts = [st.tuples(st.just(c), st.just(o), CLI_TEXT) for c in sorted(CLI_OPTIONS) for o in CLI_OPTIONS[c]]
    parts += [st.tuples(st.just(c), st.just("--format"), st.just("json")) for c in sorted(CLI_OPTIONS)]  # valid
    run_tier(tier, "cli", cases, body, parts)


# ---------------------------------------------------------------------------------------------- regressions
#: (label, call, names, kind): the errors the fuzz found, before the fix in the label.  Each must now be a
#: ValueError/TypeError of ``kind`` whose message names the argument.
REGRESSIONS = [
    ("sweep out=None (TypeError from os.fspath, unnamed)",
     lambda d: pa.sweep([1e-5], [1.0], out=None, max_workers=0, progress=False), "out", TypeError),
    ("load_sweep out=None (TypeError from os.fspath, unnamed)", lambda d: pa.load_sweep(None), "out", TypeError),
    ("load_sweep out=1.5 (TypeError from os.fspath, unnamed)", lambda d: pa.load_sweep(1.5), "out", TypeError),
    ("sweep out='a\\0b' (ValueError 'embedded null byte', unnamed)",
     lambda d: pa.sweep([1e-5], [1.0], out=d + "\0", max_workers=0, progress=False), "out", ValueError),
    ("load_sweep out='a\\0b' (ValueError 'embedded null byte', unnamed)", lambda d: pa.load_sweep(d + "\0"), "out",
     ValueError),
    ("sweep measures=None ('NoneType' object is not iterable)",
     lambda d: pa.sweep([1e-5], [1.0], None, out=d, max_workers=0, progress=False), "measures", TypeError),
    ("sweep measures='0' (unknown measure, argument unnamed)",
     lambda d: pa.sweep([1e-5], [1.0], "0", out=d, max_workers=0, progress=False), "measures", ValueError),
    ("sweep executor=array (truth value of an array is ambiguous)",
     lambda d: pa.sweep([1e-5], [1.0], out=d, executor=np.array([1.0, 2.0]), progress=False), "executor",
     ValueError),
    ("sweep I_values=[1000001.0] (accepted; every point an error record)",
     lambda d: pa.sweep([1000001.0], [1.0], out=d, max_workers=0, progress=False), "I_values", ValueError),
    ("sweep V_values='1' (a string taken for 1.0)",
     lambda d: pa.sweep([1e-5], "1", out=d, max_workers=0, progress=False), "V_values", TypeError),
    ("lyapunov d0=8.4e-86 ('the initial perturbation must have a finite positive size', unnamed)",
     lambda d: pa.lyapunov(P, t_transient=0.02, n=2, n_discard=0, rtol=1e-8, d0=8.410893216605485e-86), "d0",
     ValueError),
]


@pytest.mark.parametrize("label, call, name, kind", REGRESSIONS, ids=[r[0] for r in REGRESSIONS])
def test_fuzz_regression_errors_name_the_argument(label, call, name, kind, tmp_path):
    """Hypothesis: each error the fuzz found (its former failure in the label) now raises the stated kind
    before any work, naming the argument; nothing is written to the output directory."""
    out = tmp_path / "s"
    with pytest.raises(kind) as exc:
        call(str(out))
    assert isinstance(exc.value, ValueError)  # ArgumentTypeError is both
    assert name in str(exc.value), str(exc.value)
    assert not out.exists()


def test_fuzz_regression_periodicity_zero_and_huge_returns():
    """Hypothesis: an all-zero return map is the constant sequence (period 1, mismatch 0; it divided by
    max|x| = 0: ZeroDivisionError), and returns near the float maximum give a finite mismatch (the
    differences overflowed to inf).  Exact values: the sequences repeat exactly."""
    p = pa.periodicity([0.0] * 5)
    assert (p.kind, p.period, p.mismatch) == ("periodic", 1, 0.0)
    p = pa.periodicity([1e308, -1e308, 0.0] * 50)
    assert (p.kind, p.period, p.mismatch) == ("periodic", 3, 0.0)
    # not periodic below n = 3: the smallest mismatch tried, max|x_{k+n} - x_k| / max|x| = 2 (n = 1, 2), finite
    p = pa.periodicity([1e308, -1e308, 0.0] * 50, max_period=2)
    assert p.kind == "aperiodic" and p.mismatch == 2.0


# ---------------------------------------------------------------------------------------------- PeelForce
#: A valid table: the default cubic law (folds at 0.691 and 1.809 m/s) on 12 points of [0.1, 3] m/s.
TABLE_V = np.exp(np.linspace(math.log(0.1), math.log(3.0), 12))
TABLE_F = 150 + TABLE_V * (300 + TABLE_V * (-300 + 80 * TABLE_V))
#: Names a bad table's message may give: the array and index, or the rule it breaks.
TABLE_NAMES = ("v[", "f[", "v must", "f must", "v and f", "peel-force table", "V must", "V=")


def check_law(law: Any, where: str) -> None:
    """A law built from a table: its folds (at its V, or 1 m/s) are finite and ordered."""
    fo = law.folds(law.tables[0][0] or 1.0)
    assert fo.has_folds and _all_finite([fo.v_max, fo.f_max, fo.v_min, fo.f_min]), f"{where}: {fo}"
    assert fo.v_max < fo.v_min and fo.f_max > fo.f_min, f"{where}: {fo}"


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_tabulated_law(tier):
    """Hypothesis: a table with one entry of v or f (or V, or a whole array) replaced by anything builds a law
    whose folds are finite and ordered, or raises ValueError/TypeError naming the array and index (or V)."""
    args = {
        "v[i]": st.tuples(st.integers(0, 11), nasty_or(edges(0.05, 5.0))),
        "f[i]": st.tuples(st.integers(0, 11), nasty_or(edges(1.0, 1e3))),
        "v": NASTY, "f": NASTY, "V": nasty_or(edges(1e-6, 100.0)),
    }

    def body(case):
        name, value = case
        v, f, kw = TABLE_V.copy(), TABLE_F.copy(), {}
        if name in ("v[i]", "f[i]"):
            i, x = value
            try:
                (v if name == "v[i]" else f)[i] = x
            except (TypeError, ValueError, OverflowError):
                return  # not a float: the whole-array cases cover it
        elif name == "V":
            kw["V"] = value
        else:
            v, f = (value, f) if name == "v" else (v, value)
        classify("PeelForce.tabulated", lambda: pa.PeelForce.tabulated(v, f, **kw), TABLE_NAMES,
                 f"PeelForce.tabulated({name}={value!r})", check=check_law)

    run_tier(tier, "PeelForce.tabulated", one_of_args(args), body, each_arg(args))


#: Names a refused law's message may give (the law is a field of params).
LAW_NAMES = ("params.force", "force", "v[", "f[", "v must", "f must", "coefficient", "a must", "b must", "c must",
             "d must")
#: A law that runs: a cubic with any coefficients (folds or none, landings or none), or the test table with
#: one force scaled (its folds moved, or the table refused), each run by the hybrid or the regularised solver.
LAW_PARTS = [
    st.tuples(st.just("cubic"), st.tuples(*(nasty_or(edges(1e-3, 1e3)) for _ in range(4)))),
    st.tuples(st.just("table"), st.tuples(st.integers(0, 11), edges(0.5, 2.0))),
]
LAW_CASES = st.one_of(*LAW_PARTS)


@pytest.mark.parametrize("tier", TIERS)
def test_fuzz_simulate_with_a_law(tier):
    """Hypothesis: ``simulate`` of a law with odd coefficients or a perturbed table (hybrid for the even draws,
    regularised at ε = 1e-4 for the odd ones) returns a finite trajectory, raises ValueError/TypeError naming
    the law (params.force, a coefficient, a table entry), or stops with a documented model exception (a
    breakdown such as ``law_domain`` or ``no_landing``) with a finite time and state: never another exception,
    never a non-finite number."""
    def body(case):
        kind, value = case
        try:
            if kind == "cubic":
                law = pa.PeelForce.cubic(*value)
            else:
                i, scale = value
                f = TABLE_F.copy()
                f[i] = f[i] * scale
                law = pa.PeelForce.tabulated(TABLE_V, f)
        except (ValueError, TypeError) as exc:
            assert any(n in str(exc) for n in LAW_NAMES), f"{case}: {exc}"
            COUNTS["simulate with a law", "arg_error"] += 1
            return
        p = PeelParams(V=1.2, I=1e-3, force=law)
        method = dict(method="regularized", eps=1e-4) if hash(repr(case)) % 2 else {}
        classify("simulate with a law", lambda: exact.simulate(p, 0.05, max_wall=30.0, **method), LAW_NAMES,
                 f"simulate({law!r}, {method})")

    run_tier(tier, "simulate with a law", LAW_CASES, body, LAW_PARTS)


def test_fuzz_regression_lyapunov_tangent_without_transient():
    """Hypothesis: lyapunov_tangent(t_transient=0) (valid: [0, 1e6]) starts from the initial state; it called
    simulate with t_end = 0 and raised "t_end must be ... got 0.0" naming no argument of the call.  The
    exponent must be finite and the measured time T = 10 ms (within 1%: the tangent run ends with the step
    that reaches T, 0.3% past it here)."""
    r = pa.lyapunov_tangent(P, t_transient=0, T=0.01, rtol=1e-8)
    assert math.isfinite(r.bits_per_s)
    assert r.benettin.time == pytest.approx(0.01, rel=1e-2)


def test_fuzz_regression_cli_attractors_named_as_written():
    """Hypothesis: ``dynamics --attractors 4.0`` is refused before the run with the option's name (it was
    reported as ``alpha0s``, the library's argument, after the window run): exit status 2, one line."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        with pytest.raises(SystemExit) as exc:
            cli_main(["dynamics", "--V", "1", "--I", "1e-5", "--t-transient", "0.02", "--window", "0.1",
                      "--attractors", "4.0"])
    assert exc.value.code == 2
    assert err.getvalue().startswith("peelapprox dynamics: error: --attractors must be finite and in [-3.14159, ")
    assert err.getvalue().count("\n") == 1


# ---------------------------------------------------------------------------------------- stored files
#: Any JSON value: what a malformed file's metadata or a stored law's field may hold.
_JSON = st.recursive(st.none() | st.booleans() | st.integers(-2**70, 2**70) | st.floats(allow_nan=False)
                     | st.text(max_size=30),
                     lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner,
                                                                                 max_size=4), max_leaves=12)
_META_KEYS = ("params", "stats", "method", "solver", "rtol", "eps", "initial_state", "final_state", "t_end",
              "t_transient", "status", "message", "stats.n_steps", "stats.wall_time", "initial_state.t",
              "final_state.branch", "params.V", "params.force", "params.force.kind", "params.force.name")
_ARRAYS = st.sampled_from(["t", "alpha", "omega", "F", "v", "branch", "jumps", "atol", "Vp"])
_ARRAY_VALUES = st.one_of(
    st.lists(st.floats(), max_size=6).map(np.array),
    st.lists(st.integers(-3, 3), max_size=6).map(np.array),
    st.lists(st.text(max_size=5), max_size=3).map(np.array),
    st.floats().map(np.array),
    st.integers(0, 20).map(lambda n: np.zeros((n, 8))),
    st.integers(0, 3).map(lambda n: np.zeros((n, 3, 2))),
)


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    from exact import simulate

    path = tmp_path_factory.mktemp("npzfuzz") / "run.npz"
    simulate(PeelParams(V=1.0, I=1e-5, force=PeelForce.cubic()), 0.02).to_npz(path)
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    return arrays, json.loads(str(arrays["meta"]))


def _load_classified(path) -> str:
    """``Trajectory.from_npz(path)``: "result" (every array finite) or "named" (a ValueError naming the file and
    a field, or the file as no npz); anything else fails."""
    from exact import Trajectory

    try:
        tr = Trajectory.from_npz(path)
    except ValueError as exc:
        msg = str(exc)
        assert msg.startswith("Trajectory.from_npz(") and ("field " in msg or "not a trajectory file" in msg), msg
        return "named"
    for name in ("t", "alpha", "omega", "F", "v"):
        assert np.all(np.isfinite(getattr(tr, name)))
    assert tr.t.size == tr.F.size and tr.t_end >= 0 and tr.final_state.branch in ("AB", "CD")
    return "result"


@pytest.mark.slow
@settings(max_examples=400, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(_META_KEYS), value=_JSON)
def test_fuzz_trajectory_file_metadata(run_file, tmp_path, key, value):
    """One metadata field of a valid run's file replaced by any JSON value: the file loads with finite arrays or
    is refused by a ValueError naming the file and the field (never KeyError, TypeError, RecursionError...)."""
    import copy

    arrays, meta = run_file
    meta = copy.deepcopy(meta)
    *path, last = key.split(".")
    target = meta
    for p in path:
        target = target[p] if isinstance(target, dict) else {}
    target[last] = value
    out = tmp_path / "f.npz"
    np.savez(out, **{**arrays, "meta": np.array(json.dumps(meta))})
    _load_classified(out)


@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(key=_ARRAYS, value=_ARRAY_VALUES)
def test_fuzz_trajectory_file_arrays(run_file, tmp_path, key, value):
    """One array of a valid run's file replaced by an array of another length, shape, dtype or with NaN: loads
    or is refused by name (as above)."""
    arrays, _meta = run_file
    out = tmp_path / "f.npz"
    np.savez(out, **{**arrays, key: value})
    _load_classified(out)


@pytest.mark.slow
@settings(max_examples=400, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(d=st.fixed_dictionaries({"kind": st.sampled_from(["paper", "family", "expression", "tabulated", "smoothed"])
                                | _JSON},
                               optional={"name": st.sampled_from(["cubic", "paper", "power_branches"]) | _JSON,
                                         "coefficients": _JSON, "source": _JSON, "tables": _JSON,
                                         "display": _JSON}))
def test_fuzz_peelforce_from_dict(d):
    """A stored law's fields of any JSON value: a law, or a ValueError/TypeError (never another exception:
    ``unhashable type``, ``dictionary update sequence``, an AttributeError)."""
    try:
        law = PeelForce.from_dict(d)
    except (ValueError, TypeError):
        return
    assert isinstance(law, PeelForce)
