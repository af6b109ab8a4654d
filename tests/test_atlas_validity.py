"""The validity table's generator (``python -m comparisons.atlas.validity``): the table of
peelapprox/_reduced/_validity.py is
what the generator writes from docs/atlas/approx_grid_regimes.csv, and a new atlas's rows go into it unchanged."""

from __future__ import annotations

import csv
import importlib.util
from pathlib import Path

import pytest

from comparisons.atlas import validity

ROOT = Path(__file__).resolve().parents[1]


def test_the_committed_table_is_the_generators_output():
    """Hypothesis: regenerating peelapprox/_reduced/_validity.py from docs/atlas/approx_grid_regimes.csv changes
    nothing (the table was generated, not edited).  Exact text equality: the generator writes ``repr`` of the
    CSV's floats."""
    assert validity.regenerate(ROOT / "docs" / "atlas" / "approx_grid_regimes.csv") == validity.TARGET.read_text()
    assert validity.main(["--from", str(ROOT / "docs" / "atlas" / "approx_grid_regimes.csv"), "--check"]) == 0


def test_a_new_atlas_rewrites_the_table_and_the_source(tmp_path):
    """Hypothesis: rows of a new atlas (every approx:default fraction halved, one point count changed) appear in the
    rewritten module as the same floats (exact: ``repr`` round-trips), the rest of the file unchanged, ``--source``
    replaces SOURCE, and ``--check`` then reports the committed module as out of date (exit 1)."""
    src = ROOT / "docs" / "atlas" / "approx_grid_regimes.csv"
    rows = list(csv.DictReader(open(src, newline="")))
    for r in rows:
        if r["approximation"] == "approx:default" and r["fraction"]:
            r["fraction"] = repr(float(r["fraction"]) / 2)
            r["stick_slip"] = str(int(r["stick_slip"]) + 1)
    new = tmp_path / "atlas_regimes.csv"
    with open(new, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    target = tmp_path / "_validity.py"
    target.write_text(validity.TARGET.read_text())
    assert validity.main(["--from", str(new), "--target", str(target), "--source", "a test atlas"]) == 0
    spec = importlib.util.spec_from_file_location("generated_validity", target)  # the rewritten module, imported
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    table = validity.read_validity(new)
    assert {k: tuple(v) for k, v in mod.VALIDITY.items()} == table
    assert mod.SOURCE == "a test atlas"
    old = validity.read_validity(src)
    assert all(table[k][0] == old[k][0] + 1 and table[k][1] == old[k][1] / 2 for k in old)
    assert validity.main(["--from", str(new), "--check"]) == 1


def test_a_file_without_the_rows_is_a_named_error(tmp_path):
    """Hypothesis: a CSV without approx:default rows is a ValueError naming ``path`` (exit status 2 from the CLI)."""
    bad = tmp_path / "atlas_regimes.csv"
    bad.write_text("approximation,regime,observable,stick_slip,compared,within,fraction\n")
    with pytest.raises(ValueError, match="path"):
        validity.read_validity(bad)
    assert validity.main(["--from", str(bad), "--check"]) == 2
