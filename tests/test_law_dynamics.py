"""The dynamics measures and the sweeps with a peel-force law other than the paper's.

The cubic ``PeelForce.cubic()`` (a=150, b=300, c=300, d=80) at V = 1.2 m/s has a stable period-5 stick-slip
orbit at I = 1e-5 and a period-1 orbit at I = 3e-5 (tests/test_law_runs.py checks its physics); its coefficient
c = 290, 300, 310 gives period-1, period-5 and a breakdown (a CD→AB jump with no landing) at I = 1e-5.
"""

from __future__ import annotations

import dataclasses
import json
import math
import pickle

import numpy as np
import pytest

import exact
import peelapprox as pa
from comparisons.sweep import load_sweep, sweep
from peelapprox import PeelForce, PeelParams
from peelapprox.cli import main

CUBIC = PeelForce.cubic()
V = 1.2


def _tabulated_cubic(n: int = 400) -> PeelForce:
    """The cubic sampled at n points log-spaced over [0.05, 20] m/s (PCHIP in ln v between them)."""
    v = np.exp(np.linspace(math.log(0.05), math.log(20.0), n))
    return PeelForce.tabulated(v, CUBIC.f(v, V))


# --------------------------------------------------------------------------------------------- Lyapunov
@pytest.fixture(scope="module")
def lyapunov_pair():
    """The largest exponent of the cubic's period-1 orbit (V = 1.2, I = 3e-5) by two methods: the tangent over
    20 s (``T``, ~1 s CPU), the two-trajectory method over 10 s (2000 intervals, ~4 s CPU; judged by its own
    stated error, which the shorter run widens from ~0.4 to ~0.6 bits/s)."""
    p = PeelParams(V=V, I=3e-5, force=CUBIC)
    T = 20.0
    tan = exact.lyapunov(p, "tangent", t_transient=10.0, T=T)
    two = exact.lyapunov(p, "two-trajectory", t_transient=10.0, T=10.0)
    return p, T, tan, two


def test_lyapunov_of_a_periodic_cubic_orbit_two_methods_agree_on_zero(lyapunov_pair):
    """Hypothesis: on a stable periodic orbit the largest Lyapunov exponent is exactly 0 (the flow direction is
    neutral, every transverse direction contracts); the orbit is periodic by the return map, checked here
    independently of either exponent.  The two methods are independent (the tangent with saltation matrices
    linearises the flow and its jumps; the two-trajectory method runs two finite-distance orbits and linearises
    nothing) and each must give 0 within its own error:

    * two-trajectory: its stated standard error (``stderr_bits``; measured 0.56 bits/s for its 10 s of 5 ms
      intervals, 0.37 for 20 s), at 3σ;
    * tangent: on the orbit the tangent is carried along the flow direction, whose scaled size varies along
      the orbit (slow sticking, fast jumps), so ``|λ T|`` stays bounded instead of growing with T: we allow
      10 bits (a factor 1000; measured 5.3 bits at T = 20 s), i.e. |λ| ≤ 0.5 bits/s at T = 20 s, while any
      positive exponent above 0.5 bits/s would exceed it.

    and the two agree with each other within the sum of these errors."""
    p, T, tan, two = lyapunov_pair
    per = pa.classify(exact.window_run(p, t_transient=10.0, window=10.0))
    assert per.kind == "periodic" and per.period == 1
    assert "saltation" in tan.method and "two-trajectory" in two.method
    assert math.isfinite(two.stderr_bits) and 0 < two.stderr_bits < 20
    assert abs(two.bits_per_s) <= 3 * two.stderr_bits
    assert abs(tan.bits_per_s) * T <= 10.0
    assert abs(tan.bits_per_s - two.bits_per_s) <= 3 * two.stderr_bits + 10.0 / T
    assert tan.params.force == CUBIC and two.params.force == CUBIC


