"""Where branches of periodic orbits end or turn: folds passed by pseudo-arclength steps, period doublings with
the switch to the doubled branch, the crest event and the grazing (docs/orbits.md)."""

import numpy as np
import pytest

import exact
import peelapprox as pa
from exact import solve_orbit

FVV_1E3 = pa.PeelParams(V=1.0, I=1e-3)
FVV_1E5 = pa.PeelParams(V=1.0, I=1e-5)


@pytest.fixture(scope="module")
def branch_1e3():
    """fvV at I = 1e-3: the period-5 attractor at V = 1 continued down in V (a period doubling, a
    Neimark-Sacker, a fold, a grazing; ~3 s)."""
    o = exact.periodic_orbit(FVV_1E3, t_transient=40, window=20)
    assert o.n == 5
    return exact.continue_orbit(o, "V", stop=0.5, max_points=300)


def _one(branch, kind, near=None):
    found = [x for x in branch.bifurcations if x.kind == kind and (near is None or abs(x.value - near) < 1e-3)]
    assert len(found) == 1, [(x.kind, x.value) for x in branch.bifurcations]
    return found[0]


def test_the_bifurcations_in_order(branch_1e3):
    """Hypothesis: down from V = 1 the period-5 branch meets, in this order, a period doubling (V = 0.978457,
    the multiplier leaves the unit circle through -1), a second one (0.934722, it comes back through -1), a
    Neimark-Sacker (0.931529: the real pair, joined into a complex pair, crosses the unit circle) and a fold
    (0.931491); each located orbit has its gauge within 1e-6 of 0 (the bisection's tolerance); the branch ends
    in a grazing just beyond the fold.  (Values to 1e-6: the bisection locates them to 1e-8 relative.)"""
    b = branch_1e3
    got = [(x.kind, round(x.value, 6)) for x in b.bifurcations]
    assert got == [("period_doubling", 0.978457), ("period_doubling", 0.934722), ("neimark_sacker", 0.931529),
                   ("fold", 0.931491)]
    for x in b.bifurcations:
        mu = x.orbit.multipliers
        gauge = {"fold": np.min(np.abs(mu - 1)), "period_doubling": np.min(np.abs(mu + 1)),
                 "neimark_sacker": abs(abs(mu[0]) - 1)}[x.kind]
        assert gauge <= 1e-6, (x.kind, mu)
    assert b.stopped == "grazing"


def test_fold_is_passed_and_located(branch_1e3):
    """Hypothesis: the branch turns back in V at a fold (saddle-node): the pseudo-arclength steps pass it (V
    falls to a minimum and rises again), it is located where a real multiplier is +1 (to 1e-6, the bisection's
    gauge tolerance, within 1e-5 for slack), and the fold is real: just above it (5e-8) Newton at fixed V from a
    point on either side of the fold closes two distinct orbits (one multiplier above 1, the other's below:
    the saddle and the node), just below it Newton at fixed V does not close an orbit from the fold's state."""
    b = branch_1e3
    f = _one(b, "fold")
    assert f.value == pytest.approx(0.93149064, abs=1e-7)
    assert np.min(np.abs(f.orbit.multipliers - 1.0)) <= 1e-5
    vals = np.array([p.value for p in b.points])
    k = int(np.argmin(vals))
    assert 0 < k < len(vals) - 1 and 0 <= vals[k] - f.value < 1e-8  # the lowest point, just above the fold
    d = 5e-8
    pre = max(j for j in range(k + 1) if vals[j] > f.value + d)
    post = min(j for j in range(k, len(vals)) if vals[j] > f.value + d)
    P = FVV_1E3.replace(V=f.value + d)
    o1 = solve_orbit(P, b.points[pre].orbit.section_states[0], 5)
    o2 = solve_orbit(P, b.points[post].orbit.section_states[0], 5)
    assert np.linalg.norm((o1.section_states[0] - o2.section_states[0]) / [1, 10]) > 1e-4
    mu1, mu2 = sorted(np.abs(o1.multipliers))[0], sorted(np.abs(o2.multipliers))[0]
    assert (mu1 - 1) * (mu2 - 1) < 0
    with pytest.raises(ValueError, match="did not close"):
        solve_orbit(FVV_1E3.replace(V=f.value - d), f.orbit.section_states[0], 5, max_iter=20)


