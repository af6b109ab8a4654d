"""A model is a type: ``exact.MODELS`` holds one object per model (its state layout, field, events, start and the
methods that solve it), ``simulate(model=...)`` takes one, and adding one is one module and a registration
(CONTRIBUTING.md, "Adding a model": tested on a copy of the packages)."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import exact
from exact._model import model_of, model_parameters
from peelapprox import PeelParams

ROOT = Path(__file__).resolve().parents[1]

PARAMS = {
    "massless": PeelParams(V=1.0, I=1e-5),
    "massless_load": PeelParams(V=1.0, I=1e-5, loading="load", load_mass=1e-2),
    "tape_mass": PeelParams(V=1.0, I=1e-5, tape_mass=1e-3),
    "tape_mass_load": PeelParams(V=1.0, I=1e-5, tape_mass=1e-3, loading="load", load_mass=1e-2),
}


def test_the_registry_holds_one_object_per_model():
    """Hypothesis: MODELS maps each built-in model's name to a frozen instance of its class, with the state layout,
    the methods (default first) and the events the models had as variant switches before (exact equality), and
    the parameters of each variant pick their model."""
    assert list(exact.MODELS) == ["massless", "massless_load", "tape_mass", "tape_mass_load"]
    classes = (exact.Massless, exact.MasslessLoad, exact.TapeMass, exact.TapeMassLoad)
    for (name, model), cls in zip(exact.MODELS.items(), classes, strict=True):
        assert type(model) is cls and isinstance(model, exact.Model) and model.name == name
        assert model_of(PARAMS[name]) is model
        with pytest.raises(dataclasses.FrozenInstanceError):
            model.name = "other"  # type: ignore[misc]
    assert [m.n_states for m in exact.MODELS.values()] == [4, 5, 4, 5]
    assert [m.methods for m in exact.MODELS.values()] == [("hybrid", "regularized"), ("regularized",),
                                                          ("smooth",), ("smooth",)]
    assert [("arrest" in m.events, "no_root" in m.events) for m in exact.MODELS.values()] == [
        (False, True), (True, True), (True, False), (True, False)]


@pytest.mark.parametrize("name", list(PARAMS))
def test_a_named_model_runs_as_the_one_params_describe(name):
    """Hypothesis: ``simulate(params, model=name)`` and ``model=MODELS[name]`` are the run of ``simulate(params)``
    itself, bit for bit (tolerance 0: the same model object drives the same run), with the model's default
    method."""
    ref = exact.simulate(PARAMS[name], 2e-3)
    assert ref.method == exact.MODELS[name].methods[0]
    for model in (name, exact.MODELS[name]):
        tr = exact.simulate(PARAMS[name], 2e-3, model=model)
        for field in ("t", "alpha", "omega", "F", "v"):
            np.testing.assert_array_equal(getattr(tr, field), getattr(ref, field))


def test_a_model_refuses_what_it_does_not_solve():
    """Hypothesis: a model name outside MODELS, an object of another type, parameters of another model and a
    method the model does not list are ValueErrors (TypeError for the type) naming what was given and what fits."""
    p = PARAMS["massless"]
    with pytest.raises(ValueError, match=r"model must be one of .*'massless'.*got 'nope'"):
        exact.simulate(p, 1e-3, model="nope")
    with pytest.raises(TypeError, match="model must be None, a name in exact.MODELS or an exact.Model, got int"):
        exact.simulate(p, 1e-3, model=3)
    with pytest.raises(ValueError, match=r"model='tape_mass' is the tape-mass model .*params describe the massless "
                                         r"tape under velocity control"):
        exact.simulate(p, 1e-3, model="tape_mass")
    with pytest.raises(ValueError, match=r"method='hybrid' .* does not solve the tape-mass model .* use "
                                         r"method='smooth'"):
        exact.simulate(PARAMS["tape_mass"], 1e-3, method="hybrid")


def test_register_model_checks_its_argument():
    """Hypothesis: only a Model enters the registry, and a name cannot be taken twice (the registry is unchanged
    after both refusals)."""
    before = dict(exact.MODELS)
    with pytest.raises(TypeError, match="model must be an exact.Model, got str"):
        exact.register_model("massless")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="a model named 'massless' is registered already"):
        exact.register_model(exact.Massless(about="a second one"))
    with pytest.raises(ValueError, match=r"events of model 'x' must be among"):
        exact.Massless(name="x", events=("bounce",))
    assert exact.MODELS == before


def _contributing_block() -> tuple[str, str]:
    """The module and the registration line of CONTRIBUTING.md's "Adding a model" section."""
    text = (ROOT / "CONTRIBUTING.md").read_text()
    section = text.split("\n## Adding a model\n", 1)[1].split("\n## ", 1)[0]
    module, line = re.findall(r"```python\n(.*?)```", section, re.S)
    return module, line


