"""The peel-force law on the command line: ``--force``, ``--force-table``, ``--force-family`` and the
record of the law in what the CLI prints and writes (peelapprox/cli/_force.py)."""

from __future__ import annotations

import csv
import dataclasses
import json
import math

import numpy as np
import pytest

from peelapprox import PeelForce
from peelapprox.cli import build_parser, main
from peelapprox.cli._force import force_from_args, read_force_table

BASE = ["estimate", "--V", "1", "--I", "1e-5"]


def _law(*flags: str) -> PeelForce:
    return force_from_args(build_parser().parse_args([*BASE, *flags]))


def _same(a: PeelForce, b: PeelForce) -> None:
    assert a == b and a.key == b.key and repr(a) == repr(b)


def _cubic_points(v: np.ndarray, a=150.0, b=300.0, c=300.0, d=80.0) -> np.ndarray:
    return a + b * v - c * v**2 + d * v**3


# ------------------------------------------------------------------------------------------------ the flags

def test_no_flag_is_the_papers_law():
    """Hypothesis: without a law option the law is the paper's, the very object ``PeelForce.paper()`` (identity:
    the default path must not change)."""
    assert _law() is PeelForce.paper()


def test_force_family_with_coefs():
    """Hypothesis: ``--force-family NAME --coef k=x`` is ``PeelForce.family(NAME, k=x)`` (equal, same key and
    repr; the coefficients not given at their defaults)."""
    _same(_law("--force-family", "cubic", "--coef", "a=120", "--coef", "d=75.5"),
          PeelForce.family("cubic", a=120.0, d=75.5))
    _same(_law("--force-family", "power_branches"), PeelForce.power_branches())
    _same(_law("--force-family", "paper", "--coef", "a1=410"), PeelForce.paper_family(a1=410.0))


def test_force_expression_with_consts():
    """Hypothesis: ``--force EXPR --const k=x ...`` is ``PeelForce.expression(EXPR, k=x, ...)`` (equal, same key
    and repr), and equals the cubic family's expression with the same numbers only by value of f (a different
    kind: not equal as laws)."""
    law = _law("--force", "a + b*v - c*v**2 + d*v**3", "--const", "a=150", "--const", "b=300", "--const", "c=300",
               "--const", "d=80")
    _same(law, PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150, b=300, c=300, d=80))
    v = np.geomspace(0.01, 10, 7)
    assert np.allclose(law.f(v, 1.0), _cubic_points(v), rtol=1e-14, atol=0)  # rounding of two evaluations


def test_force_table_flag(tmp_path):
    """Hypothesis: ``--force-table FILE`` is ``PeelForce.tabulated`` of the file's columns (equal, same key)."""
    v = np.geomspace(0.1, 5.0, 12)
    f = _cubic_points(v)
    path = tmp_path / "law.csv"
    path.write_text("v,f\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(v, f)))
    _same(_law("--force-table", str(path)), PeelForce.tabulated(v, f))


def test_help_lists_the_families_and_their_coefficients(capsys):
    """Hypothesis: ``--help`` names every family with its coefficients and defaults (those of
    ``PeelForce.family(name)``), e.g. ``cubic: a=150, b=300, c=300, d=80``."""
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "--help"])
    assert exc.value.code == 0
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps the lines
    for name in ("paper", "cubic", "power_branches"):
        coefs = ", ".join(f"{c}={x:g}" for c, x in PeelForce.family(name).coefficients)
        assert f"{name}: {coefs}" in text
    for flag in ("--force EXPR", "--force-table FILE.csv", "--force-family NAME", "--const NAME=VALUE",
                 "--coef NAME=VALUE"):
        assert flag in text


# ------------------------------------------------------------------------------------------------ bad flags

def _error(argv: list[str], capsys) -> str:
    """The one-line stderr of a usage error (exit 2, no traceback)."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err.strip().splitlines()[-1]


@pytest.mark.parametrize("flags", [
    ["--force", "v", "--force-family", "cubic"],
    ["--force-family", "cubic", "--force-table", "x.csv"],
    ["--force", "v", "--force-table", "x.csv"],
])
def test_the_law_options_are_mutually_exclusive(flags, capsys):
    """Hypothesis: two law options are argparse's usage error "not allowed with" (exit 2)."""
    assert "not allowed with argument" in _error([*BASE, *flags], capsys)


