"""``exact.lyapunov(params, method, ...)``: the one entry point of the Lyapunov family.

The methods' numbers are tested in tests/test_dynamics.py (known exponents, agreement between methods) and
bitwise against the named entry points here: the dispatcher must add nothing to the computation.
"""

from __future__ import annotations

import time

import pytest

import exact
import peelapprox
from exact import SolverBudgetExceeded, lyapunov, lyapunov_return_map, lyapunov_tangent
from peelapprox import PeelParams

P = PeelParams(V=1.0, I=1e-3)  # period 5-ish stick-slip, ~20 jumps/s: short runs see several jumps


def _forbid_runs(monkeypatch) -> None:
    """Every method's runner replaced by one that fails the test: a refusal "before any run" is then checked
    as such, not by a wall-clock bound (which a loaded machine can break, and a short run can meet)."""
    import exact.dynamics._lyapunov as L
    import exact.dynamics._variational as V

    def ran(*args, **kwargs):
        raise AssertionError("a Lyapunov run started")

    for module, name in ((L, "_two_trajectory"), (L, "_tangent"), (L, "_return_map"), (V, "lyapunov_variational")):
        monkeypatch.setattr(module, name, ran)


@pytest.fixture
def no_run(monkeypatch):
    """:func:`_forbid_runs` for the whole test."""
    _forbid_runs(monkeypatch)


def test_default_method_is_the_two_trajectory_lyapunov_that_peelapprox_offers():
    """Hypothesis: ``peelapprox.lyapunov`` is ``exact.lyapunov`` (identity), its default method is
    "two-trajectory" with today's defaults (read from the signature: t_transient 30 s, alpha0 0, max_wall
    3600 s), and a short default-method run equals the explicit ``method="two-trajectory"`` one bitwise
    (same per_s, stderr, jump count, running estimate)."""
    import inspect

    assert peelapprox.lyapunov is lyapunov
    sig = inspect.signature(lyapunov).parameters
    assert sig["method"].default == "two-trajectory" and sig["t_transient"].default == 30.0
    assert sig["alpha0"].default == 0.0 and sig["max_wall"].default == exact.DEFAULT_MAX_WALL == 3600.0
    kw = dict(t_transient=0.5, n=20, n_discard=2)
    a, b = lyapunov(P, **kw), lyapunov(P, "two-trajectory", **kw)
    assert a.method == b.method == "hybrid two-trajectory (Benettin)"
    assert (a.per_s, a.stderr_bits, a.n_jumps) == (b.per_s, b.stderr_bits, b.n_jumps)
    assert list(a.benettin.running) == list(b.benettin.running)


def test_tangent_method_equals_lyapunov_tangent_bitwise():
    """Hypothesis: ``lyapunov(p, "tangent", T=..., max_steps=...)`` runs exactly ``lyapunov_tangent`` (the
    default wall budget is only checked between jumps, it changes no step): equal exponent, jump count,
    integrated time and step count (exact equality).  rtol=None is the method's default 1e-10."""
    kw = dict(t_transient=0.5, T=1.0, max_steps=10**6)
    a, b = lyapunov(P, "tangent", **kw), lyapunov_tangent(P, **kw)
    assert (a.per_s, a.n_jumps, a.benettin.time, a.notes) == (b.per_s, b.n_jumps, b.benettin.time, b.notes)
    assert a.method == "tangent dynamics with saltation matrices"
    c = lyapunov(P, "tangent", rtol=1e-10, **kw)
    assert c.per_s == a.per_s


def test_return_map_method_equals_lyapunov_return_map_bitwise():
    """Hypothesis: ``lyapunov(p, "return-map", n_returns=..., h=...)`` from alpha0 = 0 runs exactly
    ``lyapunov_return_map``: equal exponent, standard error and local rates (exact equality)."""
    kw = dict(t_transient=1.0, n_returns=6, h=1e-6)
    a, b = lyapunov(P, "return-map", **kw), lyapunov_return_map(P, **kw)
    assert (a.per_s, a.stderr_bits, a.n_jumps) == (b.per_s, b.stderr_bits, b.n_jumps)
    assert list(a.benettin.local) == list(b.benettin.local)
    assert a.method == "tangent map of the AB→CD return map (central differences)"


def test_unknown_method_lists_the_methods():
    """Hypothesis: an unknown method is a ValueError listing all four methods; a non-string method is an
    ArgumentTypeError (a TypeError) naming ``method`` (message checked by substring)."""
    with pytest.raises(ValueError, match="method must be one of") as ei:
        lyapunov(P, "benettin")
    for m in ("two-trajectory", "tangent", "return-map", "variational"):
        assert repr(m) in str(ei.value)
    with pytest.raises(TypeError, match="method"):
        lyapunov(P, 3)