def test_period_doubling_and_the_doubled_branch(branch_1e3):
    """Hypothesis: the period-5 orbit loses stability in a period doubling at V = 0.978457 (μ = -1 to 1e-6);
    the orbit ``switch_branch`` finds there has period 10, multipliers (1, μ₂²) to first order (μ₂ the
    period-5 orbit's other multiplier, -0.3385: the doubled orbit's second multiplier equals its square to
    1e-3 relative, its first is 1 to 1e-3: a pitchfork of P¹⁰), and lies on the side where the period-5 orbit
    is unstable (supercritical); continued down, the doubled branch is stable and is the long run's attractor:
    at its point nearest V = 0.975 a 100 s run's last 10 return-map values equal the orbit's, as sets, to 1e-8
    relative."""
    pd = _one(branch_1e3, "period_doubling", near=0.978457)
    assert pd.value == pytest.approx(0.978457, abs=1e-6) and pd.parameter == "V"
    assert np.min(np.abs(pd.orbit.multipliers + 1.0)) <= 1e-6
    o10 = exact.switch_branch(pd)
    assert o10.n == 10 and o10.residual <= 1e-10 and o10.params.V < pd.value
    mu2 = pd.orbit.multipliers[np.argmax(np.abs(pd.orbit.multipliers + 1.0))].real
    mus = np.sort(o10.multipliers.real)
    assert mus[1] == pytest.approx(1.0, abs=1e-3) and mus[0] == pytest.approx(mu2 ** 2, rel=1e-3)
    b10 = exact.continue_orbit(o10, "V", stop=0.9, max_points=60)
    assert all(p.orbit.n == 10 for p in b10.points) and b10.points[-1].value < 0.972
    p = min(b10.points, key=lambda q: abs(q.value - 0.975))
    assert p.orbit.stable
    tr = exact.simulate(p.orbit.params, 100.0, rtol=1e-12, save="jumps", t_transient=80.0)
    np.testing.assert_allclose(np.sort(pa.return_map(tr)[-10:]), np.sort(p.orbit.return_map_values), rtol=1e-8)
    with pytest.raises(ValueError, match="period_doubling"):
        exact.switch_branch(_one(branch_1e3, "fold"))


@pytest.fixture(scope="module")
def branch_1e5_up():
    """fvV at I = 1e-5: the period-3 attractor at V = 1 continued up in V (it ends in a crest event; ~2 s)."""
    return exact.continue_orbit(exact.periodic_orbit(FVV_1E5, n=3), "V", stop=1.5)


def _up_jumps(orbit, V):
    """AB->CD jump times [s] of a one-period run (x 1.02) at velocity ``V`` from ``orbit``'s first section state."""
    a, w = orbit.section_states[0]
    tr = exact.simulate(orbit.params.replace(V=V), 1.02 * orbit.period, alpha0=float(a), omega0=float(w),
                        F0=float(orbit.return_map_values[0]), branch0="CD", rtol=1e-12, save="jumps")
    return tr.jumps.t[tr.jumps.from_branch == 0]


