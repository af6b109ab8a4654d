"""The command line's conventions: ``python -m peelapprox`` and ``--version``; every
subcommand's help has a description, examples, every default and unit, no raw markup, and lists what the
subcommand can do; the same parameter flags and ``--format`` choices; units in table output; ``figures`` writes
into a directory of its own; ``compare`` ends with a within/outside/failed summary."""

from __future__ import annotations

import argparse
import csv
import io
import json
import subprocess
import sys

import pytest

from peelapprox import __version__
from peelapprox.cli import build_parser, main
from peelapprox.cli._common import FORMATS
from peelapprox.cli.figures import DEFAULT_OUT
from peelapprox.cli.sweep import MEASURES_HELP


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    ap = build_parser()
    sub = next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


SUB = _subparsers()
#: Options that carry a physical quantity: their help must give its unit in brackets.
PHYSICAL = {"V", "I", "k", "R", "l", "t_end", "t_transient", "window", "alpha0", "omega0", "F0", "F_in", "alpha_in",
            "alphadot_in", "v_in", "v_f", "lyapunov_time", "max_wall", "alpha_min", "alpha_max", "amplitude", "phase"}


def _block(text: str, option: str) -> str:
    """The help of ``option`` in a rendered help text: its line and the indented lines after it."""
    lines = text.splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith("  -") and line.split()[0].rstrip(",") == option)
    out = [lines[i]]
    for line in lines[i + 1:]:
        if not line.startswith("    "):  # the next option, a group title or a blank line
            break
        out.append(line)
    return " ".join(" ".join(out).split())


