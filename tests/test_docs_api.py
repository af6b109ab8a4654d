"""The documentation site's API reference lists every public name, and gives every public object one page.

``docs/api/<module>.rst`` holds one page per public module.  Its ``autosummary`` lists with ``:toctree:`` are
what Sphinx turns into one page per name (a *page entry*); a list without ``:toctree:`` names objects another
module documents (a *pointer*: ``~exact.periodic_orbit`` on ``peelapprox``'s page, a table row linking to the
one page of ``exact.periodic_orbit``).  A name offered by several modules (``peelapprox`` re-exports the
dynamics from :mod:`exact`, the sweep from :mod:`comparisons.sweep`, the exceptions from
:mod:`peelapprox.errors`) is the same object under each, documented once, in its home module.  These tests
read those sources (no Sphinx needed): a new public name, or a new public module in ``tests/test_api.py``'s
``API``, fails here until it has its entry.  That the listed entries render, with zero warnings, is the docs
build's job (``python -m sphinx -W``), and that a reader sees them, ``docs/check_site.py``'s.
"""

from __future__ import annotations

import importlib
import importlib.util
import itertools
import re
from collections import defaultdict
from pathlib import Path
from typing import NamedTuple

import pytest
from test_api import API

import peelapprox

DOCS = Path(__file__).resolve().parents[1] / "docs"


class Entry(NamedTuple):
    """One autosummary line: the name it offers, and the module of the page that documents it (``None``
    when the entry is itself that page, i.e. listed under ``:toctree:``)."""

    name: str
    home: str | None


def _autosummary(path: Path) -> list[Entry]:
    """The entries of every ``.. autosummary::`` directive of an .rst file (options skipped).

    A ``:toctree:`` list's entries are pages; a list without it holds pointers ``~home.module.name``.
    """
    entries: list[Entry] = []
    inside = pages = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith(".. autosummary::"):
            inside, pages = True, False
            continue
        if inside:
            if line and not line[0].isspace():
                inside = False
            elif line.strip() == ":toctree: generated":
                pages = True
            elif line.strip() and not line.strip().startswith(":"):
                target = line.strip().removeprefix("~")
                home, _, name = target.rpartition(".")
                assert pages == (not home), f"{path.name}: {line.strip()!r}: a page entry is a bare name, " \
                                            "a pointer (a list without :toctree:) a full dotted one"
                entries.append(Entry(name, home or None))
    return entries


def _autosummary_entries(path: Path) -> list[str]:
    """The names an API page lists, page entries and pointers alike."""
    return [e.name for e in _autosummary(path)]


def _pages() -> dict[str, list[Entry]]:
    return {module: _autosummary(DOCS / "api" / f"{module}.rst") for module in sorted(API)}


def _identity(name: str, obj: object) -> object:
    """What makes two public names one object: identity, except for plain values, which are one constant
    when both name and value agree (``MAX_BASIN_STARTS`` and ``MAX_SWEEP_POINTS`` are both 1000000, by
    coincidence: two constants, two pages)."""
    return ("value", name, repr(obj)) if isinstance(obj, (int, float, str, bytes, type(None))) else id(obj)


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


def test_every_public_object_has_one_page():
    """Hypothesis: across all API pages, each public object (by identity) has its page entry in exactly one
    module, and every other module that offers it lists a pointer to that page, not a page of its own
    (categorical: two pages for ``peelapprox.periodic_orbit`` and ``exact.periodic_orbit`` is the duplicate
    issue 29 reports).  Two names of one object within one module (``Folds``, another name of
    ``BranchStructure``) are that module's own alias and keep a page each."""
    homes: dict[object, set[str]] = defaultdict(set)
    for module, entries in _pages().items():
        mod = importlib.import_module(module)
        for e in entries:
            if e.home is None:
                homes[_identity(e.name, getattr(mod, e.name))].add(module)
    twice = {k: sorted(v) for k, v in homes.items() if len(v) > 1}
    assert not twice, f"objects with a page in several modules (keep one, point from the others): {twice}"
    for module, entries in _pages().items():
        mod = importlib.import_module(module)
        for e in entries:
            if e.home is not None:
                assert e.home in API and e.home != module, f"{module}: pointer {e} to a non-public or own module"
                pages = homes[_identity(e.name, getattr(mod, e.name))]
                assert pages == {e.home}, f"{module}.{e.name}: its pointer names {e.home}, its page is in {pages}"