def test_crest_event_ends_the_branch(branch_1e5_up):
    """Hypothesis: the period-3 branch ends where an interior crest of F (1 + sin α) on AB reaches f_max, at V =
    1.0020700 (linear extrapolation of the crest margin, which falls below 1e-6 of f_max - f_min at the last
    point).  Checked by direct simulation from the last orbit's state for one period, at dV on either side of the
    event: below it the three AB->CD jumps close the period (the third at its end, to 1e-4 s); above it the
    regular jump that follows the crest (3.5 ms later) comes instead at the crest's own time (to 1e-4 s), the
    jumps before it unchanged (to 1e-4 s).

    Which of the three jumps follows the crest depends on which jump the orbit's section starts from, and
    periodic_orbit picks it by a near-recurrence that round-off decides (on one CPU the crest precedes the first
    jump, on another the third): the test finds it (the first regular jump after the crest) instead of assuming
    it.  dV is 20 times the distance from the last point to the event, measured from the crest margin's slope
    over the last two points (~1.5e-5): far beyond the extrapolation's error (its curvature moves the event by
    < 1e-8), the margin then about +-1e-5 of f_max - f_min (6 orders above the runs' rtol), while the crest time
    drifts only ~0.1 s per unit V (2e-6 s at dV), well inside the 1e-4 s tolerance, itself 35 times below the
    3.5 ms that tell the crest's time from the regular jump's."""
    b = branch_1e5_up
    assert b.stopped == "crest" and "crest" in b.message
    assert b.end_value == pytest.approx(1.0020700, abs=2e-7)
    last, prev = b.points[-1].orbit, b.points[-2].orbit
    c, c_prev = exact.crest_margin(last), exact.crest_margin(prev)
    assert c.branch == "AB" and c.margin < 1e-6 and c.floor > 0.5
    slope = (c.margin - c_prev.margin) / (last.params.V - prev.params.V)  # per unit V, falling to 0 at the event
    assert slope < 0
    dV = 20 * c.margin / -slope
    assert 1e-6 < dV < 1e-4
    below, above = _up_jumps(last, b.end_value - dV), _up_jumps(last, b.end_value + dV)
    assert len(below) == 3 and below[2] == pytest.approx(last.period, abs=1e-4)
    k = int(np.searchsorted(below, c.t))  # the regular jump the crest precedes
    assert k < 3 and below[k] - c.t > 3e-3
    assert len(above) >= k + 1 and above[k] == pytest.approx(c.t, abs=1e-4)
    assert above[:k] == pytest.approx(below[:k], abs=1e-4)


def test_grazing_end_is_extrapolated_beyond_the_last_point(branch_1e3):
    """Hypothesis: the period-5 branch at I = 1e-3, which after its fold runs up in V, ends in a grazing: its
    largest multiplier grows at each of the last 5 points and exceeds 30 at the last (it diverges there: 11 five
    points before, 35 at the last); the grazing's parameter, extrapolated from the squared fold rate, lies
    beyond the last point in the direction of travel (above it) by less than 1e-5 of V (the rate falls like the
    square root of the distance).  The default tier's grazing end (the module's branch, computed once); the
    same end of a branch running down in V is the slow test below."""
    b = branch_1e3
    assert b.stopped == "grazing" and "grazing" in b.message
    growth = [float(np.max(np.abs(p.orbit.multipliers))) for p in b.points[-5:]]
    assert all(x < y for x, y in zip(growth, growth[1:])) and growth[-1] > 30, growth
    assert b.points[-1].value > b.points[-2].value  # running up in V, past the fold
    assert 0 <= b.end_value - b.points[-1].value < 1e-5


@pytest.mark.slow
def test_grazing_end_is_extrapolated_below_the_last_point():
    """Hypothesis: fvV's period-3 orbit at I = 1e-5 continued down in V passes a period doubling at V =
    0.998547 and ends in a grazing (its slowest fold rate falls towards 0 and its multiplier diverges, beyond
    -100); the grazing's parameter, extrapolated from the squared fold rate, lies below the last point by less
    than 1e-5 of V (the rate falls like the square root of the distance).  Slow (~20 s CPU: 24 points, most
    within 1e-4 of the grazing); covered in the default tier by
    ``test_grazing_end_is_extrapolated_beyond_the_last_point`` (the same end on the module's I = 1e-3 branch)
    and ``test_period_doubling_and_the_doubled_branch`` (a period doubling located to 1e-6)."""
    b = exact.continue_orbit(exact.periodic_orbit(FVV_1E5, n=3), "V", stop=0.5)
    assert [x.kind for x in b.bifurcations] == ["period_doubling"]
    assert b.bifurcations[0].value == pytest.approx(0.998547, abs=1e-6)
    assert b.stopped == "grazing"
    last = b.points[-1]
    assert np.max(np.abs(last.orbit.multipliers)) > 100
    assert 0 <= last.value - b.end_value < 1e-5


