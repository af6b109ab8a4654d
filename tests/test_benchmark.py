"""The work-precision benchmark's pieces: its error metric, its reference's cross-check, the ε study's
power law, and (slow tier) the whole ``peelapprox benchmark --quick`` run.

Speed is measured by the benchmark itself, never asserted here (shared, noisy machines)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from comparisons.benchmark import (
    BENCH_SCENES,
    BenchScene,
    WPRow,
    branchwise_reference,
    eps_study,
    fit_power_law,
    jump_errors,
    matched_ratios,
)
from exact import simulate


def test_jump_error_metric_on_known_shifts():
    """Analytic pair: shifting every jump time by δ and every F by a factor (1 + r) gives exactly
    (δ / T̄, r) with T̄ the mean interval (here 0.5 s); a different jump count is ``inf`` (another orbit).
    Tolerance 1e-12: only rounding of the subtraction."""
    t = np.array([0.0, 0.5, 1.0, 1.5])
    F = np.array([100.0, 200.0, 150.0, 250.0])
    et, eF = jump_errors(t + 1e-3, F * (1 + 2e-4), t, F)
    assert et == pytest.approx(2e-3, rel=1e-12)
    assert eF == pytest.approx(2e-4, rel=1e-9)
    assert jump_errors(t[:3], F[:3], t, F) == (math.inf, math.inf)
    with pytest.raises(ValueError, match="at least 2 jumps"):
        jump_errors(t[:1], F[:1], t[:1], F[:1])


def test_power_law_fit_recovers_exponent():
    """Analytic pair: data exactly C ε^p (C = 0.06, p = 2/3, the fold-passage law) is fitted back to 1e-10;
    fewer than 3 usable points is a ValueError naming the count."""
    eps = np.logspace(-12, -5, 8)
    C, p, res = fit_power_law(eps, 0.06 * eps ** (2 / 3))
    assert p == pytest.approx(2 / 3, rel=1e-10) and C == pytest.approx(0.06, rel=1e-9) and res < 1e-10
    with pytest.raises(ValueError, match="at least 3"):
        fit_power_law(eps[:2], eps[:2])


def test_branchwise_reference_agrees_with_the_hybrid_solver():
    """The benchmark's reference (hybrid, rtol 1e-13) and its independent cross-check (scipy DOP853 on
    (α, ω, F) with the branch inverse, folds as events) give the same first jumps of V=1, I=1e-5.  Tolerance
    1e-9 T̄ and 1e-10 in F: the cross-check loses digits at the folds' square-root singularity (measured 3.6e-12
    and 1.9e-12 over the benchmark's 0.3 s horizon)."""
    sc = BENCH_SCENES[0]
    ref = simulate(sc.params, 0.015, rtol=1e-13, save="jumps").jumps
    assert len(ref) == 2
    t, F = branchwise_reference(sc.params, 0.015)
    et, eF = jump_errors(t, F, ref.t, ref.F)
    assert et < 1e-9 and eF < 1e-10


def test_matched_ratio_picks_the_fastest_hybrid_run_that_is_as_accurate():
    """Synthetic rows: the regularised run (error 1e-3, 2 s) is matched with the 0.002 s hybrid run (error
    5e-4), not the faster but less accurate 0.001 s run (error 2e-3): ratio exactly 1000."""
    mk = lambda m, e, t: WPRow("s", m, "x", 0.0, 1e-6, e, 0.0, e, t, 1, 1, 2)  # noqa: E731
    rows = [mk("hybrid", 2e-3, 0.001), mk("hybrid", 5e-4, 0.002), mk("hybrid", 1e-6, 0.004),
            mk("regularized", 1e-3, 2.0), mk("regularized", math.inf, 1.0)]
    (r,) = matched_ratios(rows)
    assert r["ratio"] == pytest.approx(1000.0) and r["hybrid_error"] == 5e-4


@pytest.mark.slow
def test_fold_passage_delay_scales_as_eps_to_two_thirds():
    """Hypothesis (singular perturbation theory of a fold, the known ε^(2/3) law): the regularised scheme's
    jump at the AB fold lags the ε → 0 jump by C ε^p with p = 2/3.  Two ε two decades apart give p from their
    ratio; tolerance ±0.05 on p (measured 0.668 over ε = 1e-11…1e-5: the transit after the fold adds an O(ε)
    term, a 1 % effect at ε = 1e-4).  Slow tier (~8 s): the default tier checks the same law at a fraction of
    the cost, tests/test_exact.py::test_regularized_converges_to_hybrid at the AB fold and
    tests/test_law_runs.py::test_regularized_cubic_converges_to_the_hybrid_like_eps_two_thirds over jumps
    at both folds."""
    rows = eps_study(BENCH_SCENES[0], (1e-4, 1e-6))
    assert all(r.status == "ok" for r in rows)
    p_ab = math.log(rows[0].delay_ab / rows[1].delay_ab) / math.log(100.0)
    p_cd = math.log(rows[0].delay_cd / rows[1].delay_cd) / math.log(100.0)
    assert abs(p_ab - 2 / 3) < 0.05 and abs(p_cd - 2 / 3) < 0.05
    assert rows[1].delay_ab > 0 and rows[1].delay_cd > 0  # a delay, not an advance


def test_eps_study_needs_three_reference_jumps():
    """A horizon with fewer than 3 reference jumps cannot measure one passage of each fold: ValueError."""
    with pytest.raises(ValueError, match="at least 3 jumps"):
        eps_study(BenchScene("short", 1.0, 1e-5, 0.005), (1e-6,))


@pytest.mark.slow
def test_benchmark_quick_cli_writes_its_outputs(tmp_path):
    """``peelapprox benchmark --quick --no-peers --out DIR`` (the benchmark's acceptance run, ~1 min) writes the
    table, CSV/JSON and both plots; its JSON parses; on every scene the hybrid error falls monotonically by at
    least 1e4 from rtol 1e-4 to 1e-12 (DOP853 is 8th order; measured >= 1e6), and the regularised runs'
    errors sit above 1e-4 (their ε-bias at ε = 1e-7: measured 4.5e-4 … 0.14)."""
    from peelapprox.cli import main

    assert main(["benchmark", "--quick", "--no-peers", "--format", "json", "--out", str(tmp_path)]) == 0
    for name in ("benchmark.md", "work_precision.csv", "work_precision.json", "work_precision.png",
                 "eps_study.csv", "eps_study.png", "ratios.csv", "targets.json"):
        assert (tmp_path / name).stat().st_size > 0, name
    rows = json.loads((tmp_path / "work_precision.json").read_text())
    for sc in BENCH_SCENES:
        hyb = sorted((r for r in rows if r["scene"] == sc.name and r["method"] == "hybrid"), key=lambda r: -r["rtol"])
        errs = [r["error"] for r in hyb]
        assert all(a > b for a, b in zip(errs, errs[1:])) and errs[0] / errs[-1] > 1e4
        reg = [r["error"] for r in rows
               if r["scene"] == sc.name and r["method"] == "regularized" and r["status"] == "ok"]
        assert reg and min(reg) > 1e-4
