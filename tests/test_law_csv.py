"""Laws from files: ``PeelForce.from_csv`` (units in the header or stated), the shared reader
``peelapprox._csvread.read_columns``, and the CLI's ``--force-table FILE --smooth`` and ``--force-fit FILE
--family NAME``."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from peelapprox import PeelForce
from peelapprox._csvread import read_columns
from peelapprox.cli import build_parser, main
from peelapprox.cli._force import force_from_args

V_PTS = np.logspace(math.log10(0.2), math.log10(3.0), 40)


def _cubic(v: np.ndarray) -> np.ndarray:
    return np.asarray(PeelForce.cubic().f(v, 1.0))


def _write(path, header: str, rows) -> str:
    path.write_text(header + "\n" + "".join(",".join(repr(float(x)) for x in r) + "\n" for r in rows))
    return str(path)


def test_from_csv_plain_and_with_units(tmp_path):
    """The plain header gives ``tabulated`` of the numbers (equal: read by float()); ``v [mm/s]``, ``f [kN]``
    are converted to m/s and N (to 1 ulp: one multiplication), in any column order."""
    v = np.geomspace(0.1, 5.0, 12)
    f = _cubic(v)
    law = PeelForce.from_csv(_write(tmp_path / "a.csv", "v,f", zip(v, f)))
    assert law == PeelForce.tabulated(v, f)
    units = PeelForce.from_csv(_write(tmp_path / "b.csv", "f [kN], v [mm/s]", zip(f / 1e3, v * 1e3)))
    vv, ff = np.array(units.tables[0][1]), np.array(units.tables[0][2])
    assert np.allclose(vv, v, rtol=4e-16, atol=0) and np.allclose(ff, f, rtol=4e-16, atol=0)


def test_from_csv_columns_and_stated_units(tmp_path):
    """``columns`` names other header cells (others ignored) and states a unit the header lacks."""
    v = np.geomspace(0.1, 5.0, 12)
    f = _cubic(v)
    path = _write(tmp_path / "c.csv", "speed,temperature,force", zip(v * 60.0, np.full(v.size, 20.0), f))
    law = PeelForce.from_csv(path, columns={"v": "speed [m/min]", "f": "force"})
    assert np.allclose(law.tables[0][1], v, rtol=4e-16, atol=0)
    path2 = tmp_path / "d.csv"
    path2.write_text("v;f\n" + "".join(f"{float(a)!r};{float(b)!r}\n" for a, b in zip(v, f)))
    assert PeelForce.from_csv(str(path2), delimiter=";") == PeelForce.tabulated(v, f)


@pytest.mark.parametrize("content, says", [
    (b"", "no header"),
    (b"# only a comment\n\n", "no header"),
    (b"v,f\n", "no data rows"),
    (b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe", "not UTF-8 text"),
    (b"v,f\n0.1,2\x00\n", r"line 2 column 2 \(f\): not a number: '2\\x00'"),
    (b"v [furlong/s],f\n0.1,200\n", "column v: unknown unit 'furlong/s'; the units of a velocity are m/s"),
    (b"v [N],f\n0.1,200\n", "column v: the unit 'N' is a force, but v must be given in m/s"),
    (b"v,f\n0.1,200\n0.2,abc\n", r"line 3 column 2 \(f\): not a number: 'abc'"),
    (b"v,f\n0.1,200\n0.2,250\n0.3,nan\n1,200\n2,300\n", r"f must be finite: f\[2\] = nan \(line 4\)"),
])
def test_from_csv_bad_files(tmp_path, content, says):
    """An empty or binary file, an unknown unit or one of another dimension, a bad cell: a ValueError naming the
    file and the line (and column)."""
    path = tmp_path / "bad.csv"
    path.write_bytes(content)
    with pytest.raises(ValueError, match=f"bad.csv.*{says}"):
        PeelForce.from_csv(str(path))


def test_from_csv_bad_arguments(tmp_path):
    """Wrong argument types and values: TypeError/ValueError naming the argument."""
    path = _write(tmp_path / "a.csv", "v,f", zip(V_PTS, _cubic(V_PTS)))
    with pytest.raises(TypeError, match="path must be"):
        PeelForce.from_csv(3)
    with pytest.raises(ValueError, match="delimiter must be"):
        PeelForce.from_csv(path, delimiter="ab")
    with pytest.raises(ValueError, match="columns must name"):
        PeelForce.from_csv(path, columns={"x": "v"})
    with pytest.raises(ValueError, match="header 'v,f': expected the columns speed,f"):
        PeelForce.from_csv(path, columns=("speed", "f"))


def test_read_columns_returns_lines_and_converts(tmp_path):
    """The shared reader: the columns asked for, converted (ms -> s), the file line of each row, optional columns
    absent from the result when the file lacks them."""
    path = tmp_path / "trace.csv"
    path.write_text("# a trace\nt [ms],F [kN]\n0,1.5\n\n1,1.6  # note\n")
    cols = read_columns(str(path), {"t": "s", "F": "N", "V": "m/s"}, where="trace", optional=("V",))
    assert set(cols) == {"t", "F", "line"}
    assert np.allclose(cols["t"], [0.0, 1e-3], rtol=1e-15) and np.allclose(cols["F"], [1500.0, 1600.0], rtol=1e-15)
    assert cols["line"].tolist() == [3, 5]


def _law(*flags: str) -> PeelForce:
    return force_from_args(build_parser().parse_args(["estimate", "--V", "1", "--I", "1e-5", *flags]))


def test_cli_smooth_and_fit(tmp_path, capsys):
    """``--force-table FILE --smooth`` is ``PeelForce.smoothed`` of the file's points and ``--force-fit FILE
    --family cubic`` is ``PeelForce.fit`` (equal laws: the same numbers through the same functions);
    ``folds --force-fit`` prints the fitted law's folds."""
    f = _cubic(V_PTS) * (1 + 0.01 * np.random.default_rng(3).standard_normal(V_PTS.size))
    path = _write(tmp_path / "noisy.csv", "v [m/s],f [N]", zip(V_PTS, f))
    assert _law("--force-table", path, "--smooth") == PeelForce.smoothed(V_PTS, f)
    with pytest.raises(ValueError, match="local minimum.*; for noisy points add --smooth, or fit a family"):
        _law("--force-table", path)
    assert _law("--force-fit", path, "--family", "cubic") == PeelForce.fit(V_PTS, f, "cubic")
    assert main(["folds", "--V", "1", "--force-fit", path, "--family", "cubic", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["has_folds"] and row["law"].startswith("PeelForce.cubic(")


@pytest.mark.parametrize("flags, says", [
    (["--smooth"], "--smooth smooths the points of --force-table"),
    (["--family", "cubic"], "--force-fit FILE and --family NAME go together"),
])
def test_cli_smooth_and_fit_misuse(flags, says):
    """--smooth without --force-table, --family without --force-fit: a ValueError saying so."""
    with pytest.raises(ValueError, match=says):
        _law(*flags)


def test_cli_fit_errors_name_the_option(tmp_path):
    """A family that cannot be fitted to the file (too few points for its coefficients) names the option and
    the file."""
    path = _write(tmp_path / "few.csv", "v,f", zip(V_PTS[:4], _cubic(V_PTS[:4])))
    with pytest.raises(ValueError, match=r"--force-fit .*few.csv.* --family power_branches: v, f: 4 point"):
        _law("--force-fit", path, "--family", "power_branches")
