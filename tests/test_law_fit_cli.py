"""``--force-fit`` weighted by a sigma column, with standard errors and chi^2 (issue 36, item 2), and a fit
without a significant N shape said so (issue 34)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from peelapprox import PeelForce
from peelapprox.cli import main

V = np.geomspace(0.1, 5.0, 40)


def _status(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's own refusals (exit 2)
        return int(exc.code)


def _write(path, rows, header="v,f,sigma") -> str:
    path.write_text(header + "\n" + "".join(",".join(repr(float(x)) for x in r) + "\n" for r in rows))
    return str(path)


def test_cli_fit_weighted_by_sigma_column(tmp_path, capsys):
    """A sigma column weights the fit: the CLI's coefficients, standard errors and chi^2 equal
    ``PeelForce.fit(v, f, "cubic", sigma=s)``'s to 1e-9 (the same function on the same numbers; unweighted they
    differ: the issue's 240.57 against 238.82), and are printed (fit_stderr_*, fit_chi2, fit_dof)."""
    f0 = PeelForce.cubic().f(V, 1.0)
    sd = 0.01 * f0
    f = f0 + sd * np.random.default_rng(5).standard_normal(V.size)
    path = _write(tmp_path / "pts.csv", zip(V, f, sd))
    assert main(["folds", "--V", "1", "--force-fit", path, "--family", "cubic", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    fr = PeelForce.fit(V, f, "cubic", sigma=sd).fit_result
    assert row["fit_weighted"] is True
    assert row["fit_chi2"] == pytest.approx(fr.chi2, rel=1e-9) and row["fit_dof"] == fr.dof == 36
    for n in fr.names:
        assert row[f"fit_stderr_{n}"] == pytest.approx(fr.stderr[n], rel=1e-9)
    assert row["fit_stderr_f_min"] == pytest.approx(fr.folds.stderr["f_min"], rel=1e-9)
    assert row["f_min"] == pytest.approx(fr.folds.values["f_min"], rel=1e-12)
    unweighted = PeelForce.fit(V, f, "cubic").fit_result.folds.values["f_min"]
    assert abs(unweighted - row["f_min"]) > 1e-6  # the weights matter
    # without a sigma column: unweighted, said so
    path2 = _write(tmp_path / "pts2.csv", zip(V, f), header="v,f")
    assert main(["folds", "--V", "1", "--force-fit", path2, "--family", "cubic", "--format", "json"]) == 0
    row2 = json.loads(capsys.readouterr().out)
    assert row2["fit_weighted"] is False and row2["f_min"] == pytest.approx(unweighted, rel=1e-12)


def test_flat_points_have_no_significant_n_shape(tmp_path, capsys):
    """Flat points (f = 200 N exactly, and 200 N with 1 N of noise) fitted by the cubic: FitResult.folds is None
    with a note "no significant N shape", the law's ``folds`` raise a ValueError saying so (the issue: folds from
    coefficients of 1e-16 were reported), and the CLI exits 2 with that message.  A noisy N-shaped cubic keeps its
    folds (depth 56 N, standard error ~1 N)."""
    for f in (np.full(40, 200.0), 200.0 + np.random.default_rng(0).standard_normal(40)):
        law = PeelForce.fit(V, f, "cubic")
        assert law.fit_result.folds is None and law.fit_result.folds_note.startswith("no significant N shape")
        with pytest.raises(ValueError, match="without a significant N shape"):
            law.folds(1.0)
    path = _write(tmp_path / "flat.csv", zip(V, np.full(40, 200.0)), header="v,f")
    assert _status(["folds", "--V", "1", "--force-fit", path, "--family", "cubic"]) == 2
    assert "significant N shape" in capsys.readouterr().err
    good = PeelForce.fit(V, PeelForce.cubic().f(V, 1.0) * (1 + 0.01 * np.random.default_rng(1).standard_normal(40)),
                         "cubic")
    assert good.fit_result.folds is not None and good.folds(1.0).has_folds


def test_sigma_column_bad_values_named(tmp_path, capsys):
    """A sigma <= 0 in the file is refused, naming sigma and the index (exit 2)."""
    f = PeelForce.cubic().f(V, 1.0)
    sd = np.full(40, 1.0)
    sd[3] = 0.0
    path = _write(tmp_path / "bad.csv", zip(V, f, sd))
    assert _status(["folds", "--V", "1", "--force-fit", path, "--family", "cubic"]) == 2
    assert "sigma" in capsys.readouterr().err