def test_return_map_method_of_a_cubic_matches_the_return_maps_jacobian_at_its_fixed_point():
    """Hypothesis: on the cubic's stable period-1 orbit the return-map method measures the leading transverse
    exponent, ``ln|μ| / T_return``, μ the largest-modulus eigenvalue of the Jacobian of the AB→CD return map at
    its fixed point.  That Jacobian is computed here independently: the fixed point is the state after an
    AB→CD jump of a 10 s run (a fixed point to 1e-12: checked), the map is one ``exact.simulate`` run to the
    next AB→CD jump, its Jacobian a central difference of steps 1e-6 of each variable's natural size
    (eigenvalues change by < 1e-7 between steps 1e-5 and 1e-7: measured), its eigenvalues by numpy (they do
    not depend on the scaling; measured a complex pair |μ| = 0.2235, -17.27 bits/s).  The method's mean over
    100 returns must lie within 3 of its stated standard errors of it (measured -16.79 ± 1.37 bits/s)."""
    p = PeelParams(V=V, I=3e-5, force=CUBIC)
    r = exact.lyapunov(p, "return-map", t_transient=10.0, n_returns=100)
    J = exact.window_run(p, t_transient=0.0, window=10.0, rtol=1e-12).jumps
    k = int(np.flatnonzero(np.asarray(J.from_branch) == 0)[-1])
    x = np.array([J.alpha[k], J.omega[k], J.F[k]])

    def ret(z):
        Jz = exact.simulate(p, 1.0, alpha0=z[0], omega0=z[1], F0=z[2], branch0="CD", rtol=1e-12, save="jumps").jumps
        i = int(np.flatnonzero(np.asarray(Jz.from_branch) == 0)[0])
        return np.array([Jz.alpha[i], Jz.omega[i], Jz.F[i]]), float(Jz.t[i])

    y, T = ret(x)
    assert np.allclose(y, x, rtol=1e-10, atol=1e-10)
    step = 1e-6 * np.array([1.0, V / p.R, 240.0])
    D = np.empty((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = step[j]
        D[:, j] = (ret(x + e)[0] - ret(x - e)[0]) / (2 * step[j])
    mu = float(np.max(np.abs(np.linalg.eigvals(D))))
    expected = math.log(mu) / T / math.log(2.0)
    assert r.bits_per_s < 0 and abs(r.bits_per_s - expected) <= 3 * r.stderr_bits


def test_variational_method_runs_a_closed_form_law_and_refuses_a_table():
    """Hypothesis: the ε-variational method's DiffSL model is printed from the law's sympy form, so a cubic runs
    and, on its period-1 orbit at I = 3e-5 (largest exponent 0: the flow direction), gives |λ| within 3 of its
    own standard errors of 0 (measured -0.28 ± 0.64 bits/s over T = 10 s); a table has no closed form and is a
    ValueError naming the method and the law, raised before any solver or peer is loaded."""
    pytest.importorskip("pydiffsol")
    p = PeelParams(V=V, I=3e-5, force=CUBIC)
    r = exact.lyapunov(p, "variational", t_transient=5.0, T=10.0)
    assert math.isfinite(r.bits_per_s) and abs(r.bits_per_s) <= 3 * r.stderr_bits
    with pytest.raises(ValueError, match=r"'variational'.*PeelForce\.tabulated"):
        exact.lyapunov_variational(p.replace(force=_tabulated_cubic(50)), T=1.0)


def test_natural_scales_and_hybrid_field_follow_the_law():
    """Hypothesis: the scales every Lyapunov method divides (δα, δω, δF) by are (1, V/R, f_max) of the run's
    law (the cubic's f_max, its folds in closed form: v = (c ∓ sqrt(c² − 3bd))/3d, to 1e-9 relative), the
    paper's for the paper's law (exactly as before); ``hybrid_field`` returns by default the field
    ``simulate`` runs: the law as an argument for the cubic, fvV inlined for the paper's law (the same objects
    as ``law_argument=True``/``False``)."""
    from exact._shared import natural_scales

    a, b, c, d = 150.0, 300.0, 300.0, 80.0
    v_max = (c - math.sqrt(c * c - 3 * b * d)) / (3 * d)
    f_max = a + b * v_max - c * v_max**2 + d * v_max**3
    p = PeelParams(V=V, I=1e-5, force=CUBIC)
    s = natural_scales(p)
    assert s[0] == 1.0 and s[1] == V / p.R and s[2] == pytest.approx(f_max, rel=1e-9)
    q = PeelParams(V=V, I=1e-5)
    assert natural_scales(q)[2] == pa.branch_structure(V).f_max
    rhs, P = exact.hybrid_field(p)
    rhs_t, P_t = exact.hybrid_field(p, law_argument=True)
    assert rhs is rhs_t and np.array_equal(P[0], P_t[0]) and np.array_equal(P[2], P_t[2])
    rhs0, p0 = exact.hybrid_field(q)
    rhs_f, p_f = exact.hybrid_field(q, law_argument=False)
    assert rhs0 is rhs_f and np.array_equal(p0, p_f)


def test_the_papers_law_as_its_family_reproduces_the_built_in_dynamics():
    """Hypothesis: ``PeelForce.paper_family()`` is fvV with its numbers as coefficients, equal to the built-in law
    to ~1e-15 relative but run by the other driver (the law as an argument, not inlined), so the dynamics
    measures must give the built-in answers to rounding amplified by the orbit: at V = 1, I = 1e-4 (chaotic,
    ~4.7 bits/s) the jumps of the first 2 s at times within 1e-9 s (measured 1.5e-11 s), the tangent exponent
    of 2 s after 2 s within 1e-2 bits/s (measured 7e-4: the adaptive steps differ at rounding level)."""
    p = PeelParams(V=1.0, I=1e-4)
    q = p.replace(force=PeelForce.paper_family())
    a, b = (exact.window_run(x, t_transient=0.0, window=2.0).jumps for x in (p, q))
    assert len(a.t) == len(b.t) > 50 and np.max(np.abs(np.asarray(a.t) - np.asarray(b.t))) < 1e-9
    ra, rb = (exact.lyapunov(x, "tangent", t_transient=2.0, T=2.0) for x in (p, q))
    assert abs(ra.bits_per_s - rb.bits_per_s) < 1e-2


# --------------------------------------------------------------------------------------------- periods
def test_window_run_and_attractors_of_a_cubic_return_its_period():
    """Hypothesis: the cubic's orbit at V = 1.2, I = 1e-5 is period-5; two independent records of one window
    say so: the forces at the AB→CD jumps (the return map, ``classify``) and the times between those jumps,
    which repeat after 5 returns to 1e-9 s (the jump times are located to ~1e-12 s at rtol 1e-10) and after no
    fewer (they differ by > 1e-3 s: the five intervals of a cycle differ by ~3 ms); five consecutive
    intervals sum to the orbit's period, the same for every cycle (1e-9 s).  ``attractors`` from two starts
    finds this one attractor, period 5, with both starts, its cycle the window's return-map values (1e-6)."""
    p = PeelParams(V=V, I=1e-5, force=CUBIC)
    tr = exact.window_run(p, t_transient=10.0, window=10.0)
    per = pa.classify(tr)
    assert per.kind == "periodic" and per.period == 5
    J = tr.jumps
    dt = np.diff(np.asarray(J.t)[np.asarray(J.from_branch) == 0])
    assert dt.size > 50
    assert np.max(np.abs(dt[5:] - dt[:-5])) < 1e-9
    for n in range(1, 5):
        assert np.max(np.abs(dt[n:] - dt[:-n])) > 1e-3
    cycle = np.array([dt[k:k + 5].sum() for k in range(dt.size - 5)])
    assert np.ptp(cycle) < 1e-9
    att = exact.attractors(p, (0.0, 0.3), t_transient=10.0, window=10.0)
    assert len(att) == 1 and att[0].period == 5 and att[0].starts == (0.0, 0.3)
    x = pa.return_map(tr)
    assert np.allclose(sorted(att[0].signature), np.sort(x[:5]), rtol=1e-6, atol=0)


def test_a_tabulated_cubic_runs_the_dynamics_with_the_cubics_period():
    """Hypothesis: the cubic sampled at 400 points (PCHIP in ln v) is the same law to the interpolation error
    (folds within 2e-3 relative, measured 1.7e-3 in v_max), so the dynamics measures run it and find the same
    period-5 orbit: the same number of AB→CD jumps in the window, at times within 1e-3 s of the cubic's
    (measured 3e-5 s); the tangent exponent stays bounded as on the cubic's orbit (|λ T| <= 10 bits)."""
    tab = _tabulated_cubic()
    p = PeelParams(V=V, I=1e-5, force=tab)
    tr = exact.window_run(p, t_transient=10.0, window=10.0)
    ref = exact.window_run(p.replace(force=CUBIC), t_transient=10.0, window=10.0)
    assert pa.classify(tr).period == 5
    t_tab = np.asarray(tr.jumps.t)[np.asarray(tr.jumps.from_branch) == 0]
    t_ref = np.asarray(ref.jumps.t)[np.asarray(ref.jumps.from_branch) == 0]
    assert t_tab.size == t_ref.size and np.max(np.abs(t_tab - t_ref)) < 1e-3
    r = exact.lyapunov(p, "tangent", t_transient=10.0, T=4.0)
    assert abs(r.bits_per_s) * 4.0 <= 10.0


# --------------------------------------------------------------------------------------------- sweeps
def test_sweep_over_a_cubic_coefficient_on_a_process_pool(tmp_path):
    """Hypothesis: a sweep over the cubic's c (3 values x 1 V x 1 I) on a pool of 2 spawned workers returns one
    record per point, each recording the law its worker ran: ``law_key`` computed in the worker from the law
    it unpickled equals the key of ``PeelForce.cubic(c=value)`` here (a SHA-256 of the exact coefficients: the
    pickled law's round trip is exact), and its ``period`` equals a direct ``window_run`` here (exact: the runs
    are deterministic).  The manifest rebuilds the law (``PeelForce.from_dict``, equal), ``load_sweep`` gives
    the same 3-D grid, and resuming with other c values is a ValueError naming coef."""
    out = tmp_path / "sw"
    cs = [290.0, 300.0, 310.0]
    opts = dict(t_transient=2.0, t_end=4.0)
    res = sweep([1e-5], [V], ("period",), out=out, force=CUBIC, coef=("c", cs), max_workers=2, options=opts,
                progress=False)
    assert res.shape == (1, 1, 3) and res.complete and len(res.records) == 3
    for rec, c in zip(res.records, cs):
        law = PeelForce.cubic(c=c)
        assert rec["coef"] == c and rec["law"] == repr(law) and rec["law_key"] == law.key
        p = PeelParams(V=V, I=1e-5, force=law)
        try:
            direct = pa.classify(exact.window_run(p, t_transient=2.0, window=2.0)).period
        except pa.ModelBreakdown as exc:
            assert rec["status"] == f"breakdown:{exc.reason}"
            continue
        assert rec["status"] == "ok" and rec["period"] == direct
    assert list(res.values("period")[0, 0, :2]) == [1.0, 5.0] and math.isnan(res.values("period")[0, 0, 2])
    m = json.loads((out / "sweep.json").read_text())
    assert PeelForce.from_dict(m["force"]) == CUBIC and m["law_key"] == CUBIC.key
    assert m["coef"] == {"name": "c", "values": cs}
    again = load_sweep(out)
    assert again.force == CUBIC and again.coef_name == "c" and again.records == res.records
    with pytest.raises(ValueError, match=r"coef: existing c=\[290.0, 300.0, 310.0\], requested c=\[290.0\]"):
        sweep([1e-5], [V], ("period",), out=out, force=CUBIC, coef=("c", [290.0]), max_workers=0, options=opts)


def test_sweep_of_a_tabulated_law_over_I_and_V_records_the_law(tmp_path):
    """Hypothesis: an (I, V) sweep of a tabulated law records it (manifest: ``force``, rebuilt equal by
    ``PeelForce.from_dict`` from its JSON; records: ``law``, ``law_key``), its values equal direct calls with the
    law (exact), the law pickles as plain data (equal after a round trip, same key), and a resumed sweep with
    another law is refused naming force."""
    tab = _tabulated_cubic(60)
    assert pickle.loads(pickle.dumps(tab)) == tab and pickle.loads(pickle.dumps(tab)).key == tab.key
    out = tmp_path / "tab"
    opts = dict(t_transient=1.0, t_end=2.0)
    res = sweep([1e-5, 3e-5], [V], ("jumps",), out=out, force=tab, max_workers=0, options=opts, progress=False)
    assert res.shape == (2, 1) and len(res.records) == 2
    for rec in res.records:
        assert rec["law"] == repr(tab) and rec["law_key"] == tab.key
        tr = exact.window_run(PeelParams(V=V, I=rec["I"], force=tab), t_transient=1.0, window=1.0)
        assert rec["jumps_count"] == len(tr.jumps.t)
    m = json.loads((out / "sweep.json").read_text())
    assert PeelForce.from_dict(m["force"]) == tab and m["force"] == json.loads(json.dumps(dataclasses.asdict(tab)))
    with pytest.raises(ValueError, match="force: existing PeelForce.tabulated"):
        sweep([1e-5, 3e-5], [V], ("jumps",), out=out, force=CUBIC, max_workers=0, options=opts)


def test_sweep_refuses_a_bad_law_or_coefficient_axis(tmp_path):
    """Hypothesis: a wrong force or coef is refused before anything is written (ValueError/TypeError naming the
    argument): not a PeelForce, a coefficient axis on a non-family law, an unknown coefficient (the valid ones
    listed), repeated values, a value the family refuses."""
    cases = [
        (dict(force="cubic"), TypeError, "force must be a peelapprox.PeelForce"),
        (dict(force=_tabulated_cubic(30), coef=("c", [1.0])), ValueError, "coef: a coefficient axis .*family"),
        (dict(force=CUBIC, coef=("q", [1.0])), ValueError, "'q' is not a coefficient .*a, b, c, d"),
        (dict(force=CUBIC, coef=("c", [1.0, 1.0])), ValueError, "must not repeat"),
        (dict(force=PeelForce.power_branches(), coef=("m", [1.0, -1.0])), ValueError, "m=-1.0 is not a valid"),
    ]
    for i, (kw, exc, msg) in enumerate(cases):
        out = tmp_path / f"bad{i}"
        with pytest.raises(exc, match=msg):
            sweep([1e-5], [V], ("period",), out=out, max_workers=0, **kw)
        assert not out.exists()


def test_paper_sweep_writes_what_it_wrote_before(tmp_path):
    """Hypothesis: the paper's law given explicitly is the default: the same records, exactly, without law fields
    (the default path's files are those of before the law: the bitwise oracle compares them too), and no law
    entries in the manifest."""
    opts = dict(t_transient=1.0, t_end=1.5)
    a = sweep([1e-4], [1.0], ("period",), out=tmp_path / "a", max_workers=0, options=opts, progress=False)
    b = sweep([1e-4], [1.0], ("period",), out=tmp_path / "b", max_workers=0, options=opts, progress=False,
              force=PeelForce.paper())
    assert a.records == b.records and not {"law", "law_key", "coef"} & set(a.records[0])
    m = json.loads((tmp_path / "b" / "sweep.json").read_text())
    assert not {"force", "law", "law_key", "coef"} & set(m)


# --------------------------------------------------------------------------------------------- CLI
def test_cli_dynamics_lyapunov_and_sweep_coefficient_axis_with_a_cubic(tmp_path, capsys):
    """Hypothesis: ``peelapprox dynamics --force-family cubic --lyapunov`` runs (exit 0) and its JSON row records
    the law and its exponent equals ``exact.lyapunov`` called with the same arguments (exact: deterministic);
    ``peelapprox sweep --force-family cubic --coef-axis c=290,300`` writes one record per c value with its law."""
    rc = main(["dynamics", "--V", "1.2", "--I", "3e-5", "--force-family", "cubic", "--lyapunov", "--lyapunov-time",
               "2", "--t-transient", "2", "--window", "2", "--format", "json"])
    assert rc == 0
    row = json.loads(capsys.readouterr().out)
    assert row["law"] == repr(CUBIC) and row["law_key"] == CUBIC.key and row["period"] == "period-1"
    ly = exact.lyapunov(PeelParams(V=1.2, I=3e-5, force=CUBIC), t_transient=2.0, T=2.0, alpha0=0.0, max_wall=600.0)
    assert row["lyapunov_bits_per_s"] == ly.bits_per_s
    out = tmp_path / "sw"
    rc = main(["sweep", "--I", "1e-5", "--V", "1.2", "--measure", "period", "--force-family", "cubic", "--coef-axis",
               "c=290,300", "--t-transient", "2", "--t-end", "4", "--workers", "0", "--out", str(out), "--quiet",
               "--format", "json"])
    assert rc == 0
    rows = json.loads(capsys.readouterr().out)
    assert [(r["coef"], r["law"], r["period"]) for r in rows] == [
        (290.0, repr(PeelForce.cubic(c=290)), 1), (300.0, repr(CUBIC), 5)]
    for args, msg in ((["--coef-axis", "c"], "value must be NAME=SPEC"),
                      (["--coef-axis", "c=1,2"], "--coef-axis sweeps a coefficient of --force-family")):
        with pytest.raises(SystemExit) as e:
            main(["sweep", "--I", "1e-5", "--V", "1.2", "--out", str(tmp_path / "x"), *args])
        assert e.value.code == 2 and msg in capsys.readouterr().err
