"""Periodic orbits as objects: the section map's Jacobian, Newton's orbits, Floquet multipliers.

Oracles: central differences of the field (for its analytic Jacobian), fourth-order differences of the
return map (for the tangent's monodromy), the long-run simulation's return map (for the orbit's values),
and the orbit's own trajectory closing after one period.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

import exact
import exact._hybrid_driver as HL
from exact._jacobian import field_jacobian
from peelapprox import PeelForce, PeelParams, return_map
from peelapprox.kernels import LAW_FPP, compiled_law

CUBIC = PeelParams(V=1.2, I=3e-5, force=PeelForce.cubic())  # a stable period-1 orbit
PAPER = PeelParams(V=1.0, I=1e-5)  # period 3 from alpha0 = 0 after ~2 s (docs/dynamics.md)


@njit
def _jac(y, p, v, f, fp, fpp, J):
    field_jacobian(y, p, v, f, fp, fpp, J)


@pytest.mark.parametrize("params", [PAPER, PAPER.replace(geometry="exact", l=0.3), CUBIC],
                         ids=["fvV", "fvV-exact-geometry", "cubic"])
def test_field_jacobian_is_the_derivative_of_the_field(params):
    """Hypothesis: the analytic Jacobian of the hybrid field (chain rule through CONSTR, f'' of the law, the
    closure's second derivative) equals central differences of the field (step 1e-6 of each coordinate's
    size) at states on both branches, to 1e-6 relative to the largest entry (the difference quotient's own
    error is ~1e-8; a wrong term is off by O(1))."""
    cl = compiled_law(params.force, params.V)
    p = HL.param_vector(params, None, cl.structure, cl.domain)
    rng = np.random.default_rng(3)
    for v in (0.02, 0.3, 3.0, 12.0):
        y = np.array([0.0, rng.uniform(-0.2, 0.2), rng.uniform(0, 30), math.log(v)])
        f, fp, fpp = cl.fn(v, cl.coef, LAW_FPP)
        J = np.empty((4, 4))
        _jac(y, p, v, f, fp, fpp, J)
        fd = np.empty((4, 4))
        for j in range(4):
            h = 1e-6 * max(1.0, abs(y[j]))
            gp, gm = np.empty(4), np.empty(4)
            yp, ym = y.copy(), y.copy()
            yp[j] += h
            ym[j] -= h
            HL.field_law()(yp, p, cl.fn, cl.coef, gp)
            HL.field_law()(ym, p, cl.fn, cl.coef, gm)
            fd[:, j] = (gp - gm) / (2 * h)
        assert np.abs(J - fd).max() <= 1e-6 * np.abs(fd).max(), (v, J, fd)


@pytest.mark.parametrize("params, kw, n", [(CUBIC, {}, 1), (PAPER, dict(t_transient=40.0), 3)], ids=["cubic", "fvV"])
def test_stable_orbit_closes_matches_the_long_run_and_fd_multipliers(params, kw, n):
    """Hypothesis: from the default start, Newton finds the attractor the long run settles on: period ``n``,
    closing residual <= 1e-10 (the corrector's bound), stable; its return-map values equal those of a 20 s
    simulation after the transient at rtol 1e-12 to 1e-8 relative (measured 4e-14); its multipliers equal the
    eigenvalues of a fourth-order finite-difference monodromy to 1e-6 (measured 1e-8 and 7e-8); and one
    period of its trajectory ends where it began, (α, ω) to 1e-9 relative (v is not compared: at the fold it
    moves like the square root of the time to it, so rounding of the period shows there), after n CD→AB jumps."""
    o = exact.periodic_orbit(params, **kw)
    assert o.n == n and o.residual <= 1e-10 and o.stable and np.all(np.abs(o.multipliers) < 1)
    t0 = kw.get("t_transient", 30.0)
    tr = exact.simulate(params, t0 + 20.0, rtol=1e-12, save="jumps", t_transient=t0)
    x = return_map(tr)
    np.testing.assert_allclose(np.sort(x[-n:]), np.sort(o.return_map_values), rtol=1e-8)
    fd = exact.monodromy_fd(params, o.section_states[0], n)
    mu_fd = np.linalg.eigvals(fd)
    assert np.abs(np.sort(np.abs(mu_fd)) - np.sort(np.abs(o.multipliers))).max() <= 1e-6
    one = o.trajectory()
    end = np.array([one.final_state.alpha, one.final_state.omega])
    np.testing.assert_allclose(end, o.section_states[0], rtol=1e-9, atol=1e-12)
    assert int(np.sum(one.jumps.from_branch == 1)) == n  # n CD→AB jumps in one period


def test_unstable_orbit_in_the_chaotic_region():
    """Hypothesis: at V = 2, I = 1e-4 (chaotic, λ ≈ 4.7 bits/s, docs/dynamics.md) Newton started from the
    nearest 2-recurrence of the run finds a period-2 orbit that closes to 1e-10 and is unstable (a multiplier
    outside the unit circle: measured a complex pair of modulus 1.063), as every orbit embedded in a chaotic
    attractor must be."""
    o = exact.periodic_orbit(PeelParams(V=2.0, I=1e-4), n=2, t_transient=30.0)
    assert o.residual <= 1e-10 and not o.stable and np.abs(o.multipliers).max() > 1.0


def test_bad_arguments_and_no_section():
    """Hypothesis: bad arguments are ValueErrors naming them; a law without folds has no section."""
    with pytest.raises(ValueError, match="tol"):
        exact.periodic_orbit(CUBIC, tol=0.5)
    with pytest.raises(ValueError, match="n"):
        exact.periodic_orbit(CUBIC, n=0)
    with pytest.raises(TypeError, match="start"):
        exact.periodic_orbit(CUBIC, start="here")
    with pytest.raises(ValueError, match="no folds"):
        exact.periodic_orbit(CUBIC.replace(force=PeelForce.cubic(c=10.0)))


# --------------------------------------------------------------------------- continuation
@pytest.fixture(scope="module")
def cubic_branch():
    """The cubic's period-1 orbit continued in I from 3e-5 down to 1.9e-5 (it ends in a grazing)."""
    return exact.continue_orbit(exact.periodic_orbit(CUBIC), "I", stop=1.9e-5)


def test_continued_points_are_the_attractors_where_stable(cubic_branch):
    """Hypothesis: every point of a continued branch is a closed orbit (residual <= 1e-10) and the branch is
    smooth (its period changes by < 3e-3 s between neighbours: no jump to a coexisting orbit, which the
    corrector-distance control refuses); where the branch is stable it is the attractor of a long run: at two
    of its points the return-map value equals a 60 s simulation's after a 40 s transient to 1e-8 relative."""
    pts = cubic_branch.points
    assert len(pts) >= 10 and all(p.orbit.residual <= 1e-10 for p in pts)
    assert np.abs(np.diff([p.orbit.period for p in pts])).max() < 3e-3
    stable = [p for p in pts if p.orbit.stable]
    for p in (stable[1], stable[len(stable) // 2]):
        tr = exact.simulate(p.orbit.params, 60.0, rtol=1e-12, save="jumps", t_transient=40.0)
        np.testing.assert_allclose(return_map(tr)[-1], p.orbit.return_map_values[0], rtol=1e-8)


def test_neimark_sacker_then_grazing_on_the_cubic_branch(cubic_branch):
    """Hypothesis: along the branch the complex pair of multipliers grows through the unit circle: one
    Neimark-Sacker bifurcation, located by bisection where |μ| = 1 to 1e-6 (measured 6e-8), at I = 2.112e-5,
    between the last stable and the first unstable point of the branch; further down the orbit meets the AB
    fold tangentially (its fold rate Ġ falls below 1e-3 k V, the multipliers diverge): the branch stops with
    "grazing" near I = 1.997e-5."""
    b = cubic_branch
    assert [x.kind for x in b.bifurcations] == ["neimark_sacker"]
    ns = b.bifurcations[0]
    assert abs(abs(ns.orbit.multipliers[0]) - 1.0) <= 1e-6 and ns.value == pytest.approx(2.112e-5, rel=1e-3)
    stable = [p.value for p in b.points if p.orbit.stable]
    unstable = [p.value for p in b.points if not p.orbit.stable]
    assert min(stable) > ns.value > max(unstable)  # stable above the bifurcation, unstable below
    assert b.stopped == "grazing" and b.points[-1].value == pytest.approx(1.997e-5, rel=1e-3)
    assert np.abs(b.points[-1].orbit.fold_rates).min() < 1e-3 * 1e3 * 1.2
    rows = b.rows()
    assert len(rows) == len(b.points) and {"I", "period", "stable", "mu1_abs", "F1"} <= set(rows[0])


def test_continuation_arguments():
    """Hypothesis: an unknown parameter (the message lists the valid ones, a family law's coefficients
    included), a stop equal to the start, a non-orbit are refused naming the argument; a family coefficient
    is a parameter."""
    o = exact.periodic_orbit(CUBIC)
    with pytest.raises(ValueError, match=r"parameter must be one of V, I, k or .*force\.c"):
        exact.continue_orbit(o, "R", stop=0.2)
    with pytest.raises(ValueError, match="stop"):
        exact.continue_orbit(o, "I", stop=3e-5)
    with pytest.raises(TypeError, match="orbit"):
        exact.continue_orbit("orbit", "I", stop=1e-5)  # type: ignore[arg-type]
    b = exact.continue_orbit(o, "force.c", stop=301.0, max_points=3)
    assert b.points[-1].orbit.params.force.coefficients[2] == ("c", b.points[-1].value)


# --------------------------------------------------------------------------- command line and picture
def test_cli_orbit_and_bifurcation(tmp_path, capsys):
    """Hypothesis: ``peelapprox orbit`` prints the orbit ``periodic_orbit`` finds (period, multipliers' moduli,
    stability, F at the jump: the same numbers, to the 6 digits printed) and draws one period; ``peelapprox
    bifurcation`` writes the diagram and the branches (rows of both kinds, every branch row a closed orbit) and
    a picture; a bad range is a one-line usage error (exit 2)."""
    from peelapprox.cli import main

    assert main(["orbit", "--V", "1.2", "--I", "3e-5", "--force-family", "cubic", "--format", "json",
                 "--plot", str(tmp_path / "o.png")]) == 0
    import json

    row = json.loads(capsys.readouterr().out)
    o = exact.periodic_orbit(CUBIC)
    assert row["n"] == 1 and row["stable"] is True
    assert row["multiplier_1_abs"] == pytest.approx(abs(o.multipliers[0]), rel=1e-9)
    assert row["F_at_jumps"][0] == pytest.approx(o.return_map_values[0], rel=1e-12)
    assert (tmp_path / "o.png").stat().st_size > 10_000
    out = tmp_path / "b.json"
    assert main(["bifurcation", "--V", "1.2", "--I", "3e-5", "--force-family", "cubic", "--param", "I",
                 "--range", "2.6e-5:3e-5:4", "--seeds", "2.8e-5", "--t-transient", "20", "--window", "5",
                 "--out", str(out),
                 "--plot", str(tmp_path / "b.png")]) == 0
    rows = json.loads(out.read_text())
    kinds = {r["kind"] for r in rows}
    assert "diagram" in kinds and {"branch 1", "branch 2"} <= kinds
    assert all(r["residual"] <= 1e-10 for r in rows if r["kind"] in ("branch 1", "branch 2"))
    assert (tmp_path / "b.png").stat().st_size > 10_000
    with pytest.raises(SystemExit) as e:
        main(["bifurcation", "--V", "1.2", "--I", "3e-5", "--range", "3:1"])
    assert e.value.code == 2 and "--range" in capsys.readouterr().err


def test_orbit_diagram_values_and_labels():
    """Hypothesis: the brute-force diagram's returns at each value are the long run's return map after the
    transient: at I = 2.8e-5 (stable period-1 orbit of the cubic) every return equals the orbit's F at the
    jump to 1e-8 relative and the label is "period-1"; a law without folds at a value gives "no stick-slip";
    progress is called once per value."""
    calls = []
    d = exact.orbit_diagram(CUBIC, "I", [2.8e-5], t_transient=30.0, window=5.0, rtol=1e-12,
                            progress=lambda done, total: calls.append((done, total)))
    o = exact.periodic_orbit(CUBIC.replace(I=2.8e-5))
    assert d.labels == ("period-1",) and calls == [(1, 1)]
    np.testing.assert_allclose(d.returns[0], o.return_map_values[0], rtol=1e-8)
    flat = exact.orbit_diagram(CUBIC.replace(force=PeelForce.cubic(c=10.0)), "I", [3e-5], t_transient=1.0,
                               window=1.0)
    assert flat.labels == ("no stick-slip",) and flat.rows()[0]["F"] is None


@pytest.mark.slow
def test_branches_explain_the_brute_force_periods_at_I_1e_2(tmp_path):
    """Hypothesis (orbits explain the diagram, in a window): at I = 1e-2 every periodic value of the brute-force
    orbit diagram over V in [0.9, 1.2] (from α0 = 0 after 30 s) lies in the stable range of a continued branch
    of the same period (seeded automatically where the diagram's period changes): the periods 7, 8, 9, 10 of
    the period-adding windows, whose ends are Neimark–Sacker bifurcations and crest events (measured on
    [0.5, 2.5]: 41 of 41 values, docs/orbits.md)."""
    import json

    from peelapprox.cli import main

    out = tmp_path / "b.json"
    assert main(["bifurcation", "--V", "1", "--I", "1e-2", "--param", "V", "--range", "0.9:1.2:7", "--out",
                 str(out)]) == 0
    rows = json.loads(out.read_text())
    diag = {r["V"]: r["label"] for r in rows if r["kind"] == "diagram"}
    ranges = []
    for kind in {r["kind"] for r in rows if r["kind"].startswith("branch") and r.get("n") is not None}:
        st = [r["V"] for r in rows if r["kind"] == kind and r.get("stable")]
        if st:
            ranges.append((next(r["n"] for r in rows if r["kind"] == kind), min(st), max(st)))
    periodic = {V: int(lab.split("-")[1]) for V, lab in diag.items() if lab.startswith("period-")}
    assert len(periodic) >= 5
    for V, n in periodic.items():
        assert any(m == n and lo - 1e-9 <= V <= hi + 1e-9 for m, lo, hi in ranges), (V, n, ranges)


def test_bifurcation_kinds_table():
    """Hypothesis: the one table of kinds detects each bifurcation by its test function on synthetic multipliers
    (a real one through +1: fold, through -1: period doubling, a complex pair through the unit circle:
    Neimark-Sacker, a real pair turning complex: none) and drives the bisection gauge to the signed distance of
    the nearest multiplier; every kind has its own plot marker, and a record reads its marker from the table."""
    from exact.orbits._kinds import BIFURCATIONS, ENDS, crossing, gauge

    def mu(*x):
        return np.array(x, dtype=complex)

    assert crossing(mu(0.5, 0.9), mu(0.5, 1.1)) == "fold"
    assert crossing(mu(-0.9, 0.2), mu(-1.1, 0.2)) == "period_doubling"
    assert crossing(mu(0.9j, -0.9j), mu(1.1j, -1.1j)) == "neimark_sacker"
    assert crossing(mu(0.5, 0.6), mu(0.5 + 0.1j, 0.5 - 0.1j)) is None
    assert crossing(mu(0.5, 0.6), mu(0.4, 0.7)) is None
    assert gauge("fold", mu(0.2, 0.999)) == pytest.approx(-0.001)
    assert gauge("neimark_sacker", mu(1.01j, -1.01j)) == pytest.approx(0.01)
    kinds = BIFURCATIONS + ENDS
    assert len({k.name for k in kinds}) == len({k.marker for k in kinds}) == len(kinds)
    b = exact.Bifurcation("period_doubling", 1.0, None, "V")  # type: ignore[arg-type]
    assert b.marker == ("D", "C1") and b.doubles and not exact.Bifurcation("fold", 1.0, None).doubles  # type: ignore[arg-type]