def test_cli_bifurcation_switches_to_the_doubled_branch(tmp_path, capsys):
    """Hypothesis: ``peelapprox bifurcation`` over V in [0.975, 0.98] at I = 1e-3 seeded at 0.98 continues the
    period-5 branch through its period doubling, starts the doubled branch there (``--switch 1``) and continues
    it; each of the 3 brute-force values is explained by a stable branch of its own period (exact.explain):
    0.98 by the period-5 branch (its 40 s run still reads period 10: the multiplier -0.97 decays slowly, and
    the seed orbit is reduced to its own period 5), 0.9775 and 0.975 (beyond the doubling) by the period-10
    one; the end of each branch is a row."""
    import json

    from peelapprox.cli import main

    out = tmp_path / "b.json"
    assert main(["bifurcation", "--V", "1", "--I", "1e-3", "--param", "V", "--range", "0.975:0.98:3", "--seeds",
                 "0.98", "--t-transient", "40", "--window", "20", "--switch", "1", "--out", str(out)]) == 0
    assert "explained: 3 of the 3 periodic values" in capsys.readouterr().err
    rows = json.loads(out.read_text())
    diag = {r["V"]: r for r in rows if r["kind"] == "diagram"}
    n_of = {r["kind"]: r["n"] for r in rows if r["kind"].startswith("branch") and "n" in r}
    got = {v: n_of[f"branch {r['explained_by_branch']}"] for v, r in diag.items()}
    assert got == {0.975: 10, 0.9775: 10, 0.98: 5}
    assert any(r["kind"].endswith("period_doubling") for r in rows)
    assert any(": crest" in r["kind"] or ": stop" in r["kind"] for r in rows)


def test_cli_basins(tmp_path, capsys):
    """Hypothesis: ``peelapprox basins`` on a 3 x 3 (α0, ω0) grid of the cubic law at V = 1.2, I = 2.2e-5 (the two
    coexisting period-1 orbits of docs/orbits.md) prints both attractors with their multipliers (|μ| = 0.2855
    and 0.6603, to the 4 digits printed) and writes one CSV row per start and a picture; a bad grid is a
    usage error (exit 2) naming the option."""
    from peelapprox.cli import main

    args = ["basins", "--V", "1.2", "--I", "2.2e-5", "--force-family", "cubic", "--omega0", "10:26:3",
            "--t-transient", "20", "--window", "10", "--workers", "0", "--orbits"]
    assert main(args + ["--alpha0=-0.05:0.05:3", "--out", str(tmp_path / "b.csv"),
                        "--plot", str(tmp_path / "b.png")]) == 0
    text = capsys.readouterr().out
    assert "period-1: 8 starts" in text and "|mu| = 0.2855" in text and "|mu| = 0.6603" in text
    assert len((tmp_path / "b.csv").read_text().strip().splitlines()) == 1 + 9
    assert (tmp_path / "b.png").stat().st_size > 10_000
    with pytest.raises(SystemExit) as e:
        main(args + ["--alpha0", "0.1:0.05"])
    assert e.value.code == 2 and "--alpha0" in capsys.readouterr().err


def test_a_return_the_tangent_cannot_take_is_a_solver_failure():
    """Hypothesis: a section state far from any orbit (a wild Newton iterate of a branch switch, found at V =
    3.49 and I = 1e-5 before λ's steps were bounded) where the compiled tangent integration divides by zero
    raises SolverFailure with the (finite) start state, never ZeroDivisionError."""
    p = pa.PeelParams(V=5.223673296215096, I=1e-5)
    with pytest.raises(exact.SolverFailure, match="tangent integration failed") as e:
        exact.section_return(p, [-0.05958918, 51.00845879], tangent=False)
    assert all(np.isfinite(v) for v in e.value.state.values() if isinstance(v, float))
