"""The dynamics tools with the model variants (docs/tape-mass-dynamics.md): what runs a tape mass or
a constant load through ``exact.simulate``'s variant method, and what refuses it with a ValueError naming
``params`` and the model it supports."""

from __future__ import annotations

import importlib.util
import math

import numpy as np
import pytest

import exact
from comparisons.sweep.measures import measure_period
from comparisons.sweep.task import make_params
from peelapprox import PeelParams, return_map

TAPE = PeelParams(V=1.0, I=1e-2, tape_mass=1e-3)
SHORT = dict(t_transient=0.05, window=0.1, rtol=1e-8)


# ------------------------------------------------------------------------------------------ refusals
@pytest.mark.parametrize("call, what", [
    (lambda p: exact.periodic_orbit(p), "periodic_orbit"),
    (lambda p: exact.solve_orbit(p, [0.0, 10.0], 1), "hybrid tangent dynamics"),
    (lambda p: exact.section_return(p, [0.0, 10.0]), "hybrid tangent dynamics"),
    (lambda p: exact.lyapunov(p, "tangent"), "'tangent'"),
    (lambda p: exact.lyapunov(p, "return-map"), "'return-map'"),
    (lambda p: exact.lyapunov(p, "variational"), "'variational'"),
    (lambda p: exact.lyapunov_tangent(p), "'tangent'"),
    (lambda p: exact.lyapunov_return_map(p), "'return-map'"),
])
@pytest.mark.parametrize("params", [TAPE, PeelParams(V=1.0, I=1e-2, loading="load", load_mass=1.0)],
                         ids=["tape", "load"])
def test_hybrid_only_tools_refuse_the_variants(call, what, params):
    """The section map, saltation tangent and ε-scheme variational tools are the massless velocity-controlled
    model's: a variant is refused before any run, naming params, the variant's model (``exact.MODELS``) and the
    model supported."""
    with pytest.raises(ValueError, match="massless, velocity-controlled model only") as info:
        call(params)
    msg = str(info.value)
    model = exact.model_of(params)
    assert model.name != "massless" and what in msg and f"model {model.name!r}, {model.about}" in msg
    assert "params" in msg


def test_continuation_refuses_a_variant_parameter():
    """continue_orbit follows the massless model's section map: a variant's parameter is a ValueError naming
    it and pointing to the brute-force diagram (checked before any Newton step: the orbit is never touched)."""
    orbit = exact.PeriodicOrbit.__new__(exact.PeriodicOrbit)
    with pytest.raises(ValueError, match=r"parameter='tape_mass'.*orbit_diagram"):
        exact.continue_orbit(orbit, "tape_mass", stop=1e-3)


def test_solver_is_refused_for_the_hybrid_method():
    """The hybrid method has its own integrator: lyapunov(solver=...) on the massless model is a ValueError
    naming solver; attractors checks method/solver before its first start (not an 'infeasible start' entry)."""
    with pytest.raises(ValueError, match="solver"):
        exact.lyapunov(PeelParams(V=1.0, I=1e-2), solver="LSODA", T=0.1)
    with pytest.raises(ValueError, match="solver"):
        exact.attractors(PeelParams(V=1.0, I=1e-2), [0.0], solver="LSODA")
    with pytest.raises(ValueError, match="solver"):
        exact.lyapunov(TAPE, solver="Euler", T=0.1)


# ------------------------------------------------------------------------------------------ parameters
def test_with_parameter_takes_the_variant_parameters():
    """tape_mass 0 is the massless model itself (PeelParams equal); load_mass/load switch on loading='load';
    parameter_value reads them back (0 for no tape mass); a bad value is PeelParams' ValueError."""
    p = PeelParams(V=1.0, I=1e-2)
    assert exact.with_parameter(p, "tape_mass", 0.0) == p
    assert exact.with_parameter(p, "tape_mass", 1e-3).tape_mass == 1e-3
    q = exact.with_parameter(p, "load_mass", 2.0)
    assert (q.loading, q.load_mass, q.load) == ("load", 2.0, pytest.approx(2.0 * 9.80665, rel=1e-15))
    assert exact.with_parameter(q, "load", 15.0).load == 15.0
    assert exact.parameter_value(p, "tape_mass") == 0.0 and exact.parameter_value(TAPE, "tape_mass") == 1e-3
    with pytest.raises(ValueError, match="tape_mass"):
        exact.with_parameter(p, "tape_mass", -1.0)
    with pytest.raises(ValueError, match="tape_mass, load_mass, load"):
        exact.with_parameter(p, "mass", 1.0)


