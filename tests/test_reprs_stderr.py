"""Short reprs and named standard errors (issue 36, item 7)."""

from __future__ import annotations

import pytest

from exact import Inference
from peelapprox import PeelParams


def _inference() -> Inference:
    return Inference(params=PeelParams(V=1.0, I=0.00996, k=1000.3), values={"I": 0.00996, "k": 1000.3},
                     stderr={"I": 0.0257, "k": 0.0166}, intervals={"I": (0.00953, 0.0104), "k": (968.0, 1034.0)},
                     identified={"I": True, "k": True}, verdicts={"I": "identified", "k": "identified"},
                     residuals=[], chi2=1.2, dof=5, status="converged", message="ok", n_evaluations=110,
                     wall_time=44.0)


def test_inference_stderr_in_the_parameters_units():
    """``stderr`` of I and k is the error of ln θ; ``stderr_abs`` is value x that (first order: 0.00996 x 0.0257 =
    2.56e-4 kg m^2, to rounding), the report prints it with "±", and the repr says the stderr is of ln θ."""
    res = _inference()
    assert res.stderr_abs["I"] == pytest.approx(0.00996 * 0.0257, rel=1e-12)
    assert res.stderr_abs["k"] == pytest.approx(1000.3 * 0.0166, rel=1e-12)
    assert "± 0.000256" in res.report()
    r = repr(res)
    assert "stderr of ln I" in r and len(r) < 300


def test_exact_run_repr_is_one_line():
    """``repr(exact_run("V1-I1e-2"))`` is one line under 200 characters naming the run and counting its segments
    (it printed every segment)."""
    from comparisons import exact_run

    run = exact_run("V1-I1e-2")
    r = repr(run)
    assert "\n" not in r and len(r) < 200 and "V1-I1e-2" in r and f"{len(run.segments)} segments" in r
