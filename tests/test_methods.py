"""The solver-method contract of ``exact.simulate``: a method is one class and one ``METHODS`` entry."""

from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np
import pytest

import exact
import exact._hybrid as H
from exact import MODELS
from exact._method_contract import Method, default_method
from exact._options import METHODS
from exact._trajectory import Jumps, SolverStats, State, Trajectory
from peelapprox import PeelParams
from peelapprox.kernels import bound_variant_field, compiled_law, variant_parameters

TAPE = PeelParams(V=1.0, I=1e-5, tape_mass=1e-3)


@dataclasses.dataclass(frozen=True, kw_only=True)
class Euler(Method):
    """Explicit Euler with a fixed step ``dt`` on the tape-mass model's smooth field: a method as a contributor
    would add one (CONTRIBUTING.md, "Adding a solver method")."""

    name: ClassVar[str] = "euler"
    about: ClassVar[str] = "explicit Euler with a fixed step on the tape-mass model's field"
    atol_scale: ClassVar[tuple[float, ...]] = (1e-4, 1e-3, 1e-2, 1e-6)
    step_budget: ClassVar[tuple[float, float, float]] = (1e8, 1e3, 1e9)
    models: ClassVar[frozenset[str]] = frozenset({"tape_mass"})
    dt: float = 1e-7
    rtol: float = 1e-8
    atol: float | None = None
    v_floor: float | None = None

    def _check_own(self) -> None:
        if not self.dt > 0:
            raise ValueError(f"dt must be positive, got {self.dt!r}")

    def run(self, model, params, t_end, s0, saveat, budget, progress):
        cl = compiled_law(params.force, params.V)
        field, _ = bound_variant_field("tape", cl.fn)
        q = variant_parameters(params, params.tape_mass)
        n = int(round((t_end - s0.t) / self.dt))
        ys = np.empty((n + 1, 4))
        ys[0] = (s0.alpha, s0.omega, s0.F, s0.v)
        for i in range(n):
            ys[i + 1] = ys[i] + self.dt * np.asarray(field(ys[i], q, cl.coef))
        t = s0.t + self.dt * np.arange(n + 1)
        end = State(float(t[-1]), *map(float, ys[-1]), "AB")
        return Trajectory(t=t, alpha=ys[:, 0], omega=ys[:, 1], F=ys[:, 2], v=ys[:, 3], branch=np.zeros(n + 1),
                          jumps=Jumps.from_buffer(np.empty((0, 8))), stats=SolverStats(n, 0, n, 0, 0.0),
                          params=params, method=self.name, solver="euler", rtol=self.rtol, atol=self.atol_vector(),
                          eps=None, initial_state=s0, final_state=end, t_end=t_end, t_transient=0.0)


@pytest.fixture
def euler(monkeypatch):
    monkeypatch.setitem(METHODS, Euler.name, Euler)
    return Euler


def test_a_registered_method_runs_through_simulate(euler):
    """Hypothesis: a class deriving from Method and entered in METHODS is a method of ``simulate`` by name and as
    an object: simulate builds the consistent start, resolves its step budget from the class and calls its run;
    its orbit of the tape-mass model (explicit Euler, dt = 1e-7 s over 2 ms) ends within 1e-3 relative of the
    built-in smooth method's (LSODA at rtol 1e-10: Euler's global error is O(dt), ~1e-5 here)."""
    tr = exact.simulate(TAPE, 2e-3, method="euler")
    assert tr.method == "euler" and tr.stats.n_steps == 20_000
    assert tr.initial_state == exact.initial_state(TAPE)
    assert exact.default_max_steps("euler", 2e-3) == 200_000
    ref = exact.simulate(TAPE, 2e-3, method="smooth", rtol=1e-10).final_state
    for name in ("alpha", "omega", "F", "v"):
        assert getattr(tr.final_state, name) == pytest.approx(getattr(ref, name), rel=1e-3)
    by_object = exact.simulate(TAPE, 2e-3, method=Euler(dt=1e-7))
    np.testing.assert_array_equal(by_object.v, tr.v)


def test_a_registered_method_keeps_the_contract_checks(euler):
    """Hypothesis: the contract's checks apply to a new method as to the built-in ones: a keyword it has no field
    for is refused naming the methods that take it, a model it does not solve is refused naming the ones that do
    (itself among them where it fits), and the defaults stay the first built-in method that solves each model."""
    with pytest.raises(ValueError, match=r"eps applies only to method='regularized' \(method='euler' is explicit"):
        exact.simulate(TAPE, 1e-3, method="euler", eps=1e-7)
    with pytest.raises(ValueError, match=r"solver applies only to method='regularized' or 'smooth'"):
        exact.simulate(TAPE, 1e-3, method="euler", solver="LSODA")
    with pytest.raises(ValueError, match=r"it does not solve the massless tape under velocity control .*"
                                         r"use method='hybrid' or 'regularized'"):
        exact.simulate(PeelParams(V=1.0, I=1e-5), 1e-3, method="euler")
    with pytest.raises(ValueError, match=r"method='hybrid' .* use method='smooth' or 'euler' \(the default there"):
        exact.simulate(TAPE, 1e-3, method="hybrid")
    assert default_method(TAPE) == "smooth" and default_method(PeelParams(V=1.0, I=1e-5)) == "hybrid"