# ------------------------------------------------------------------------------------------ what runs
def test_orbit_diagram_over_the_tape_mass_has_the_massless_limit():
    """orbit_diagram(params, "tape_mass", [0, 1e-6]): m = 0 runs the hybrid method, m = 1e-6 kg the smooth one
    (LSODA).  Hypothesis: the low-mass limit (ε_eff = m (1 + sin α)² of the ε-scheme, whose jumps lag the
    hybrid's by ~ε^(2/3)): the same number of AB→CD jumps in 0.15 s and their forces equal to 2e-3 relative
    (measured 4.6e-4 at V = 1, I = 1e-2; 1e-4 at m = 1e-7)."""
    d = exact.orbit_diagram(PeelParams(V=1.0, I=1e-2), "tape_mass", [0.0, 1e-6], t_transient=0.0, window=0.15,
                            rtol=1e-8, solver="LSODA")
    F0, F1 = d.returns
    assert F0.size == F1.size >= 5
    np.testing.assert_allclose(F1, F0, rtol=2e-3)
    if importlib.util.find_spec("pandas") is not None:  # the data extra (in the test install since 0.3.0)
        assert d.to_dataframe().attrs["units"]["tape_mass"] == "kg"


def test_window_run_and_attractors_run_the_variant_method():
    """window_run passes method/solver to simulate: the tape-mass window is the smooth method's, its jumps
    those of the direct simulate call (the same deterministic run: equal to the last bit); attractors groups
    two starts of it (each with its own entry or a shared one, all with returns)."""
    tr = exact.window_run(TAPE, solver="LSODA", **SHORT)
    direct = exact.simulate(TAPE, 0.15, t_transient=0.05, rtol=1e-8, solver="LSODA", save="jumps")
    assert tr.method == "smooth" and tr.solver == "LSODA"
    np.testing.assert_array_equal(tr.jumps.t, direct.jumps.t)
    assert return_map(tr).size >= 3
    att = exact.attractors(TAPE, [0.0, 0.1], solver="LSODA", **SHORT)
    assert sum(len(a.starts) for a in att) == 2
    assert all(math.isfinite(a.F_range[0]) and a.F_range[1] > a.F_range[0] for a in att)


def test_two_trajectory_lyapunov_of_the_tape_mass_model():
    """lyapunov(method='two-trajectory') restarts the smooth ODE from the full state (α, ω, F, v).  Hypothesis:
    at V = 1, I = 1e-2 the tape (m = 1e-3 kg) settles on a periodic orbit (as the massless model, period 1),
    whose largest exponent is 0: a 0.4 s estimate (20 intervals of 0.02 s after 0.1 s) lies within 4 of its
    standard errors + 3 bits/s of 0 (short windows: the estimate's spread, docs/tape-mass-dynamics.md)."""
    r = exact.lyapunov(TAPE, t_transient=0.1, T=0.4, tau=0.02, n_discard=5, d0=1e-4, rtol=1e-9, solver="LSODA")
    assert r.method == "smooth LSODA two-trajectory (Benettin)" and r.n_jumps > 0
    assert math.isfinite(r.stderr_bits)
    assert abs(r.bits_per_s) <= 4 * r.stderr_bits + 3.0


def test_sweep_runs_a_variant_from_its_options():
    """The sweep's options carry the variant (tape_mass, loading, load_mass, load) and the solver: the period
    measure at a point counts the returns of the same window as window_run (one deterministic run); a bad
    solver is a ValueError naming it."""
    opts = {"tape_mass": 1e-3, "solver": "LSODA", "t_transient": 0.05, "t_end": 0.15, "rtol": 1e-8}
    p = make_params(1e-2, 1.0, opts)
    assert p.tape_mass == 1e-3
    rec = measure_period(p, opts)
    tr = exact.window_run(TAPE, solver="LSODA", **SHORT)
    assert rec["status"] == "ok" and rec["n_returns"] == return_map(tr).size
    with pytest.raises(ValueError, match="solver"):
        measure_period(p, {**opts, "solver": "Euler"})


def test_basins_run_the_variant_method_and_refuse_its_orbits():
    """basins passes solver to each start's simulate: the start (α0 = 0, ω0 = V/R, the default initial state)
    counts the returns of the same window as window_run (one deterministic run); orbits=True (periodic_orbit,
    the massless model's) and solver with the hybrid method are ValueErrors before any start."""
    res = exact.basins(TAPE, alpha0=[0.0], omega0=[10.0], solver="LSODA", max_workers=0, progress=False, **SHORT)
    tr = exact.window_run(TAPE, solver="LSODA", **SHORT)
    assert res.n_returns[0, 0] == return_map(tr).size
    with pytest.raises(ValueError, match="orbits=True"):
        exact.basins(TAPE, alpha0=[0.0], omega0=[10.0], orbits=True, max_workers=0, progress=False, **SHORT)
    with pytest.raises(ValueError, match="solver"):
        exact.basins(PeelParams(V=1.0, I=1e-2), alpha0=[0.0], omega0=[10.0], solver="LSODA", max_workers=0,
                     progress=False)


def test_explain_refuses_a_diagram_over_a_variant_parameter():
    """No continued branch lives in a variant's parameter: explain refuses the diagram (ValueError naming
    it) instead of returning None for every value."""
    d = exact.OrbitDiagram("tape_mass", np.array([0.0]), (np.zeros(0),), ("no stick-slip",), 0.0)
    with pytest.raises(ValueError, match="diagram.*'tape_mass'"):
        exact.explain(d, [])
