"""Data out in the ecosystem's shapes : pandas DataFrames and xarray Datasets of the result
objects, the ImportError without the ``data`` extra, and the short ``__repr__``/``_repr_html_`` of notebooks.

The round-trips are checked against the result objects' own arrays and records, compared **exactly**
(``np.array_equal``, ``==``): a DataFrame column or a Dataset variable is the same float64 data moved into
another container, so any difference, even in the last bit, would be a bug (a lost, reordered or converted
value), not round-off.  Where an object can be built by hand (sweep records, orbits, branches, report rows)
it is, with numbers chosen here, so that the expected values do not come from the code under test.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

import exact
from comparisons import CompareReport, ComparisonRow, Row, RowTable, StatRow, compare
from comparisons.sweep import SweepResult
from peelapprox import BRANCHES, PeelForce, PeelParams

pd = pytest.importorskip("pandas", reason="the data extra (pandas) is not installed: pip install 'peelapprox[data]'")
xr = pytest.importorskip("xarray", reason="the data extra (xarray) is not installed: pip install 'peelapprox[data]'")

P = PeelParams(V=1.0, I=1e-5)


@pytest.fixture(scope="module")
def traj():
    """1 s of the paper's low-inertia stick-slip: a few thousand points and about 25 jumps."""
    return exact.simulate(P, 1.0)


# ------------------------------------------------------------------------------------------------ trajectory
def test_trajectory_dataframe_columns_are_the_arrays_exactly(traj):
    """Every column is the trajectory's array, bit for bit; the branch column spells the codes as BRANCHES."""
    df = traj.to_dataframe()
    assert list(df.columns) == ["t", "alpha", "omega", "F", "v", "branch"]
    assert len(df) == len(traj.t) > 100
    for c in ("t", "alpha", "omega", "F", "v"):
        assert df[c].dtype == np.float64
        assert np.array_equal(df[c].to_numpy(), getattr(traj, c))
    assert list(df["branch"].astype(str)) == [BRANCHES[b] for b in traj.branch]
    assert set(df["branch"].astype(str)) == {"AB", "CD"}


def test_trajectory_dataframe_attrs_hold_units_params_and_law(traj):
    """Units per column, the parameters (V, I, k, R, l, geometry) and the law (repr and key) of the run."""
    a = traj.to_dataframe().attrs
    assert a["units"] == {"t": "s", "alpha": "rad", "omega": "rad/s", "F": "N", "v": "m/s", "branch": ""}
    assert a["params"]["V"] == 1.0 and a["params"]["I"] == 1e-5 and a["params"]["k"] == 1000.0
    assert a["params"]["geometry"] == "paper"
    assert a["params"]["force"] == "PeelForce.paper()" and a["params"]["force_key"] == PeelForce.paper().key
    assert a["method"] == "hybrid" and a["rtol"] == 1e-8 and a["t_end"] == 1.0


def test_jumps_dataframe_matches_the_jumps(traj):
    """One row per jump, the float columns equal to the arrays, the branches as names of the codes."""
    j = traj.jumps
    df = j.to_dataframe()
    assert list(df.columns) == list(j.FIELDS) and len(df) == len(j) > 10
    for c in ("t", "alpha", "omega", "F", "v_before", "v_after"):
        assert np.array_equal(df[c].to_numpy(), getattr(j, c))
    assert list(df["from_branch"].astype(str)) == [x.from_branch for x in j]
    assert list(df["to_branch"].astype(str)) == [x.to_branch for x in j]
    assert df.attrs["units"]["F"] == "N" and df.attrs["units"]["v_after"] == "m/s"


@pytest.mark.parametrize("module, call", [
    ("pandas", lambda t: t.to_dataframe()),
    ("pandas", lambda t: t.jumps.to_dataframe()),
    ("pandas", lambda t: RowTable().to_dataframe(StatRow)),
    ("xarray", lambda t: SweepResult([1e-5], [1.0], ["regime"], {}, []).to_xarray()),
])
def test_missing_optional_dependency_names_the_extra(traj, monkeypatch, module, call):
    """Without pandas/xarray (an import of None in sys.modules fails), the message says what is needed and how
    to install it."""
    monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(ImportError, match=rf"needs {module}: pip install 'peelapprox\[data\]'"):
        call(traj)