#: The run of the toy model in the copy; with ``{run_default}`` the paper's parameters' default is *run*
#: (``simulate(p, 1e-3).method``: the hybrid driver compiled in the copy's empty cache, ~20 s of CPU), else read
#: where ``simulate`` reads it (``model_of`` and ``default_method``, which pick the model and the method of a
#: call without ``model=`` or ``method=``).
_RUN = """
import json, math, exact
from exact._method_contract import default_method
from peelapprox import PeelParams
assert exact.__file__.startswith({root!r}), exact.__file__
p = PeelParams(V=1.0, I=1e-5)
toy = exact.MODELS["rigid_roller"]
w = math.sqrt(p.k * p.R ** 2 / p.I)
tr = exact.simulate(p, 0.01, model="rigid_roller", omega0=p.V / p.R + 0.01 * w, rtol=1e-10, atol=1e-14)
print(json.dumps(dict(method=tr.method, w=w, t=tr.t.tolist(), alpha=tr.alpha.tolist(), omega=tr.omega.tolist(),
                      F=tr.F.tolist(), F0=tr.initial_state.F, v=tr.v.tolist(), v0=tr.initial_state.v,
                      default=exact.simulate(p, 1e-3).method if {run_default} else default_method(p),
                      default_model=exact.model_of(p).name, type=type(toy).__name__, has_hybrid=toy.has_hybrid,
                      under_load=toy.under_load, parameters=toy.parameters, Vp=tr.Vp is None,
                      columns=list(tr.to_dataframe().columns))))
"""


@pytest.mark.parametrize("run_default", [False, pytest.param(True, marks=pytest.mark.slow)],
                         ids=["default_read", "default_run"])
