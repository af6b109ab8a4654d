"""The comparison harness: the paper's scenes, the two seeding modes, statistics, transient checks, CLI.

Every test states the paper's claim it checks and why its tolerance.  Where a reduction fails the
paper's claim in our computation, the failure is pinned with the measured range, not skipped.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from comparisons import (
    CLAIM,
    SCENES,
    TransientNotPassed,
    check_past_transient,
    exact_run,
    scene_rows,
    statistics,
)
from exact import simulate
from peelapprox import PeelParams
from peelapprox.cli import main


def _pick(rows, quantity, seed, method):
    hit = [r for r in rows if r.quantity.startswith(quantity) and r.seed == seed and r.method == method]
    assert len(hit) == 1, (quantity, seed, method, [r.quantity for r in rows])
    return hit[0]


@pytest.mark.parametrize("scene", ["case-I-periods", "case-I-times", "case-II-point-a", "case-III-bounds",
                                   "periods-I1e-2-V1", "periods-I1e-2-V4"])
def test_paper_claims_hold_when_seeded_from_the_exact_solution(scene):
    """Hypothesis (paper Sec. V): each reduction the paper uses matches the exact Δt, ΔF, exit force, period
    or force bound "within 10 %".  Seeded from our exact segment, every row carrying that claim in these
    scenes is within it (measured: ≤ 4.3 %).  The tolerance is the paper's own claim, CLAIM = 0.10."""
    rows = [r for r in scene_rows(scene) if r.seed == "exact" and r.claim is not None]
    assert rows
    for r in rows:
        assert r.status == "ok", r
        assert abs(r.rel_error) <= CLAIM, (r.quantity, r.method, r.rel_error)


def test_case_i_ab_time_and_exit_force():
    """Case I b (I=1e-5, V=1): approxalpha + approxvdot from the AB stay entering near F = 211.5 N gives the
    exact Δt (≈ 0.062 s; the paper's 0.063) and jumps before f_max.  Tolerances: 1 % on Δt (measured
    0.4 %: the neglected v̇/R term is O(1e-3) and the F ramp error O(α)), and the exit force below
    0.95 f_max (measured 0.942: the orbit jumps when F(1 + sin α) = f_max with α ≈ 0.06)."""
    rows = scene_rows("case-I-times")
    dt = _pick(rows, "AB Δt", "exact", "approxalpha + approxvdot")
    assert abs(dt.rel_error) <= 0.01 and 0.055 <= dt.ours_exact <= 0.07
    assert _pick(rows, "AB exit F / f_max", "exact", "exact solution").ours_exact < 0.95


def test_case_ii_cascade_top_cd_misses_ten_percent_with_approxvdot():
    """Pinned failure (Case II, top of the cascade): Airy2 + approxvdot underestimates the exact CD time by
    12.7 % seeded from our exact entry (18.5 % from the paper's seed), outside the paper's 10 %; the paper's
    own numbers (1.78e-3 vs 1.89e-3) are 6 % apart.  Keeping the 1 + α factor and Ḟ (fullvdot) brings it to
    -4.8 %.  The exponential α the paper recommends "for analytical estimates" discards α̇_in = -147 rad/s
    and overestimates Δt by +276 %.  Bands of ±3 points around the measured values."""
    rows = scene_rows("case-II-cascade")
    assert -0.16 <= _pick(rows, "CD Δt, top", "exact", "airy2 + approxvdot").rel_error <= -0.10
    assert abs(_pick(rows, "CD Δt, top", "exact", "airy2 + fullvdot").rel_error) <= CLAIM
    assert abs(_pick(rows, "CD ΔF, top", "exact", "airy2 + approxvdot").rel_error) <= CLAIM
    assert 2.4 <= _pick(rows, "CD Δt, top", "exact", "exponential + approxvdot").rel_error <= 3.1
    assert _pick(rows, "CD Δt, top", "exact", "exponential + approxvdot").verdict == "outside"