def test_python_m_peelapprox_and_version():
    """Hypothesis: ``python -m peelapprox --version`` runs the package's CLI and prints ``peelapprox <version>`` of
    ``peelapprox._version`` (exact string), exit status 0; ``python -m peelapprox --help`` lists the commands."""
    out = subprocess.run([sys.executable, "-m", "peelapprox", "--version"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == f"peelapprox {__version__}"
    out = subprocess.run([sys.executable, "-m", "peelapprox", "--help"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and all(name in out.stdout for name in SUB)


@pytest.mark.parametrize("name", sorted(SUB))
def test_every_subcommand_help_has_description_examples_defaults_units_and_no_markup(name):
    """Hypothesis: each subcommand's help has a description, an examples section whose commands are this
    subcommand, every option with a default states it, every physical option its unit ``[...]``, and the text has
    no raw markup (backticks, Sphinx roles); exact string checks on the rendered help."""
    sp = SUB[name]
    text = sp.format_help()
    assert sp.description and len(sp.description) > 80
    examples = text.split("examples:\n", 1)[1]
    assert examples.count(f"peelapprox {name}") >= 1
    for markup in ("`", ":func:", ":class:", ":mod:", ":data:", ":meth:"):
        assert markup not in text, markup
    for a in sp._actions:
        if not a.option_strings or a.dest in ("help", "version"):
            continue
        block = _block(text, a.option_strings[0])
        if a.default not in (None, False) and not isinstance(a.default, list):
            assert "default" in block, (a.option_strings[0], block)
        if a.dest in PHYSICAL:
            assert "[" in block and "]" in block, (a.option_strings[0], block)


def test_the_same_parameter_flags_and_formats_on_every_subcommand():
    """Hypothesis: the subcommands that run the exact model take --V --I --k --R --l --geometry and the law; those of
    the reduced equations --V --I --k --R and the law; sweep --k --R --l --geometry; every subcommand that prints
    a result takes --format with table, csv and json among its choices, those printing one summary exactly
    these (set equality)."""
    def flags(sp):
        return {s for a in sp._actions for s in a.option_strings}

    model = {"--V", "--I", "--k", "--R", "--force", "--force-family", "--force-table"}
    for name in ("simulate", "dynamics", "orbit", "bifurcation", "basins"):
        assert model | {"--l", "--geometry"} <= flags(SUB[name]), name
    for name in ("estimate", "segment"):
        assert model <= flags(SUB[name]), name
    assert {"--k", "--R", "--l", "--geometry", "--force"} <= flags(SUB["sweep"])
    for name, sp in SUB.items():
        if name == "figures":
            continue
        fmt = next(a for a in sp._actions if "--format" in a.option_strings)
        assert set(FORMATS) <= set(fmt.choices) and fmt.default == "table", name
        if name in ("simulate", "folds", "estimate", "segment", "dynamics", "orbit", "bifurcation", "basins"):
            assert tuple(fmt.choices) == FORMATS, name


def test_help_lists_what_a_subcommand_can_do():
    """Hypothesis: sweep --help names every built-in measure of comparisons.sweep (and only measures it has); dynamics
    --help every Lyapunov method of exact.lyapunov; segment and compare --help every alpha model and v equation;
    bifurcation --help the parameters it continues in (exact string checks)."""
    from comparisons.sweep import MEASURES
    from exact.dynamics._lyapunov_options import LYAPUNOV_METHODS
    from peelapprox import ALPHA_MODELS, V_EQUATIONS

    text = " ".join(SUB["sweep"].format_help().split())
    assert set(MEASURES_HELP) <= set(MEASURES) and {"regime", "jumps", "period", "lyapunov"} == set(MEASURES_HELP)
    assert all(f"{m}:" in text for m in MEASURES_HELP)
    dyn = " ".join(SUB["dynamics"].format_help().split())
    assert all(m in dyn for m in LYAPUNOV_METHODS)
    for name in ("segment", "compare"):
        text = " ".join(SUB[name].format_help().split())
        assert all(m in text for m in (*ALPHA_MODELS, *V_EQUATIONS)), name
    assert "V, I, k or force.NAME" in " ".join(SUB["bifurcation"].format_help().split())


def test_table_output_has_units_and_csv_is_one_row(capsys):
    """Hypothesis: ``folds --format table`` prints each quantity with its unit (m/s, N, N s/m) and ``--format csv``
    a header and one row with the same values as ``--format json`` (exact strings and float equality)."""
    main(["folds", "--V", "1"])
    lines = {line.split(":")[0].strip(): line.split(":", 1)[1].strip() for line in capsys.readouterr().out.splitlines()}
    assert lines["V"] == "1 m/s" and lines["v_max"].endswith(" m/s") and lines["f_max"].endswith(" N")
    assert lines["fprime_at_V"].endswith(" N s/m") and lines["has_folds"] == "True"
    main(["folds", "--V", "1", "--format", "json"])
    js = json.loads(capsys.readouterr().out)
    main(["folds", "--V", "1", "--format", "csv"])
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert len(rows) == 1 and float(rows[0]["v_max"]) == js["v_max"] and float(rows[0]["f_min"]) == js["f_min"]


def test_simulate_table_output_has_units(capsys):
    """Hypothesis: ``simulate``'s summary gives times in s, forces in N and the final state with each unit
    (exact string checks)."""
    main(["simulate", "--V", "1", "--I", "1e-2", "--t-end", "0.2", "--quiet"])
    out = capsys.readouterr().out
    assert "t_end: 0.2 s" in out and "F_at_jumps_range: [" in out and "] N" in out
    assert "final_state: t = 0.2 s, alpha = " in out and " rad, omega = " in out and " rad/s, F = " in out


def test_figures_writes_into_its_own_directory_not_docs(tmp_path, monkeypatch, capsys):
    """Hypothesis: ``figures`` without --out writes into ./peelapprox-figures of the working directory, and a
    ``docs/`` that happens to be there stays untouched (exact: file listings)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "docs").mkdir()
    assert main(["figures", "--only", "fig2"]) == 0
    assert DEFAULT_OUT == "peelapprox-figures" and DEFAULT_OUT in SUB["figures"].format_help()
    assert sorted(p.name for p in (tmp_path / DEFAULT_OUT).iterdir()) == ["fig2.png"]
    assert list((tmp_path / "docs").iterdir()) == []
    assert f"fig2: {DEFAULT_OUT}/fig2.png" in capsys.readouterr().out


def test_compare_explains_its_columns_and_ends_with_a_summary(capsys):
    """Hypothesis: the table output starts with the columns' meaning and ends with ``Summary: N rows: a within
    ..., b outside, c failed ...`` whose counts are those of the rows' verdicts in ``--format json`` (exact)."""
    argv = ["compare", "--scene", "case-II-point-a", "--no-stats"]
    main(argv)
    out = capsys.readouterr().out
    main([*argv, "--format", "json"])
    rows = json.loads(capsys.readouterr().out)["rows"]
    v = [r["verdict"] for r in rows]
    assert out.startswith("Columns: quantity = ")
    last = out.strip().splitlines()[-1]
    assert last == (f"Summary: {len(rows)} rows: {v.count('within')} within the paper's claim, {v.count('outside')} "
                    f"outside, {sum(x.startswith('failed') for x in v)} failed (the reduction stopped), "
                    f"{sum(x == '' for x in v)} without a claim.")