@pytest.mark.parametrize("method, option, owner", [
    ("tangent", "n", "two-trajectory"),
    ("return-map", "T", "tangent"),
    ("return-map", "d0", "two-trajectory"),
    ("two-trajectory", "eps", "variational"),
    ("variational", "n_returns", "return-map"),
    ("tangent", "window", None),
])
def test_an_option_of_another_method_is_refused_by_name(no_run, method, option, owner):
    """Hypothesis: an option the chosen method does not take raises before any run a TypeError (also a
    ValueError, peelapprox's ArgumentTypeError) naming the option, the chosen method and, when it is another
    method's option, that method (substrings; categorical).  The variational case needs no pydiffsol: the
    check comes first.  (T is now also an option of two-trajectory, so the row that refused T for
    two-trajectory asks return-map, the one method without T.)"""
    with pytest.raises(TypeError) as ei:  # refused up front: no_run fails the test if a run starts
        lyapunov(P, method, **{option: 1})
    assert isinstance(ei.value, ValueError)
    msg = str(ei.value)
    assert repr(option) in msg and f"method={method!r}" in msg
    assert (repr(owner) in msg) if owner else "no method" in msg


@pytest.mark.parametrize("method, kw, name", [
    ("two-trajectory", dict(tau=-1.0), "tau"),
    ("two-trajectory", dict(d0=1e-20), "d0"),
    ("tangent", dict(T=0.0), "T"),
    ("tangent", dict(max_steps=2.5), "max_steps"),
    ("return-map", dict(h=0.0), "h"),
    ("return-map", dict(alpha0=9.0), "alpha0"),
    ("tangent", dict(max_wall=-1.0), "max_wall"),
    ("two-trajectory", dict(rtol=1.0), "rtol"),
])
def test_bad_values_are_refused_by_each_method_naming_the_argument(method, kw, name):
    """Hypothesis: each method validates its own options and the common arguments with the validators of
    peelapprox.validate: a bad value is a ValueError (or ArgumentTypeError) whose message starts with the
    argument's name (categorical)."""
    with pytest.raises(ValueError, match=rf"^{name} "):
        lyapunov(P, method, **kw)


def test_tangent_method_honours_the_wall_budget():
    """The tangent method's compiled loop cannot watch a clock; through ``lyapunov`` the wall budget is
    checked after every jump.  Hypothesis: T = 1000 s (about 1000 s of work) with max_wall = 0.3 s raises
    SolverBudgetExceeded(budget="max_wall", limit=0.3) with a finite state on the orbit (categorical; no
    wall time asserted)."""
    import math

    with pytest.raises(SolverBudgetExceeded) as ei:
        lyapunov(P, "tangent", t_transient=0.5, T=1000.0, max_wall=0.3)
    e = ei.value
    assert e.budget == "max_wall" and e.limit == 0.3
    assert all(math.isfinite(e.state[k]) for k in ("t", "alpha", "omega", "F", "v")) and e.state["v"] > 0


def test_variational_wall_watch_raises_between_intervals():
    """The variational method gets its wall budget through its ``progress`` callback (called after every
    renormalisation interval).  Hypothesis: the watcher calls the user's progress while the budget lasts and
    raises SolverBudgetExceeded(budget="max_wall") with the interval's time once it is spent (categorical)."""
    from exact.dynamics._lyapunov import _watch_wall
    from peelapprox.errors import WallBudget

    seen = []
    watch = _watch_wall(WallBudget(0.05), lambda t, T: seen.append((t, T)))
    watch(0.5, 10.0)
    assert seen == [(0.5, 10.0)]
    time.sleep(0.1)
    with pytest.raises(SolverBudgetExceeded) as ei:
        watch(1.0, 10.0)
    assert ei.value.budget == "max_wall" and ei.value.t == 1.0 and seen == [(0.5, 10.0)]


def test_variational_method_refuses_a_bad_eps_and_equals_lyapunov_variational():
    """Hypothesis: ``lyapunov(p, "variational", eps=1e-300)`` is refused by the method's own validator with a
    ValueError naming ``eps``; a short run (V = 0.05, I = 1e-2: a stable sliding point, 2 s after 1 s) equals
    ``exact.lyapunov_variational`` with the same arguments bitwise (the wall watcher only wraps ``progress``).
    Skipped without the optional pydiffsol (the ``[bench]`` extra)."""
    pytest.importorskip("pydiffsol")
    p = PeelParams(V=0.05, I=1e-2)
    with pytest.raises(ValueError, match=r"^eps "):
        lyapunov(p, "variational", eps=1e-300)
    a = lyapunov(p, "variational", t_transient=1.0, T=2.0)
    b = exact.lyapunov_variational(p, t_transient=1.0, T=2.0)
    assert (a.per_s, a.stderr_bits, a.n_jumps, a.notes) == (b.per_s, b.stderr_bits, b.n_jumps, b.notes)