def test_a_model_added_as_contributing_says_runs_through_simulate(tmp_path, run_default):
    """Hypothesis: the section's module, written into a copy of the packages with its registration line, is a
    model of ``simulate(model=...)``: its default method (smooth, the one it lists) integrates its field, the
    linear roller ``α'' = -Ω² α`` (Ω² = k R² / I) with F and v held, from the consistent start with
    ``ω0 = V/R + A Ω``, A = 0.01 rad; the orbit is ``α = A sin(Ω t)``, ``ω = V/R + A Ω cos(Ω t)`` to 1e-7 of A
    and A Ω (LSODA at rtol 1e-10 over ~1.6 periods: a global error of ~1e-9 relative, while a wrong sign or
    frequency is O(1)), F and v stay at the start's values exactly (their rates are 0), and the paper's
    parameters still run the paper's model by default.

    The default tier reads that default where ``simulate`` picks it (``exact.model_of``, ``default_method``: the
    massless model, hybrid); running it (``run_default``, the hybrid driver compiled in the copy's own empty
    cache, ~20 s of CPU) is slow: covered in the default tier by the ``default_read`` case and by
    test_a_named_model_runs_as_the_one_params_describe (``simulate(params)`` is the run of ``model_of(params)``
    with its first method)."""
    pkg = tmp_path / "pkg"
    for name in ("peelapprox", "exact"):
        shutil.copytree(ROOT / name, pkg / name, ignore=shutil.ignore_patterns("__pycache__"))
    module, line = _contributing_block()
    (pkg / "exact" / "_model_rigid.py").write_text(module)
    models = pkg / "exact" / "_models.py"
    models.write_text(models.read_text() + "\n" + line)
    env = dict(os.environ, PYTHONPATH=str(pkg), NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    code = _RUN.format(root=str(pkg), run_default=run_default)
    out = subprocess.run([sys.executable, "-c", code], cwd=pkg, env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    got = json.loads(out.stdout)
    assert got["type"] == "RigidRoller" and got["method"] == "smooth" and got["default"] == "hybrid"
    assert got["default_model"] == "massless"
    # the questions the tools ask a model (the hybrid method's tools, a load's pull speed, the fields it reads):
    # the base class's answers for a model that lists only "smooth" and the four states
    assert (got["has_hybrid"], got["under_load"], got["parameters"], got["Vp"]) == (False, False, [], True)
    assert got["columns"] == ["t", "alpha", "omega", "F", "v", "branch"]
    t, w, a = np.array(got["t"]), got["w"], 0.01
    assert t[-1] == 0.01 and t[-1] * w / (2 * math.pi) > 1.5
    np.testing.assert_allclose(got["alpha"], a * np.sin(w * t), rtol=0, atol=1e-7 * a)
    np.testing.assert_allclose(np.array(got["omega"]) - 1.0 / PARAMS["massless"].R, a * w * np.cos(w * t), rtol=0,
                               atol=1e-7 * a * w)
    assert set(got["F"]) == {got["F0"]} and set(got["v"]) == {got["v0"]}


@pytest.mark.parametrize("name", list(PARAMS))
def test_each_model_field_has_its_layout(name):
    """Hypothesis: each model's field, at seeded random states in its layout ``states``, has FLOW1's
    ``α̇ = ω - v/R`` as its first component (to 1e-12 relative of the terms: one rounding of the subtraction, while
    a state out of place is an O(1) error) and one rate per state, finite; its Jacobian is square in the
    layout."""
    model, p = exact.MODELS[name], PARAMS[name]
    law = model.law(p)
    fun, jac = model.field(p, law, 1e-7 if "regularized" in model.methods else None)
    rng = np.random.default_rng(38)
    for _ in range(5):
        y = np.array([rng.uniform(-0.3, 0.3), rng.uniform(5.0, 20.0), rng.uniform(100.0, 300.0),
                      10 ** rng.uniform(-3, 0.5)] + ([rng.uniform(0.5, 2.0)] if model.n_states == 5 else []))
        rate = np.asarray(fun(0.0, y))
        assert rate.shape == (model.n_states,) and np.all(np.isfinite(rate))
        assert np.asarray(jac(0.0, y)).shape == (model.n_states, model.n_states)
        expected = y[1] - y[3] / p.R
        assert abs(rate[0] - expected) <= 1e-12 * (abs(y[1]) + abs(y[3] / p.R))


def test_the_questions_tools_ask_a_model():
    """Hypothesis: the properties the tools read instead of the parameters' variant fields answer, for each built-in
    model, what those fields said (exact: booleans and names): only the paper's massless tape has the hybrid method
    (so its tools and the refusal of a scipy ``solver``), the models under a load integrate the pull speed ``Vp``,
    each model lists the fields it reads, the load's selected by ``loading="load"`` (which ``with_parameter``
    sets with a load's parameter), and a variant's trajectory shows the variant fields that are set, with their
    units, in its repr and its DataFrame's attrs (the paper's model: none)."""
    assert [m.has_hybrid for m in exact.MODELS.values()] == [True, False, False, False]
    assert [m.under_load for m in exact.MODELS.values()] == [False, True, False, True]
    assert [dict(m.parameters) for m in exact.MODELS.values()] == [
        {}, {"loading": "", "load_mass": "kg", "load": "N"}, {"tape_mass": "kg", "loading": ""},
        {"tape_mass": "kg", "loading": "", "load_mass": "kg", "load": "N"}]
    assert [m.selected_by for m in exact.MODELS.values()] == [(), (("loading", "load"),), (), (("loading", "load"),)]
    # the numeric parameters, each set with the field values that select its first model (a load's loading)
    owners = {n: m.name for n, m in model_parameters().items()}
    assert owners == {"tape_mass": "tape_mass", "load_mass": "massless_load", "load": "massless_load"}
    p = PARAMS["massless"]
    assert exact.with_parameter(p, "load_mass", 2.0) == p.replace(loading="load", load_mass=2.0)
    for zero in (0, 0.0, np.int64(0), np.float32(0.0)):  # 0 of any real type: the massless model
        assert exact.with_parameter(PARAMS["tape_mass"], "tape_mass", zero) == p
    assert exact.model_of(PARAMS["tape_mass"]) is exact.MODELS["tape_mass"]
    tr = exact.simulate(PARAMS["tape_mass"], 1e-3)
    assert "tape_mass=0.001 kg, loading='velocity'," in repr(tr)
    attrs = tr.to_dataframe().attrs
    assert attrs["variant_units"] == {"tape_mass": "kg", "loading": ""}
    assert (attrs["params"]["tape_mass"], attrs["params"]["loading"]) == (1e-3, "velocity")
    tr = exact.simulate(PARAMS["massless"], 1e-3)
    assert "tape_mass" not in repr(tr) and "variant_units" not in tr.to_dataframe().attrs
