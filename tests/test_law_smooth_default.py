"""``PeelForce.smoothed``'s default penalty on plausible measured N-shaped data (issue 36, item 1), its bound on
many points, its refusal of non-positive forces (as ``tabulated``), and the CLI's ``--lam``.

The data: 40 points of the cubic family (v from 0.1 to 5 m/s, log-spaced) with relative normal noise; the truth
is the cubic's own fold, f_min = 184.549 N at v_min = 1.809 m/s (closed form: the roots of f' = 0)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from peelapprox import PeelForce
from peelapprox.cli import main

V40 = np.geomspace(0.1, 5.0, 40)
F_MIN, F_MAX = 184.54915028125276, 240.4508497187474  # the cubic's folds (a=150, b=300, c=300, d=80)


def _noisy(seed: int, noise: float, v: np.ndarray = V40) -> np.ndarray:
    return PeelForce.cubic().f(v, 1.0) * (1 + noise * np.random.default_rng(seed).standard_normal(v.size))


def test_truth_is_the_closed_form():
    """The cubic's folds are the roots of f' = 300 - 600 v + 240 v^2 (to 1e-12: rounding of the fold search)."""
    r = np.sort(np.roots([240.0, -600.0, 300.0]))
    f = PeelForce.cubic().f(r, 1.0)
    bs = PeelForce.cubic().folds(1.0)
    assert bs.v_max == pytest.approx(r[0], rel=1e-9) and bs.v_min == pytest.approx(r[1], rel=1e-9)
    assert (f[0], f[1]) == pytest.approx((F_MAX, F_MIN), rel=1e-12)


def test_default_penalty_works_on_noisy_cubic_many_seeds():
    """10 seeds at 1 % noise: the default (``lam="gcv"``, shape-constrained) always gives an N-shaped law, with
    |f_min - 184.55| <= 5 N (2.7 %) and |f_max - 240.45| <= 6 N.  Why: over 100 seeds the largest errors measured
    4.31 N and 4.95 N (sd 1.4 N: each datum is off by ~1.8 N at the fold); the issue's failing default raised on
    4 of the first 10 seeds, and lam = 1e-2 biased f_min to 137 N.  Ten seeds (were 30) still meet that failing
    default four times; all 100 at 1 % are ``test_default_penalty_over_noise_levels`` (slow)."""
    errs = []
    for seed in range(10):
        bs = PeelForce.smoothed(V40, _noisy(seed, 0.01)).folds(1.0)
        errs.append((bs.f_min - F_MIN, bs.f_max - F_MAX))
    e = np.abs(np.array(errs))
    assert e[:, 0].max() <= 5.0 and e[:, 1].max() <= 6.0


@pytest.mark.slow
@pytest.mark.parametrize("noise, tol_min, tol_max", [(0.003, 2.0, 2.5), (0.01, 5.0, 6.0), (0.02, 20.0, 10.0)])
def test_default_penalty_over_noise_levels(noise, tol_min, tol_max):
    """100 seeds at each noise level: no failure; the largest f_min and f_max errors within the stated tolerance
    (measured 1.41/1.82 N at 0.3 %, 4.31/4.95 N at 1 %, 17.4/7.5 N at 2 %: at 2 % the noise (3.7 N at the fold)
    is a seventh of the N's depth, 56 N, and the least penalty that removes its wiggles flattens the fold)."""
    errs = []
    for seed in range(100):
        bs = PeelForce.smoothed(V40, _noisy(seed, noise)).folds(1.0)
        errs.append((bs.f_min - F_MIN, bs.f_max - F_MAX))
    e = np.abs(np.array(errs))
    assert e[:, 0].max() <= tol_min and e[:, 1].max() <= tol_max


def test_many_points_are_binned_and_still_right():
    """20,000 points (1 % noise) are averaged in runs to at most MAX_POINTS (the law's knots say so: at most
    MAX_POINTS + 10 for a quintic clamped at both ends), over the data's whole range, and f_min within 1 N of the
    truth (measured 0.06 N: 20 points a run average the noise down 4.5x).  The work is bounded by the binning
    (measured ~6 s on a loaded 2-core machine where it took 60 s), not asserted as a time."""
    from peelapprox.law._spline import MAX_POINTS

    v = np.geomspace(0.1, 5.0, 20000)
    law = PeelForce.smoothed(v, _noisy(0, 0.01, v))
    knots = law.tables[0][1]
    assert len(knots) <= MAX_POINTS + 10
    assert law.v_range == pytest.approx((0.1, 5.0), rel=1e-12)
    assert law.folds(1.0).f_min == pytest.approx(F_MIN, abs=1.0)


@pytest.mark.parametrize("make", [lambda v, f: PeelForce.smoothed(v, f), lambda v, f: PeelForce.fit(v, f, "cubic"),
                                  lambda v, f: PeelForce.tabulated(v, f)])
def test_non_positive_forces_refused_alike(make):
    """All-negative forces (and one zero) are refused by smoothed, fit and tabulated alike, naming f and the index."""
    f = PeelForce.cubic().f(V40, 1.0)
    with pytest.raises(ValueError, match=r"f must be > 0 .*f\[0\]"):
        make(V40, -f)
    g = f.copy()
    g[7] = 0.0
    with pytest.raises(ValueError, match=r"f must be > 0 .*f\[7\]"):
        make(V40, g)


def _csv(path, f) -> str:
    path.write_text("v,f\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(V40, f)))
    return str(path)


def test_cli_lam(tmp_path, capsys):
    """``folds --force-table pts.csv --smooth`` works by default on the issue's data (seed 3, which failed), and
    ``--lam X`` is ``PeelForce.smoothed(lam=X)``: the same f_min to 1e-9 (the same numbers through the same
    function); ``--lam`` without ``--smooth`` and a bad ``--lam`` exit 2."""
    f = _noisy(3, 0.01)
    path = _csv(tmp_path / "pts.csv", f)
    assert main(["folds", "--V", "1.2", "--force-table", path, "--smooth", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["f_min"] == pytest.approx(F_MIN, abs=5.0)
    assert main(["folds", "--V", "1.2", "--force-table", path, "--smooth", "--lam", "1e-3", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["f_min"] == pytest.approx(PeelForce.smoothed(V40, f, lam=1e-3).folds(1.2).f_min, rel=1e-9)
    for flags, says in ((["--lam", "1e-3"], "--lam is the penalty of --smooth"),
                        (["--smooth", "--lam", "big"], "must be 'gcv' or a number"),
                        (["--smooth", "--lam", "-1"], "lam")):
        assert _status(["folds", "--V", "1.2", "--force-table", path, *flags]) == 2
        assert says in capsys.readouterr().err


def _status(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's own refusals
        return int(exc.code)


def test_smoothing_length_scale():
    """The documented scale: ``smoothing_length(lam, v) = (lam L / n)^(1/4)`` (40 points over 0.1-5 m/s: L =
    ln 50; lam = 1e-3 gives 0.0996 in ln v, to rounding)."""
    from peelapprox.law._spline import smoothing_length

    assert smoothing_length(1e-3, V40) == pytest.approx((1e-3 * math.log(50.0) / 40) ** 0.25, rel=1e-12)