# ------------------------------------------------------------------------------------------------ sweeps
def _records(coef=None):
    """Hand-made records of a 2 x 3 grid (one point left out, one with a string and a None)."""
    recs = []
    for i, I in enumerate((1e-5, 1e-3)):
        for j, V in enumerate((0.5, 1.0, 2.0)):
            for k, c in enumerate(coef or [None]):
                if (i, j, k) == (1, 2, 0):
                    continue  # not computed yet
                r = {"I": I, "V": V, "status": "ok", "jumps_mean_period": 0.1 * (i + 1) + j + 10 * k,
                     "period_label": f"period-{j + 1}", "jumps_mean_force_drop": None if j == 1 else 40.0 + i}
                if c is not None:
                    r["coef"] = c
                recs.append(r)
    return recs


def test_sweep_dataset_values_equal_the_records():
    """At every (I, V) the Dataset's value is the record's; a point without a record or a None value is NaN (a
    number variable) or "" (a text variable); units and descriptions are attrs."""
    res = SweepResult([1e-5, 1e-3], [0.5, 1.0, 2.0], ["jumps", "period"], {"t_transient": 5}, _records())
    ds = res.to_xarray()
    assert ds["jumps_mean_period"].dims == ("I", "V") and ds.sizes == {"I": 2, "V": 3}
    assert np.array_equal(ds["I"].values, [1e-5, 1e-3]) and np.array_equal(ds["V"].values, [0.5, 1.0, 2.0])
    for rec in res.records:
        pt = ds.sel(I=rec["I"], V=rec["V"])
        assert pt["jumps_mean_period"].item() == rec["jumps_mean_period"]
        assert pt["period_label"].item() == rec["period_label"]
        f = pt["jumps_mean_force_drop"].item()
        assert (math.isnan(f) if rec["jumps_mean_force_drop"] is None else f == rec["jumps_mean_force_drop"])
    missing = ds.sel(I=1e-3, V=2.0)
    assert math.isnan(missing["jumps_mean_period"].item()) and missing["period_label"].item() == ""
    assert ds["jumps_mean_period"].attrs["units"] == "s" and "period" in ds["jumps_mean_period"].attrs["description"]
    assert ds["jumps_mean_force_drop"].attrs["units"] == "N"
    assert ds.attrs["force"] == "PeelForce.paper()" and ds.attrs["points"] == 5 and ds.attrs["total"] == 6
    assert '"t_transient": 5' in ds.attrs["options"]


def test_sweep_dataset_has_the_coefficient_axis():
    """With a law coefficient swept, the Dataset is 3-D (I, V, coef) and each value is its record's."""
    res = SweepResult([1e-5, 1e-3], [0.5, 1.0, 2.0], ["jumps"], {}, _records([200.0, 300.0]),
                      force=PeelForce.cubic(), coef=("c", [200.0, 300.0]))
    ds = res.to_xarray()
    assert ds["jumps_mean_period"].dims == ("I", "V", "coef") and ds.sizes["coef"] == 2
    assert "coefficient c" in ds["coef"].attrs["description"] and ds.attrs["coef_name"] == "c"
    for rec in res.records:
        assert ds["jumps_mean_period"].sel(I=rec["I"], V=rec["V"], coef=rec["coef"]).item() == rec["jumps_mean_period"]


def test_sweep_run_dataset_equals_the_values_arrays(tmp_path):
    """A real (closed-form) sweep: each numeric variable is ``values(key)`` exactly."""
    from comparisons.sweep import sweep

    res = sweep([1e-5, 1e-3], [1.0, 2.0], ["regime"], out=str(tmp_path / "s"), max_workers=0, progress=False)
    ds = res.to_xarray()
    for key in ("regime_inertia_ratio", "regime_period_at_mean", "regime_force_gap"):
        assert np.array_equal(ds[key].values, res.values(key))
    assert ds["regime_period_at_mean"].attrs["units"] == "s"
    assert ds["regime_label"].sel(I=1e-5, V=1.0).item() == res.record(1e-5, 1.0)["regime_label"]


# ------------------------------------------------------------------------------------------------ basins, orbits
@pytest.fixture(scope="module")
def basin():
    """A 2 x 2 basin grid of short runs (seconds): the labels need not be converged to test the data out."""
    return exact.basins(P, alpha0=[0.0, 0.1], F0=[250.0, 270.0], t_transient=2.0, window=3.0, max_workers=0,
                        progress=False)