@pytest.mark.parametrize("module,name,home", [(m, e.name, e.home) for m, entries in _pages().items()
                                              for e in entries if e.home is not None])
def test_each_reexport_is_its_homes_object(module, name, home):
    """Hypothesis: a name a page points elsewhere for is the home module's very object (``is``, not equal:
    ``peelapprox.periodic_orbit is exact.periodic_orbit``, ``peelapprox.MEASURES is
    comparisons.sweep.MEASURES``), so the one page documents exactly what the re-export gives; and the home
    of a class or function is, among the modules that offer it, the one nearest the module that defines it
    (the longest common dotted prefix with ``obj.__module__``)."""
    obj = getattr(importlib.import_module(module), name)
    assert obj is getattr(importlib.import_module(home), name)
    defined = getattr(obj, "__module__", None)
    if isinstance(defined, str) and (callable(obj) or isinstance(obj, type)):
        def shared(m: str) -> int:
            return len(list(itertools.takewhile(lambda ab: ab[0] == ab[1], zip(m.split("."), defined.split(".")))))
        offering = [m for m in API if name in importlib.import_module(m).__all__
                    and getattr(importlib.import_module(m), name) is obj]
        assert shared(home) == max(shared(m) for m in offering), (home, defined, offering)


@pytest.mark.parametrize("name", sorted(peelapprox._LAZY))
def test_every_lazy_reexport_of_peelapprox_points_at_its_defining_module(name):
    """Hypothesis: each name ``peelapprox`` imports lazily (``peelapprox._LAZY``: the dynamics from exact,
    the sweep from comparisons.sweep) is on ``peelapprox``'s page as a pointer to that very module, and is
    that module's object (``peelapprox.periodic_orbit is exact.periodic_orbit``; categorical)."""
    home = peelapprox._LAZY[name]
    assert Entry(name, home) in _autosummary(DOCS / "api" / "peelapprox.rst")
    assert Entry(name, None) in _autosummary(DOCS / "api" / f"{home}.rst")
    assert getattr(peelapprox, name) is getattr(importlib.import_module(home), name)


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


def _private_citations(line: str) -> list[str]:
    """The code spans of a markdown line that cite a private dotted name (``exact._hybrid._rhs``,
    ``_generated.slow_rates(...)``): a dotted name (before any call parentheses) with a part that starts with
    one underscore.  A file (``peelapprox/_compiled/_symbolic.py``), a dunder (``__main__``) or a command (``python -m
    peelapprox._compiled._symbolic``) is not one."""
    found = []
    for span in re.findall(r"`([^`]+)`", line):
        name = re.match(r"[\w.]+", span)
        if name is None or span.startswith("python -m ") or name.group(0).endswith(".py"):
            continue
        parts = name.group(0).split(".")
        if len(parts) > 1 and any(p.startswith("_") and not p.startswith("__") for p in parts):
            found.append(span)
    return found


def test_chapters_cite_no_private_dotted_name():
    """Hypothesis: no markdown chapter (docs/**/*.md, README.md) cites code by a private dotted name
    (``exact._hybrid._rhs``), which reads like an import path but is no API; internals are cited as a source
    file (``_rhs`` in ``exact/_hybrid.py``; CONTRIBUTING.md, "Docs cite what a reader can use").  Categorical:
    the count of such citations is 0."""
    assert _private_citations("`exact._hybrid._rhs` and `_generated.slow_rates(x)`") == \
        ["exact._hybrid._rhs", "_generated.slow_rates(x)"]
    assert _private_citations("`peelapprox/_compiled/_symbolic.py`, `_generated.py`, `python -m peelapprox._compiled._symbolic`, "  # noqa: E501
                              "`__main__`, `peelapprox.kernels.diffsl_code(tangent=True)`") == []
    found = []
    for path in [DOCS.parent / "README.md", *sorted(DOCS.rglob("*.md"))]:
        if "_build" in path.parts:
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            found += [f"{path.relative_to(DOCS.parent)}:{n}: {span}" for span in _private_citations(line)]
    assert not found, found
