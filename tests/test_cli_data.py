"""``peelapprox series FILE`` and ``peelapprox infer FILE`` (issue 36, item 3); ``ForceSeries.to_csv`` /
``to_dataframe`` and ``Slips.to_dataframe``."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from comparisons.benchmark.detector_bias import DROP, sawtooth
from peelapprox import ForceSeries
from peelapprox.cli import main


@pytest.fixture()
def trace(tmp_path):
    t, F = sawtooth(40, 20.0, 0.1, cycles=60, seed=2)
    s = ForceSeries(t / 10.0, F, V=1.0)  # 60 cycles of 0.1 s at 400 Hz
    path = tmp_path / "trace.csv"
    s.to_csv(str(path))
    return s, str(path)


def test_to_csv_round_trips_bitwise_and_dataframes(trace):
    """``to_csv`` then ``from_csv`` gives the same samples bitwise (17 significant digits); the DataFrames hold
    the trace and the slips (same numbers as the arrays, exactly)."""
    s, path = trace
    back = ForceSeries.from_csv(path)
    assert np.array_equal(back.t, s.t) and np.array_equal(back.F, s.F)
    df = s.to_dataframe()
    assert list(df.columns) == ["t", "F"] and np.array_equal(df["F"].to_numpy(), s.F)
    assert df.attrs["units"] == {"t": "s", "F": "N"} and df.attrs["V"] == 1.0
    sl = s.slips()
    sdf = sl.to_dataframe()
    assert len(sdf) == len(sl) and np.array_equal(sdf["drop"].to_numpy(), sl.drop)
    assert np.isnan(sdf["stick_before"].iloc[0]) and sdf.attrs["units"]["rise"] == "N/s"


def test_cli_series(trace, tmp_path, capsys):
    """``series FILE`` prints the observables of the trace (the slips the library finds: 58 or 59 of 60 cycles,
    the mean drop within 2 % of 5.6 N, the detector's goal), writes the slips and the plots."""
    s, path = trace
    slips_out, plot = tmp_path / "slips.csv", tmp_path / "trace.png"
    assert main(["series", path, "--V", "1", "--format", "json", "--slips-out", str(slips_out),
                 "--plot", str(plot)]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["status"] == "stick-slip" and 58 <= row["n_slips"] <= 59
    assert abs(row["force_drop"] / DROP - 1) < 0.02
    with open(slips_out) as fh:
        assert len(list(csv.DictReader(fh))) == row["n_slips"]
    assert plot.stat().st_size > 1000


def _status(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's own refusals (exit 2)
        return int(exc.code)


def test_cli_series_bad_input(tmp_path, capsys):
    """A missing file and bad --columns exit 2 with one line naming them."""
    assert _status(["series", str(tmp_path / "none.csv")]) == 2
    assert "none.csv" in capsys.readouterr().err
    p = tmp_path / "x.csv"
    p.write_text("t,F\n0,1\n")
    assert _status(["series", str(p), "--columns", "t"]) == 2
    assert "--columns" in capsys.readouterr().err


def test_cli_infer_reports_progress(tmp_path, capsys):
    """``infer FILE --free k`` reports each exact run on stderr and prints a result with a status (a 20 s budget:
    "budget" or "converged"; the fit's accuracy is exact.infer's, tested in tests/test_infer.py).  The trace is 1 s
    (10 slips of the period-8 orbit at 10 kHz): each of the fit's ~25 exact runs covers the trace, and 2 s of it
    made the test twice as long (5.7 s of CPU against 3.0 s, warm) for the same report."""
    import exact
    from peelapprox import PeelParams

    tr = exact.simulate(PeelParams(V=1.0, I=1e-2), 31.0, t_eval=30.0 + np.arange(10000) / 1e4)
    path = tmp_path / "run.csv"
    tr.as_series(1e4, noise=0.5, seed=1).to_csv(str(path))
    assert main(["infer", str(path), "--V", "1", "--I", "1e-2", "--k", "950", "--free", "k", "--search", "1.2",
                 "--max-wall", "20", "--format", "json"]) == 0
    cap = capsys.readouterr()
    res = json.loads(cap.out)
    assert res["status"] in ("budget", "converged") and "k" in res["values"]
    assert "infer: " in cap.err


def test_cli_infer_refuses_attractors_and_replicates_out_of_range(tmp_path, capsys):
    """``--attractors`` and ``--replicates`` take 1-8 (exact.infer's range): 0 and 9 exit 2 naming the option,
    before the trace is read."""
    for opt in ("--attractors", "--replicates"):
        for bad in ("0", "9"):
            with pytest.raises(SystemExit) as e:
                main(["infer", str(tmp_path / "none.csv"), "--V", "1", opt, bad])
            assert e.value.code == 2 and opt in capsys.readouterr().err