def test_basins_dataset_holds_the_labels(basin):
    """label, outcome and n_returns are the result's arrays over (alpha0, F0), with units on the coordinates."""
    ds = basin.to_xarray()
    assert ds["label"].dims == ("alpha0", "F0")
    assert np.array_equal(ds["label"].values, basin.labels) and np.array_equal(ds["n_returns"].values, basin.n_returns)
    assert np.array_equal(ds["alpha0"].values, basin.alpha0) and np.array_equal(ds["F0"].values, basin.values)
    for i, a in enumerate(basin.alpha0):
        for j, f in enumerate(basin.values):
            pt = ds.sel(alpha0=a, F0=f)
            assert pt["outcome"].item() == basin.texts[i, j]
            lab = int(basin.labels[i, j])
            assert pt["n"].item() == (basin.attractors[lab].n if lab >= 0 else 0)
    assert ds["F0"].attrs["units"] == "N" and ds["alpha0"].attrs["units"] == "rad"
    assert ds.attrs["params_V"] == 1.0 and ds.attrs["window"] == 3.0


def _orbit(value, F, stable=True):
    """A hand-made period-1 orbit (numbers chosen here, no solver)."""
    return exact.PeriodicOrbit(params=PeelParams(V=value, I=1e-5), n=1, period=0.08 + value / 100,
                               section_states=np.array([[0.1, 2.0]]), return_map_values=np.array([F]),
                               itinerary=("CD", "AB"), multipliers=np.array([0.5 + 0j, 0.01 + 0j]), stable=stable,
                               residual=1e-12, newton=(1e-3, 1e-12), monodromy=np.eye(2))


def test_orbit_branch_dataframe_is_its_rows():
    """One row per point, in order, equal to rows(); the parameter's unit and the stop reason in attrs."""
    pts = tuple(exact.BranchPoint(v, _orbit(v, 280.0 - v)) for v in (1.0, 1.2, 1.4))
    br = exact.OrbitBranch("V", pts, (exact.Bifurcation("period_doubling", 1.3, pts[1].orbit),), "stop", "",
                           0.5, 1.4)
    df = br.to_dataframe()
    assert df.to_dict("records") == br.rows()
    assert list(df["V"]) == [1.0, 1.2, 1.4] and list(df["F1"]) == [279.0, 278.8, 278.6]
    assert df.attrs["units"]["V"] == "m/s" and df.attrs["units"]["period"] == "s" and df.attrs["units"]["F1"] == "N"
    assert df.attrs["stopped"] == "stop" and df.attrs["bifurcations"] == [{"kind": "period_doubling", "value": 1.3}]
    r = repr(br)
    assert r.count("\n") == 0 and "3 points" in r and "period_doubling at 1.3" in r and "stop at 1.4" in r
    assert br._repr_html_().startswith("<table")


def test_orbit_diagram_dataframe_is_its_rows():
    """One row per (value, return); a value without returns is one row with F NaN."""
    d = exact.OrbitDiagram("I", np.array([1e-5, 2e-5]), (np.array([270.0, 280.0]), np.zeros(0)),
                           ("period-2", "breakdown:v_floor"), 1.0)
    df = d.to_dataframe()
    assert list(df["I"]) == [1e-5, 1e-5, 2e-5] and list(df["label"]) == ["period-2", "period-2", "breakdown:v_floor"]
    assert df["F"].iloc[:2].tolist() == [270.0, 280.0] and math.isnan(df["F"].iloc[2])
    assert df.attrs["units"] == {"I": "kg m²", "F": "N", "label": ""}
    r = repr(d)
    assert r.count("\n") == 0 and "2 values" in r and "period-2 ×1" in r


# ------------------------------------------------------------------------------------------------ comparisons
def test_compare_returns_a_list_that_becomes_a_dataframe(traj):
    """compare() still returns a list (of ComparisonRow); its DataFrame holds each row's fields, None as NaN."""
    rows = compare(traj)
    assert isinstance(rows, list) and isinstance(rows, RowTable) and len(rows) > 5
    df = rows.to_dataframe()
    assert list(df.columns) == [f for f in ComparisonRow.__dataclass_fields__]
    assert df["dt_exact"].tolist() == [r.dt_exact for r in rows]
    for x, r in zip(df["dt_rel_error"], rows):
        assert (math.isnan(x) if r.dt_rel_error is None else x == r.dt_rel_error)
    assert df.attrs["units"]["dF_exact"] == "N" and df.attrs["units"]["dt_exact"] == "s"