def test_the_table_holds_the_methods_facts():
    """Hypothesis: METHODS is the one table (the built-in methods in their default order), and the public
    ATOL_SCALE and STEP_BUDGET dicts and every model's default are read from its classes (exact equality)."""
    assert list(METHODS) == ["hybrid", "regularized", "smooth"]
    assert [METHODS[n] for n in METHODS] == [exact.Hybrid, exact.Regularized, exact.Smooth]
    assert exact.ATOL_SCALE == {n: m.atol_scale for n, m in METHODS.items()}
    assert exact.STEP_BUDGET == {n: m.step_budget for n, m in METHODS.items()}
    assert {name: model.methods for name, model in MODELS.items()} == {
        "massless": ("hybrid", "regularized"), "massless_load": ("regularized",), "tape_mass": ("smooth",),
        "tape_mass_load": ("smooth",)}
    assert all(m in METHODS for model in MODELS.values() for m in model.methods)
    assert exact.Smooth.solvers == ("Radau", "BDF", "LSODA", "DOP853", "RK45") and exact.Smooth().solver == "LSODA"
    assert exact.Hybrid().solver is None and exact.Hybrid().eps is None


def test_the_hybrid_jump_columns_are_those_of_jumps():
    """Hypothesis: the compiled loop's named jump columns (exact._hybrid.J_*) are the columns
    Jumps.from_buffer reads, field by field (a row of distinct values comes back in the named fields)."""
    row = np.arange(1.0, H.N_J + 1.0)
    row[H.J_FROM], row[H.J_TO] = 0.0, 1.0
    j = Jumps.from_buffer(row[None, :])[0]
    assert (j.t, j.alpha, j.omega, j.F, j.v_before, j.v_after) == (
        row[H.J_T], row[H.J_ALPHA], row[H.J_OMEGA], row[H.J_F], row[H.J_V_BEFORE], row[H.J_V_AFTER])
    assert (j.from_branch, j.to_branch) == ("AB", "CD")


def test_the_cli_reads_its_method_and_solver_choices_from_the_table(euler):
    """Hypothesis: ``simulate --method`` and ``--solver`` take what the table holds when the parser checks them
    (a method entered after the parser was built included), and the help states each method's own default
    solver (LSODA for smooth, Radau for regularized) from the classes (exact strings)."""
    import argparse

    from peelapprox.cli import build_parser

    ap = build_parser()
    sim = next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction)).choices["simulate"]
    opts = {a.dest: a for a in sim._actions}
    assert tuple(opts["method"].choices) == ("hybrid", "regularized", "smooth", "euler")
    assert tuple(opts["solver"].choices) == ("Radau", "BDF", "LSODA", "DOP853", "RK45")
    text = " ".join(sim.format_help().split())
    assert "--method smooth: Radau, BDF, LSODA, DOP853, RK45 (default: LSODA)" in text
    assert "--method regularized: Radau, BDF, LSODA (default: Radau)" in text
    assert f"euler: {Euler.about}" in text


def test_the_sweep_reads_its_solver_choices_from_the_table(monkeypatch):
    """Hypothesis: the sweep's option ``solver`` (comparisons.sweep) and ``peelapprox sweep --solver`` accept
    every scipy solver of the table, in its order, a solver of a method entered after the parser was built
    included; an unknown one is refused naming the option (exact tuples, categorical outcome)."""
    import argparse

    from comparisons.sweep import measures
    from peelapprox.cli import build_parser

    @dataclasses.dataclass(frozen=True, kw_only=True)
    class Heun(Euler):
        name: ClassVar[str] = "heun"
        solvers: ClassVar[tuple[str, ...]] = ("Heun",)

    ap = build_parser()
    monkeypatch.setitem(METHODS, Heun.name, Heun)
    every = ("Radau", "BDF", "LSODA", "DOP853", "RK45", "Heun")
    assert measures.solvers() == every
    assert measures._check_solver({"solver": "Heun"}) == "Heun"
    with pytest.raises(ValueError, match="solver"):
        measures._check_solver({"solver": "heun"})
    sw = next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction)).choices["sweep"]
    assert tuple(next(a for a in sw._actions if a.dest == "solver").choices) == every