@pytest.mark.parametrize("flags, says", [
    (["--const", "a=1"], "--const sets a constant of --force EXPR; there is no --force"),
    (["--force-family", "cubic", "--const", "a=1"], "there is no --force"),
    (["--coef", "a=1"], "--coef sets a coefficient of --force-family NAME; there is no --force-family"),
    (["--force", "a*v", "--coef", "a=1"], "there is no --force-family"),
    (["--force-family", "cubic", "--coef", "z=1"], "unknown coefficient(s) 'z' of the 'cubic' peel-force family: its "
                                                   "coefficients are a, b, c, d"),
    (["--force-family", "nope"], "the families are paper, cubic, power_branches"),
    (["--force-family", "cubic", "--coef", "a=1", "--coef", "a=2"], "--coef a is given twice"),
    (["--force", "a*v + w", "--const", "a=1"], "unknown symbol 'w'"),
    (["--coef", "a"], "argument --coef: value must be NAME=VALUE"),
    (["--force-family", "cubic", "--coef", "a=x"], "argument --coef: value of a must be a real number, got 'x'"),
])
def test_bad_law_options_are_one_line_errors(flags, says, capsys):
    """Hypothesis: each misuse is one line naming the option and what is wrong (the family's names, its
    coefficients), exit 2."""
    line = _error([*BASE, *flags], capsys)
    assert line.startswith("peelapprox estimate: error:") and says in line


def test_a_law_the_run_cannot_use_is_a_one_line_error(capsys, tmp_path):
    """Hypothesis: a law a consumer refuses (a table of the cubic ending at 2.2 m/s, below where its AB→CD jumps
    land, 2.37 m/s: ``simulate`` refuses it before running) reaches the user as one line with exit status 2, no
    traceback, naming params.force and what to do."""
    import numpy as np

    from peelapprox import PeelForce

    v = np.exp(np.linspace(np.log(0.05), np.log(2.2), 60))
    f = PeelForce.cubic().f(v, 1.0)
    path = tmp_path / "short.csv"
    path.write_text("v,f\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(v, f)))
    line = _error(["simulate", "--V", "1.2", "--I", "1e-3", "--t-end", "0.1", "--force-table", str(path),
                   "--quiet"], capsys)
    assert line.startswith("peelapprox simulate: error: params.force") and "extend the table" in line


# ------------------------------------------------------------------------------------------------ the table file

def test_read_one_table_with_comments(tmp_path):
    """Hypothesis: whole-line and trailing ``#`` comments and blank lines are skipped, the columns found by the
    header in any order; the law equals ``PeelForce.tabulated(v, f)`` of the numbers (exact: read by float())."""
    v = np.geomspace(0.1, 5.0, 9)
    f = _cubic_points(v)
    lines = ["# measured on tape X", "", "f , v  # header, columns swapped"]
    lines += [f"{float(b)!r},{float(a)!r}" + ("  # a note" if i == 3 else "") for i, (a, b) in enumerate(zip(v, f))]
    path = tmp_path / "t.csv"
    path.write_text("\n".join(lines) + "\n")
    law = read_force_table(str(path))
    _same(law, PeelForce.tabulated(v, f))
    assert law.tables[0][0] is None  # one table: used at every V


def test_read_several_tables_grouped_by_V(tmp_path):
    """Hypothesis: with a V column the rows are grouped by V (rows of different V may interleave), one table
    per V in order of first appearance: equal to ``PeelForce.tabulated(tables=...)`` of the same numbers."""
    v = np.geomspace(0.1, 5.0, 8)
    f1, f2 = _cubic_points(v), _cubic_points(v, a=160.0)
    path = tmp_path / "t.csv"
    rows = [f"1.0,{float(a)!r},{float(b)!r}\n2.0,{float(a)!r},{float(c)!r}\n" for a, b, c in zip(v, f1, f2)]
    path.write_text("V,v,f\n" + "".join(rows))
    _same(read_force_table(str(path)), PeelForce.tabulated(tables=[(1.0, v, f1), (2.0, v, f2)]))


@pytest.mark.parametrize("text, says", [
    ("v,f\n0.1,200\n0.2,abc\n", "line 3 column 2 (f): not a number: 'abc'"),
    ("# c\nf,v\n200,0.1\n0.2\n", "line 4: 1 column(s), expected 2 (f,v)"),
    ("V,v,f\n1,0.1,200\n1,0.2,250,3\n", "line 3: 4 column(s), expected 3 (V,v,f)"),
    ("x,f\n0.1,200\n", "line 1: header 'x,f': expected the columns v,f or V,v,f"),
    ("v,v,f\n0.1,0.1,200\n", "header 'v,v,f'"),
    ("# only a comment\n", "no header"),
    ("v,f\n", "no data rows"),
    ("v,f\n0.1,200\n0.3,250\n0.2,240\n1,200\n2,300\n", "v must be strictly increasing: v[1] = 0.3 >= v[2] = 0.2 "
                                                        "(line 3)"),
    ("v,f\n0.1,200\n0.2,250\n0.3,nan\n1,200\n2,300\n", "f must be finite: f[2] = nan (line 4)"),
])
def test_a_bad_table_names_file_line_and_column(tmp_path, text, says):
    """Hypothesis: a bad table is a ValueError naming the file and the line (and column) of the bad cell, or
    passing on ``PeelForce.tabulated``'s message (which names the point) with that point's file line."""
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ValueError) as exc:
        read_force_table(str(path))
    msg = str(exc.value)
    assert msg.startswith(f"--force-table {str(path)!r}") and says in msg