def test_compare_report_tables():
    """The report's rows (with the verdict), statistics and timings as DataFrames; an unknown table is a
    ValueError naming the argument; the repr counts the verdicts."""
    rows = [Row("s1", "dt", "exact", "m", 1.0, 1.0, 1.05, 1.0, 0.05, 0.1),
            Row("s1", "dF", "exact", "m", 1.0, 1.0, 1.5, 1.0, 0.5, 0.1),
            Row("s2", "dt", "exact", "m", None, None, None, 1.0, None, 0.1, status="breakdown: v_floor")]
    stats = [StatRow("run", "regime", "AB", "m", "dt", 10, 1, 9, 0.01, 0.02, 0.03)]
    rep = CompareReport(rows, stats, {"run": "past the transient"}, {"total": 12.5})
    df = rep.to_dataframe()
    assert df["verdict"].tolist() == ["within", "outside", "failed: breakdown: v_floor"]
    assert df["ours_approx"].iloc[0] == 1.05
    st = rep.to_dataframe("stats")
    assert st.iloc[0]["p90"] == 0.02 and st.iloc[0]["n_failed"] == 1
    assert rep.to_dataframe("timings").to_dict("records") == [{"step": "total", "wall_time": 12.5}]
    with pytest.raises(ValueError, match="table must be one of"):
        rep.to_dataframe("nope")
    r = repr(rep)
    assert r.count("\n") == 0 and "1 within, 1 outside, 1 failed" in r and "12.5 s" in r


# ------------------------------------------------------------------------------------------------ reprs
def _short(obj, *numbers, max_len: int = 400) -> None:
    """One line, at most ``max_len`` characters (no arrays), with the key numbers; the HTML a table with them.
    Each of ``numbers`` is a text found in both, or ``(in the repr, in the HTML)``."""
    r, h = repr(obj), obj._repr_html_()
    assert r.count("\n") == 0 and len(r) <= max_len, r
    assert h.startswith("<table") and h.endswith("</table>")
    for n in numbers:
        in_repr, in_html = n if isinstance(n, tuple) else (n, n)
        assert in_repr in r, (in_repr, r)
        assert f">{in_html}<" in h or in_html in h, (in_html, h)


def test_reprs_are_short_and_carry_the_key_numbers(traj, basin):
    """The result objects with big arrays print as one line of key numbers (and a small HTML table)."""
    nj, nab = len(traj.jumps), int(np.sum(traj.jumps.from_branch == 0))
    _short(traj, (f"jumps={nj}", f">{nj}<"), (f"points={len(traj.t)}", f">{len(traj.t)}<"))
    _short(traj.jumps, (f"{nj} jumps", f">{nj}<"), (f"{nab} AB→CD", f">{nab}<"))
    _short(basin, "2 alpha0 x 2 F0")
    _short(_orbit(1.0, 285.8), ("period-1", "period-1"), "285.8", ("T=0.09 s", ">0.09<"))
    logs = np.full(10_000, 0.01)  # a constant log growth 0.01 per interval of 0.5: exponent exactly 0.02
    b = exact.BenettinResult.from_logs(logs, np.full(10_000, 0.5), 1e-8, 3.0)
    _short(b, ("exponent=0.02", ">0.02<"), ("n=10000", ">10000<"))
    ly = exact.LyapunovResult(b.exponent, b.exponent / math.log(2), 0.5, b, P, 0.5, 1234)
    _short(ly, "0.02885 ± 0.5", ("jumps=1234", ">1234<"))
    res = SweepResult([1e-5, 1e-3], [0.5, 1.0, 2.0], ["jumps"], {}, _records())
    r = repr(res)
    assert r.count("\n") == 0 and "5/6 points" in r
    assert "5/6" in res._repr_html_()


def test_datasets_round_trip_through_netcdf(tmp_path, basin):
    """The attrs are flat scalars and strings, so the Datasets write to netCDF (scipy's engine, netCDF3) and read
    back equal, values exactly (the labels fit int32, netCDF3's integer)."""
    res = SweepResult([1e-5, 1e-3], [0.5, 1.0, 2.0], ["jumps", "period"], {"t_transient": 5}, _records())
    for ds, name in ((res.to_xarray(), "sweep.nc"), (basin.to_xarray(), "basins.nc")):
        ds.to_netcdf(tmp_path / name, engine="scipy")
        with xr.open_dataset(tmp_path / name, engine="scipy") as back:
            assert back.load().identical(ds)