def test_point_a_needs_the_true_landing_velocity():
    """Case II point a: from the paper's printed seed (v_in = 0.0188) the AB time is 0.0205 s, 82 % short of
    the exact 0.115 s; with the landing velocity 0.00188 it is 0.1172 s (the paper's 0.117), 1.9 % from
    ours.  Tolerances: the corrected seed within the paper's 10 %, the printed one outside 50 %."""
    rows = scene_rows("case-II-point-a")
    printed = _pick(rows, "AB Δt a→b", "paper", "approxalpha + approxvdot")
    fixed = _pick(rows, "AB Δt a→b", "paper, corrected", "approxalpha + approxvdot")
    assert printed.rel_error < -0.5
    assert abs(fixed.rel_error) <= CLAIM and abs(fixed.ours_approx - 0.117) <= 0.001


def test_point_e_printed_seed_breaks_down_and_corrected_agrees():
    """Case II point e: the printed α_in = +0.239 drives v to 0 (a ModelBreakdown reported as a row status,
    not a crash); α_in = -0.239 gives Δt = 0.0159 s, the paper's 0.016 (tolerance 0.0005 s, the paper's
    rounding).  Seeded from our exact entry the AB time is within 10 % (measured -9.5 %)."""
    rows = scene_rows("case-II-point-e")
    assert _pick(rows, "AB Δt at e", "paper", "approxalpha + approxvdot").status == "breakdown: v_floor"
    assert abs(_pick(rows, "AB Δt at e", "paper, corrected", "approxalpha + approxvdot").ours_approx - 0.016) <= 5e-4
    assert abs(_pick(rows, "AB Δt at e", "exact", "approxalpha + approxvdot").rel_error) <= CLAIM


def test_slope_criterion_separates_a_from_k():
    """Case II: the entry slope α̇_in at point a matches the natural slope 2πν α₀ of the a→b sinusoid
    (ratio 0.94, within the criterion's 25 % tolerance), while at point k it is 2.4 times larger, so k
    cannot start the monotonic rise.  Both verdicts are the paper's."""
    rows = scene_rows("case-II-slope")
    a = _pick(rows, "natural slope 2πνα₀ vs α̇_in at a", "exact", rows[1].method)
    k = [r for r in rows if r.quantity.endswith("at k [rad/s]") and r.seed == "exact"][0]
    assert "compatible" in a.note and abs(a.ours_exact / a.ours_approx - 1) <= 0.25
    assert "incompatible" in k.note and k.ours_exact / k.ours_approx > 2.0


def test_case_iii_coupled_approxvdot_fails_fullvdot_holds():
    """Pinned failure (Case III, V=4, I=1e-2): the paper's coupled genalpha + approxvdot is off by a median
    33-38 % in Δt on the rapid jumps, because approxvdot drops 1 + α with |α| up to 0.7.  genalpha +
    fullvdot keeps it and is within the paper's 10 % in median (measured 6-7 %; its 90th percentile is 13 %
    from sin α ≈ α).  Bands: 0.25-0.5 for the failure, CLAIM for the median of the fix."""
    rows = scene_rows("case-III-coupled")
    for branch in ("AB", "CD"):
        bad = _pick(rows, f"{branch} rapid jumps: median |rel. error| of Δt", "exact", "genalpha + approxvdot")
        good = _pick(rows, f"{branch} rapid jumps: median |rel. error| of Δt", "exact", "genalpha + fullvdot")
        assert 0.25 <= bad.rel_error <= 0.5 and bad.verdict == "outside"
        assert good.rel_error <= CLAIM


def test_v4_alpha_cycle_is_two_inertial_periods():
    """Case III periods: the monotonic α decrease ab lasts one approxalpha period (0.117 vs 0.115 s, within
    10 %), so the full α cycle is twice the inertial period (ratio 2.07 measured; band 1.9-2.2)."""
    rows = scene_rows("periods-I1e-2-V4")
    full = _pick(rows, "V=4: full α cycle", "exact", "approxalpha at F ≈ 300")
    assert 1.9 <= full.ours_exact / full.ours_approx <= 2.2


