"""Packaging: the licence file matches the declared SPDX licence, the citation file names the
paper and the library, and the DOP853 coefficients are the package's own (no import of scipy's private module),
equal bitwise to scipy's where scipy still has them."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    tomllib = pytest.importorskip("tomli")


def _project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def test_license_is_an_spdx_string_matching_the_license_file():
    """Hypothesis: ``license`` is the SPDX string (PEP 639; the table form is deprecated), ``license-files`` names
    files that exist, and the first of them is that licence's text (its title and its three clauses; exact
    string checks)."""
    project = _project()
    assert project["license"] == "BSD-3-Clause"
    files = project["license-files"]
    assert files and all((ROOT / f).is_file() for f in files)
    text = (ROOT / files[0]).read_text()
    assert text.startswith("BSD 3-Clause License\n")
    assert "Neither the name of the copyright holder nor the names of its" in text
    assert "SciPy Developers" in text  # the copied DOP853 tableau keeps scipy's notice


def test_citation_file_names_the_paper_and_the_library():
    """Hypothesis: CITATION.cff is valid YAML of CFF 1.2.0 for the software (its licence that of pyproject.toml)
    with the paper as preferred citation: its title and three authors as printed in the paper's TeX, the journal,
    volume, article number and year as the citing literature gives them (Phys. Rev. E 70, 046223 (2004); the
    TeX carries no journal reference), exact strings."""
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software" and cff["title"].startswith("peelapprox")
    assert cff["license"] == _project()["license"]
    paper = cff["preferred-citation"]
    assert paper["title"] == "Dynamics of stick-slip in peeling of an adhesive tape"
    assert [a["family-names"] for a in paper["authors"]] == ["De", "Maybhate", "Ananthakrishna"]
    assert (paper["journal"], paper["volume"], paper["start"], paper["year"]) == ("Physical Review E", 70, "046223",
                                                                                2004)


def test_no_module_imports_scipys_private_dop853_coefficients():
    """Hypothesis: no source file of the three packages imports ``scipy.integrate._ivp`` (exact: text search)."""
    pattern = re.compile(r"^\s*(from|import)\s+scipy\.integrate\._ivp", re.M)
    offenders = [str(p.relative_to(ROOT)) for pkg in ("peelapprox", "exact", "comparisons")
                 for p in (ROOT / pkg).rglob("*.py") if pattern.search(p.read_text())]
    assert offenders == []


def test_dop853_tableau_equals_scipys_bitwise():
    """Hypothesis: the package's copy of the tableau is scipy's, bit for bit (``tobytes`` equality, dtype and shape),
    wherever the installed scipy still has the private module it was copied from; the integrator uses the copy."""
    ref = pytest.importorskip("scipy.integrate._ivp.dop853_coefficients")
    from peelapprox._compiled import _dop853
    from peelapprox._compiled import _dop853_tableau as ours

    for name in ("N_STAGES", "N_STAGES_EXTENDED", "INTERPOLATOR_POWER"):
        assert getattr(ours, name) == getattr(ref, name)
    for name in ("C", "A", "B", "E3", "E5", "D"):
        a, b = getattr(ours, name), getattr(ref, name)
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), name
    assert np.array_equal(_dop853._A, ours.A[: ours.N_STAGES, : ours.N_STAGES])
