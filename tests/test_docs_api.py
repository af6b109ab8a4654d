"""The documentation site's API reference lists every public name (each has a rendered entry).

``docs/api/<module>.rst`` holds one page per public module, whose ``autosummary`` lists are what Sphinx
turns into one page per name.  These tests read those sources (no Sphinx needed): a new public name, or a new
public module in ``tests/test_api.py``'s ``API``, fails here until it has its entry.  That the listed entries
render, with zero warnings, is the docs build's job (``python -m sphinx -W``), and that a reader sees them,
``docs/check_site.py``'s.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
from pathlib import Path

import pytest
from test_api import API

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _autosummary_entries(path: Path) -> list[str]:
    """The names listed under every ``.. autosummary::`` directive of an .rst file (options skipped)."""
    names: list[str] = []
    inside = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith(".. autosummary::"):
            inside = True
            continue
        if inside:
            if line and not line[0].isspace():
                inside = False
            elif line.strip() and not line.strip().startswith(":"):
                names.append(line.strip())
    return names


def _toctree_entries(path: Path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    block = text.split(".. toctree::", 1)[1]
    return [line.strip() for line in block.splitlines()[1:] if line.strip() and not line.strip().startswith(":")]


@pytest.mark.parametrize("module", sorted(API))
def test_every_public_name_has_a_reference_entry(module):
    """Hypothesis: the module's API page lists exactly the names of its ``__all__`` (set equality, each
    once): a public name without an entry, or an entry for a name no longer offered, fails."""
    page = DOCS / "api" / f"{module}.rst"
    assert page.is_file(), f"no API page for the public module {module}: add docs/api/{module}.rst"
    entries = _autosummary_entries(page)
    public = importlib.import_module(module).__all__
    missing = [n for n in public if n not in entries]
    assert not missing, f"add to an autosummary list of docs/api/{module}.rst: {missing}"
    stale = sorted(set(entries) - set(public))
    assert not stale, f"docs/api/{module}.rst lists names {module}.__all__ does not offer: {stale}"
    assert len(entries) == len(set(entries)), f"docs/api/{module}.rst lists a name twice"
    assert re.search(rf"^\.\. currentmodule:: {re.escape(module)}$", page.read_text(encoding="utf-8"), re.M)


def test_the_api_index_and_the_browser_check_know_every_public_module():
    """Hypothesis: the API index's toctree and ``docs/check_site.py``'s ``API_MODULES`` are the public
    modules of ``tests/test_api.py`` (set equality), so no module page is orphaned or left unchecked."""
    assert set(_toctree_entries(DOCS / "api" / "index.rst")) == set(API)
    spec = importlib.util.spec_from_file_location("check_site", DOCS / "check_site.py")
    assert spec is not None and spec.loader is not None
    check_site = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(check_site)  # imports playwright only when it runs
    assert set(check_site.API_MODULES) == set(API)


def test_every_chapter_is_in_the_site():
    """Hypothesis: every markdown chapter under docs/ is in a toctree of the landing page (categorical: a
    chapter left out is a page no reader finds; Sphinx -W would also stop on it)."""
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^([\w/-]+)$", index, re.M))
    chapters = {p.relative_to(DOCS).with_suffix("").as_posix() for p in DOCS.rglob("*.md")
                if "_build" not in p.parts and p.name != "index.md"}
    assert chapters <= listed, sorted(chapters - listed)
