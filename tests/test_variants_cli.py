"""Downstream of the solver: the model variants (tape mass, constant load) on the command line, the
paper's reduced equations refusing them, and a variant trajectory's repr, DataFrame, .npz and plot.

The CLI runs are checked against the Python API run with the same settings: the CLI calls
``exact.simulate`` with the same arguments (the same code path), so the numbers must be EQUAL, not close.
Runs are short (10-20 ms of model time, ~1 s of wall time each) to keep the default tier fast."""

from __future__ import annotations

import json
import types

import numpy as np
import pytest

import exact
import peelapprox as pa
from peelapprox.cli import main

V, I = 1.0, 1e-5
T_END = 0.012  # past the first AB->CD jump at ~3.6-4.2 ms (PREAMBLE: m = 1e-3 kg: 4.22 ms) and the CD->AB one
M_LOAD = 25.0  # kg: F_L = M g = 245.2 N, inside [f_min, f_max] = [199, 286] N at V = 1: stick-slip


def _json_run(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


@pytest.fixture(scope="module")
def load_run():
    """The massless tape under a load (method regularized, the model's default), 12 ms."""
    return exact.simulate(pa.PeelParams(V=V, I=I, loading="load", load_mass=M_LOAD), T_END)


# ------------------------------------------------------------------------------------------------ the CLI runs

def test_simulate_tape_mass_equals_the_python_run(capsys):
    """``--tape-mass 1e-4 --solver LSODA``: the smooth method (picked by the model), the same jump count, the
    same force range at the jumps and the same final state as exact.simulate with those settings (exact
    equality: one code path)."""
    row = _json_run(capsys, ["simulate", "--V", "1", "--I", "1e-5", "--t-end", str(T_END), "--tape-mass", "1e-4",
                             "--solver", "LSODA", "--format", "json", "--quiet"])
    tr = exact.simulate(pa.PeelParams(V=V, I=I, tape_mass=1e-4), T_END, solver="LSODA", progress=False)
    assert row["method"] == tr.method == "smooth"
    assert row["tape_mass"] == 1e-4 and row["loading"] == "velocity"
    assert row["jumps"] == len(tr.jumps) >= 2  # the AB->CD jump and the landing back on AB
    assert row["F_at_jumps_range"] == [float(tr.jumps.F.min()), float(tr.jumps.F.max())]
    assert row["final_state"] == tr.final_state.as_dict()
    assert "Vp" not in row["final_state"]  # velocity control: no pull-speed state


def test_simulate_load_equals_the_python_run(capsys, load_run):
    """``--loading load --load-mass 25``: the load defaults to M g (9.80665 m/s², exact product), the
    regularized method is picked (massless tape), and the jumps, the final state (with V_p) and V_p's range equal
    the Python run's."""
    row = _json_run(capsys, ["simulate", "--V", "1", "--I", "1e-5", "--t-end", str(T_END), "--loading", "load",
                             "--load-mass", "25", "--format", "json", "--quiet"])
    tr = load_run
    assert row["load"] == M_LOAD * pa.GRAVITY and row["load_mass"] == M_LOAD
    assert row["method"] == tr.method == "regularized"
    assert row["jumps"] == len(tr.jumps) >= 1
    assert row["final_state"] == tr.final_state.as_dict() and "Vp" in row["final_state"]
    assert row["Vp_range"] == [float(tr.Vp.min()), float(tr.Vp.max())]


def test_simulate_help_lists_the_variants_with_units(capsys):
    """``simulate --help`` documents the four options with their units and the three methods."""
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    for s in ("--tape-mass KG", "[kg]", "--loading {velocity,load}", "--load-mass KG", "--load N", "[N]",
              "{hybrid,regularized,smooth}", "DOP853", "RK45"):
        assert s in out, s


@pytest.mark.parametrize("argv, what", [
    (["estimate", "--V", "1", "--I", "1e-5", "--tape-mass", "1e-4"], "reduced equations"),
    (["segment", "--V", "1", "--I", "1e-2", "--branch", "AB", "--F-in", "200", "--alpha-in", "0",
      "--alphadot-in", "0", "--loading", "load", "--load-mass", "25"], "reduced equations"),
    (["orbit", "--V", "1", "--I", "1e-5", "--tape-mass", "1e-4"], "hybrid"),
    (["bifurcation", "--V", "1", "--I", "1e-5", "--param", "V", "--range", "0.5:1.5:3", "--loading", "load",
      "--load-mass", "25"], "hybrid"),
    (["basins", "--V", "1", "--I", "1e-5", "--alpha0", "0:0.1:2", "--F0", "200:250:2", "--orbits",
      "--tape-mass", "1e-4"], "hybrid"),
])
def test_commands_of_the_massless_model_refuse_the_variants(capsys, argv, what):
    """The commands built on the paper's massless model (the reduced equations; the hybrid orbit tools) refuse a
    variant option before any computation: exit status 2 (a bad argument) and one line naming the option and
    why, never a silent run of the massless model."""
    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and what in err
    assert ("--tape-mass" in err) or ("--loading" in err)


def test_tape_mass_zero_is_the_massless_model(capsys):
    """``--tape-mass 0`` means the massless tape (PeelParams' convention): estimate accepts it and prints what it
    prints without the option."""
    base = _json_run(capsys, ["estimate", "--V", "1", "--I", "1e-5", "--format", "json"])
    zero = _json_run(capsys, ["estimate", "--V", "1", "--I", "1e-5", "--tape-mass", "0", "--format", "json"])
    assert zero == base


@pytest.mark.parametrize("argv, opt", [
    (["--tape-mass", "1e3"], "--tape-mass must be"),
    (["--loading", "load"], "--load-mass is required"),
    (["--load-mass", "25"], "--load-mass is used only with loading='load'"),
])
def test_bad_variant_options_name_the_option(capsys, argv, opt):
    """An out-of-range or inconsistent variant option is a usage error (2) naming the option as spelt."""
    with pytest.raises(SystemExit) as e:
        main(["simulate", "--V", "1", "--I", "1e-5", "--t-end", "0.01", *argv])
    assert e.value.code == 2 and opt in capsys.readouterr().err


# ---------------------------------------------------------------------------- the reduced equations refuse

_TAPE = pa.PeelParams(V=V, I=I, tape_mass=1e-4)
_LOAD = pa.PeelParams(V=V, I=I, loading="load", load_mass=M_LOAD)


@pytest.mark.parametrize("call", [
    lambda p: pa.estimate(p),
    lambda p: pa.crude_branch_time(p),
    lambda p: pa.reduced_segment(p, "AB", F_in=200.0, alpha_in=0.0, alphadot_in=0.0),
    lambda p: pa.airy_alpha(p, [0.0, 1e-3], F_in=250.0, alpha_in=0.0, alphadot_in=0.0, F_rate=1e3),
    lambda p: pa.inertial_period(p, 250.0),
], ids=["estimate", "crude_branch_time", "reduced_segment", "airy_alpha", "inertial_period"])
@pytest.mark.parametrize("params", [_TAPE, _LOAD], ids=["tape", "load"])
def test_reduced_equations_refuse_a_variant(call, params):
    """Every entry point of the paper's reduced equations refuses a variant with one message (the one validator,
    peelapprox.validate.paper_model) naming params.tape_mass / params.loading and why."""
    with pytest.raises(ValueError, match=r"params\.tape_mass / params\.loading: .*massless DAE under velocity "
                                         r"control"):
        call(params)


def test_compare_refuses_a_variant_trajectory():
    """The comparison harness refuses a variant's trajectory before reading it (the check is the validator's)."""
    from comparisons import compare

    with pytest.raises(ValueError, match=r"trajectory\.params\.tape_mass / trajectory\.params\.loading: compare"):
        compare(types.SimpleNamespace(params=_TAPE))


def test_paper_model_passes_the_validator():
    """The paper's model is returned as is (the check costs nothing on the default path)."""
    from peelapprox.validate import paper_model

    p = pa.PeelParams(V=V, I=I)
    assert paper_model("params", p, where="x") is p


# ------------------------------------------------------------------------- a variant trajectory's data out

def test_load_trajectory_dataframe_npz_and_repr(tmp_path, load_run):
    """Under a load: the DataFrame has a Vp column equal to traj.Vp (the array itself) in m/s and the variant in
    attrs; the .npz round trip gives back every array exactly and the params (with the variant); the repr names
    the load."""
    pytest.importorskip("pandas")
    tr = load_run
    df = tr.to_dataframe()
    assert list(df.columns) == ["t", "alpha", "omega", "F", "v", "Vp", "branch"]
    assert np.array_equal(df["Vp"].to_numpy(), tr.Vp) and df.attrs["units"]["Vp"] == "m/s"
    assert df.attrs["params"]["load_mass"] == M_LOAD and df.attrs["variant_units"]["load"] == "N"
    path = tmp_path / "load.npz"
    tr.to_npz(path)
    back = exact.Trajectory.from_npz(path)
    for name in ("t", "alpha", "omega", "F", "v", "Vp", "branch"):
        assert np.array_equal(getattr(back, name), getattr(tr, name)), name
    assert back.params == tr.params and back.params.variant == "eps_load"
    assert back.final_state == tr.final_state and back.final_state.Vp is not None
    assert "load_mass=25.0 kg" in repr(tr) and "loading='load'" in repr(tr)


def test_paper_trajectory_dataframe_is_unchanged():
    """Velocity control: no Vp column, no variant attrs, the repr as before (no variant fields)."""
    pytest.importorskip("pandas")
    tr = exact.simulate(pa.PeelParams(V=V, I=I), 0.005)
    df = tr.to_dataframe()
    assert "Vp" not in df.columns and "variant_units" not in df.attrs
    assert "tape_mass" not in repr(tr) and "load" not in repr(tr)


def test_plot_trajectory_shows_the_pull_speed_under_a_load(tmp_path, load_run):
    """The force panel gets a twin axis with V_p(t) (its data the stored V_p), and the title names the load."""
    pytest.importorskip("matplotlib")
    from peelapprox.plotting import plot_trajectory

    fig = plot_trajectory(load_run, str(tmp_path / "load.png"), cycles=None)
    assert "load F_L = 245.2 N on M = 25 kg" in fig._suptitle.get_text()
    twins = [a for a in fig.axes if a.get_ylabel() == "$V_p$ [m/s]"]
    assert len(twins) == 1
    assert np.array_equal(twins[0].lines[0].get_ydata(), load_run.Vp)
    assert (tmp_path / "load.png").stat().st_size > 0


def test_sweep_runs_the_tape_mass_at_every_point(tmp_path):
    """``peelapprox sweep --tape-mass`` passes the variant to the measures: its ``jumps`` record's slip count equals
    that of a direct window run of the tape-mass model with the same settings (exactly: the same run), and the
    manifest records the option.  Half a second of window after a quarter of transient (the tape-mass model's
    LSODA run is the test's cost): it holds 4 slips (measured), where the massless model's same window holds 7, so a
    sweep that ran the massless model instead, or nothing, would differ."""
    out = tmp_path / "sw"
    assert main(["sweep", "--I", "1e-5", "--V", "1", "--measure", "jumps", "--t-transient", "0.25", "--window", "0.5",
                 "--tape-mass", "1e-3", "--out", str(out), "--workers", "0", "--quiet", "--format", "json"]) == 0
    rec = json.loads((out / "results.jsonl").read_text().splitlines()[0])
    tr = exact.window_run(pa.PeelParams(V=1.0, I=1e-5, tape_mass=1e-3), t_transient=0.25, window=0.5)
    slips = int(np.sum(tr.jumps.from_branch == 0))
    assert rec["jumps_n_slips"] == slips >= 3
    assert json.loads((out / "sweep.json").read_text())["options"]["tape_mass"] == 1e-3