def test_a_missing_table_file(tmp_path, capsys):
    """Hypothesis: an unreadable file is a one-line usage error naming it (exit 2)."""
    line = _error([*BASE, "--force-table", str(tmp_path / "none.csv")], capsys)
    assert "none.csv" in line and "cannot read it" in line


# ------------------------------------------------------------------------------------------------ the record

def test_simulate_with_a_cubic_records_the_law(tmp_path, capsys):
    """Hypothesis: ``simulate --force-family cubic`` runs the cubic and every output records it: the JSON summary
    (``law``, ``law_key``, ``law_spec`` which ``PeelForce.from_dict`` rebuilds into an equal law with the same
    key), the jumps CSV (``law``, ``law_key`` on every row) and the .npz (its params' force).  The run is the
    cubic's: every AB->CD jump leaves at its fold v_max = (c - sqrt(c² - 3bd))/(3d) and every CD->AB one at
    v_min = (c + sqrt(c² - 3bd))/(3d) (closed form; ≤ 1e-9, the fold accuracy promised for every law)."""
    from exact import Trajectory

    a, b, c, d = 150.0, 300.0, 280.0, 80.0
    law = PeelForce.cubic(a, b, c, d)
    out, jumps = tmp_path / "run.npz", tmp_path / "jumps.csv"
    rc = main(["simulate", "--V", "1.2", "--I", "1e-5", "--t-end", "0.3", "--force-family", "cubic", "--coef",
               f"c={c}", "--format", "json", "--quiet", "--out", str(out), "--jumps-csv", str(jumps)])
    assert rc == 0
    summary = json.loads(capsys.readouterr().out)
    rebuilt = PeelForce.from_dict(summary["law_spec"])
    _same(rebuilt, law)
    assert summary["law"] == repr(law) and summary["law_key"] == law.key
    with open(jumps, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == summary["jumps"] >= 4
    assert {r["law"] for r in rows} == {repr(law)} and {r["law_key"] for r in rows} == {law.key}
    root = math.sqrt(c * c - 3 * b * d)
    v_max, v_min = (c - root) / (3 * d), (c + root) / (3 * d)
    for r in rows:
        fold = v_max if r["from_branch"] == "AB" else v_min
        assert abs(float(r["v_before"]) - fold) <= 1e-9
    tr = Trajectory.from_npz(out)
    _same(tr.params.force, law)
    assert np.array_equal(tr.jumps.t, [float(r["t"]) for r in rows])  # the CSV's floats in full precision


def test_tables_written_record_the_law(tmp_path, capsys):
    """Hypothesis: a table the CLI writes (``estimate --out``) records the law on every row, ``law`` and
    ``law_key`` in CSV, and also ``law_spec`` in JSON, rebuilding the paper's law; the estimate's own columns
    come first, unchanged (the JSON's numbers equal the printed ones exactly)."""
    js, cs = tmp_path / "e.json", tmp_path / "e.csv"
    assert main([*BASE, "--out", str(js), "--format", "json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert main([*BASE, "--out", str(cs)]) == 0
    (row,) = json.loads(js.read_text())
    paper = PeelForce.paper()
    _same(PeelForce.from_dict(row["law_spec"]), paper)
    assert row["law"] == "PeelForce.paper()" and row["law_key"] == paper.key
    assert list(row)[-3:] == ["law", "law_key", "law_spec"] and row == printed
    with open(cs, newline="") as fh:
        (crow,) = list(csv.DictReader(fh))
    assert list(crow)[-2:] == ["law", "law_key"] and crow["law_key"] == paper.key
    assert row["law_spec"] == json.loads(json.dumps(dataclasses.asdict(paper)))


def test_const_keeps_integer_and_float_apart():
    """Hypothesis: ``--const a=150`` gives the law of ``a=150`` and ``--const a=150.0`` that of ``a=150.0``, as in
    Python (sympy keeps Integer and Float apart: two laws, equal values)."""
    _same(_law("--force", "a*v + 100", "--const", "a=150"), PeelForce.expression("a*v + 100", a=150))
    _same(_law("--force", "a*v + 100", "--const", "a=150.0"), PeelForce.expression("a*v + 100", a=150.0))
    _same(_law("--force", "a*v + 100", "--const", "a=1.5e2"), PeelForce.expression("a*v + 100", a=150.0))


def test_folds_of_a_given_law(tmp_path, capsys):
    """Hypothesis: ``folds --force-family cubic`` prints the cubic's folds, at the roots of f' = b - 2cv + 3dv²
    (closed form; ≤ 1e-9 as promised of every law's folds) with f there, and the fixed point's f'(V, V) (the
    polynomial, to rounding: 1e-12 relative); the record rebuilds the law.  ``--force-table`` of the same
    cubic sampled every 0.5 % in v finds v_max within one table spacing (the folds of a table are data
    points, docs/usage.md)."""
    b, c, d, V = 300.0, 300.0, 80.0, 1.2  # PeelForce.cubic()'s, a = 150 in _cubic_points
    assert main(["folds", "--V", str(V), "--force-family", "cubic", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    root = math.sqrt(c * c - 3 * b * d)
    v_max, v_min = (c - root) / (3 * d), (c + root) / (3 * d)
    assert row["has_folds"] and abs(row["v_max"] - v_max) <= 1e-9 and abs(row["v_min"] - v_min) <= 1e-9
    assert np.allclose([row["f_max"], row["f_min"]], _cubic_points(np.array([v_max, v_min])), rtol=1e-9, atol=0)
    fp = b - 2 * c * V + 3 * d * V * V
    assert row["fixed_point_stable"] is False and abs(row["fprime_at_V"] - fp) <= 1e-12 * abs(fp)
    _same(PeelForce.from_dict(row["law_spec"]), PeelForce.cubic())
    v = np.geomspace(0.05, 5.0, 925)  # ratio 1.005
    path = tmp_path / "cubic.csv"
    path.write_text("v,f\n" + "".join(f"{float(x)!r},{float(y)!r}\n" for x, y in zip(v, _cubic_points(v))))
    assert main(["folds", "--V", str(V), "--force-table", str(path), "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert abs(row["v_max"] - v_max) <= 0.005 * v_max and row["law"].startswith("PeelForce.tabulated(<V=None: 925")


def test_compare_out_records_the_papers_law(tmp_path, capsys):
    """Hypothesis: ``compare --out DIR`` writes its rows with the law they ran, the paper's (``law``, ``law_key``
    in CSV and JSON, ``law_spec`` in JSON rebuilding ``PeelForce.paper()``), after the rows' own columns, whose
    numbers equal the ones printed by ``--format json`` (exact: the same run, only metadata added)."""
    argv = ["compare", "--scene", "case-II-point-a", "--no-stats", "--no-figures"]
    assert main([*argv, "--format", "json"]) == 0
    printed = json.loads(capsys.readouterr().out)["rows"]
    assert main([*argv, "--out", str(tmp_path)]) == 0
    rows = json.loads((tmp_path / "compare_rows.json").read_text())
    paper = PeelForce.paper()
    assert [{k: v for k, v in r.items() if not k.startswith("law")} for r in rows] == printed
    assert all(r["law"] == "PeelForce.paper()" and r["law_key"] == paper.key for r in rows)
    _same(PeelForce.from_dict(rows[0]["law_spec"]), paper)
    with open(tmp_path / "compare_rows.csv", newline="") as fh:
        header = next(csv.reader(fh))
    assert header[-2:] == ["law", "law_key"] and "law_spec" not in header


def test_dynamics_variational_refuses_a_table_before_running(capsys, tmp_path):
    """Hypothesis: ``dynamics --lyapunov-method variational`` needs a closed-form law (its DiffSL model), so a
    table is refused before the window run (one line, exit 2, naming the method and the laws it runs) instead
    of after a run that may last minutes."""
    import numpy as np

    from peelapprox import PeelForce

    v = np.exp(np.linspace(np.log(0.02), np.log(10.0), 60))
    f = PeelForce.cubic().f(v, 1.0)
    path = tmp_path / "cubic.csv"
    path.write_text("v,f\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(v, f)))
    line = _error(["dynamics", "--V", "1.2", "--I", "1e-3", "--force-table", str(path), "--lyapunov-method",
                   "variational"], capsys)
    assert "--lyapunov-method variational" in line and "not PeelForce.tabulated" in line