def test_two_trajectory_T_is_round_T_over_tau_intervals_and_excludes_n(monkeypatch):
    """``T`` (measured seconds) is common to the methods that measure a time.  Hypothesis: for
    two-trajectory ``T`` runs ``n = max(2, round(T/tau))`` intervals, bitwise the run with that ``n`` (0.1 s is
    20 intervals of 0.005 s; 0.0124 s rounds to 2); giving both ``T`` and ``n`` is a ValueError naming both,
    raised before any run (substrings)."""
    kw = dict(t_transient=0.5, n_discard=2)
    a, b = lyapunov(P, T=0.1, **kw), lyapunov(P, n=20, **kw)
    assert (a.per_s, a.stderr_bits, a.n_jumps) == (b.per_s, b.stderr_bits, b.n_jumps)
    assert list(a.benettin.running) == list(b.benettin.running)
    c, d = lyapunov(P, T=0.0124, **kw), lyapunov(P, n=2, **kw)
    assert (c.per_s, c.n_jumps) == (d.per_s, d.n_jumps)
    _forbid_runs(monkeypatch)  # the runs above done: from here a run fails the test (refused before any run)
    with pytest.raises(ValueError, match=r"T .*n .*not both") as ei:
        lyapunov(P, T=1.0, n=200)
    assert "T=1.0" in str(ei.value) and "n=200" in str(ei.value)


def test_check_lyapunov_options_checks_without_running(no_run):
    """Hypothesis: ``exact.check_lyapunov_options(method, **options)`` returns the method and raises the
    errors ``lyapunov`` would raise for the options (bad eps, T with n, another method's option, unknown
    method), without running (``no_run``) and without pydiffsol (categorical; messages by substring)."""
    from exact import check_lyapunov_options

    assert check_lyapunov_options("variational", eps=1e-7, T=5.0, progress=None) == "variational"
    assert check_lyapunov_options() == "two-trajectory"
    with pytest.raises(ValueError, match=r"^eps must be finite and in \[1e-15, 0.01\], got 1e-30"):
        check_lyapunov_options("variational", eps=1e-30)
    with pytest.raises(ValueError, match="not both"):
        check_lyapunov_options("two-trajectory", T=1.0, n=10)
    with pytest.raises(TypeError, match="'n_returns' is an option of method 'return-map'"):
        check_lyapunov_options("tangent", n_returns=10)
    with pytest.raises(ValueError, match="method must be one of"):
        check_lyapunov_options("saltation")


def test_return_map_takes_alpha0_like_the_dispatcher():
    """``lyapunov_return_map`` takes ``alpha0`` as ``lyapunov(p, "return-map", ...)`` does.
    Hypothesis: from alpha0 = 0.1 the two are equal bitwise (exponent, standard error, local rates), and the
    start matters (a different exponent than from 0: the transient's last section crossing moves)."""
    kw = dict(t_transient=1.0, n_returns=6, h=1e-6)
    a, b = lyapunov(P, "return-map", alpha0=0.1, **kw), lyapunov_return_map(P, alpha0=0.1, **kw)
    assert (a.per_s, a.stderr_bits, a.n_jumps) == (b.per_s, b.stderr_bits, b.n_jumps)
    assert list(a.benettin.local) == list(b.benettin.local)
    assert a.per_s != lyapunov_return_map(P, **kw).per_s


def test_tangent_and_return_map_results_carry_no_nan():
    """Hypothesis ("never NaN in a result"): the tangent method records its renormalisations at the jumps, so
    its result has a finite standard error (from the local rates between jumps) and a finite mean
    renormalisation interval ``tau`` (time / intervals), as the return-map method does; the record's exponent is
    the method's exponent exactly, and its running estimate ends on it to 1e-12 relative (the same logs summed
    in another order)."""
    import math

    p = PeelParams(V=1.0, I=1e-3)
    for r in (exact.lyapunov(p, "tangent", t_transient=2.0, T=2.0),
              exact.lyapunov(p, "return-map", t_transient=2.0, n_returns=20)):
        assert all(math.isfinite(x) for x in (r.per_s, r.bits_per_s, r.stderr_bits, r.tau, r.benettin.d0))
        assert r.tau > 0 and r.stderr_bits > 0 and r.benettin.exponent == r.per_s
        assert abs(r.benettin.running[-1] - r.per_s) <= 1e-12 * abs(r.per_s)


def test_tangent_record_short_runs_have_no_empty_batch():
    """Hypothesis: a run shorter than its batching (T = 0.05 s, a handful of jumps, one long interval) makes
    no empty batch: every batch has a positive duration, and the standard error is a number or inf (fewer
    than two batches), never NaN (a 0/0 of an empty batch once made it NaN, with a RuntimeWarning)."""
    import math
    import warnings

    from peelapprox import PeelParams

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        for T in (0.05, 0.3):
            r = exact.lyapunov(PeelParams(V=1.0, I=1e-3), "tangent", t_transient=1.0, T=T)
            assert not math.isnan(r.stderr_bits) and (r.benettin.local.size == 0 or r.tau > 0)