def test_local_period_from_extrema_matches_dense_output():
    """Where a stay holds less than one α cycle (the a→b stay at I=1e-2) the period is twice the spacing of
    the α extrema, located on the Hermite cubic of the stored steps.  Reference: the extrema of a
    200001-point dense sampling of the same exact solution (resolution 6e-7 s).  Tolerance 5e-5 relative:
    the stationary point of the Hermite cubic is the root of its derivative, which is only 3rd order in
    the step (measured 2.2e-5, i.e. 3e-6 s on 0.128 s; the period is quoted to 3 digits)."""
    run = exact_run("V1-I1e-2")
    a = max((s for s in run.segments if s.branch == "AB"), key=lambda s: s.dt)
    te = np.linspace(a.t_in, a.t_out, 200001)
    tr = simulate(run.spec.params, run.spec.t_transient + run.spec.window, rtol=run.spec.rtol,
                  t_transient=run.spec.t_transient, t_eval=te)
    ref = 2 * (te[np.argmin(tr.alpha)] - te[np.argmax(tr.alpha)])
    assert len(a.periods) == 0 and len(a.extrema) == 2
    assert abs(a.local_period() / ref - 1) <= 5e-5


def test_transient_check_accepts_the_runs_and_rejects_a_transient():
    """Every registered scene run is past its transient (V=1, I=1e-2 repeats with period 8 to 1e-6), and the
    same parameters stored from t = 0 are rejected: the AB→CD force envelope still moves by ~9 % of its
    range between the two halves of a 3 s window (tolerance 2 %)."""
    assert exact_run("V1-I1e-2").transient.period == 8
    for sc in SCENES.values():
        assert exact_run(sc.run).transient.kind in ("periodic", "stationary")
    with pytest.raises(TransientNotPassed) as exc:
        check_past_transient(simulate(PeelParams(V=1.0, I=1e-2), 3.0, rtol=1e-9, save="jumps"))
    assert exc.value.detail["envelope_mismatch"] > 0.02


def test_statistics_low_inertia():
    """Statistics over every segment of the V=1, I=1e-5 window: genalpha + fullvdot is the full model
    linearised in α, so its median error is below the linearisation bound α²/2 ≈ 3e-3; approxalpha +
    approxvdot on AB is within the paper's 10 % at the 90th percentile (measured 5.1 %)."""
    st = statistics(["V1-I1e-5"])

    def one(branch, method, q):
        return next(s for s in st if (s.branch, s.method, s.quantity) == (branch, method, q))

    for b in ("AB", "CD"):
        assert one(b, "genalpha + fullvdot", "dt").median <= 3e-3
    ab = one("AB", "approxalpha + approxvdot", "dt")
    assert ab.n_failed == 0 and ab.n >= 20 and ab.p90 <= CLAIM


def test_cli_compare_json_rows(capsys):
    """`peelapprox compare --format json` prints rows carrying the documented keys, with numbers or null
    (never NaN: json.loads would accept NaN, so it is checked explicitly)."""
    assert main(["compare", "--scene", "case-II-point-a", "--scene", "case-III-bounds", "--format", "json",
                 "--no-stats"]) == 0
    doc = json.loads(capsys.readouterr().out)
    keys = {"scene", "quantity", "paper_approx", "paper_exact", "ours_approx", "ours_exact", "rel_error"}
    assert doc["rows"] and all(keys <= set(r) for r in doc["rows"])
    for r in doc["rows"]:
        for k in keys - {"scene", "quantity"}:
            assert r[k] is None or (isinstance(r[k], float) and math.isfinite(r[k]))
    assert {"scene case-II-point-a", "scene case-III-bounds", "total"} <= set(doc["timings"])


def test_cli_compare_rejects_unknown_scene(capsys):
    """A bad scene name exits 2 with the list of valid names."""
    with pytest.raises(SystemExit) as exc:
        main(["compare", "--scene", "case-IV"])
    assert exc.value.code == 2
    assert "case-I-periods" in capsys.readouterr().err
