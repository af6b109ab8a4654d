"""The import contract's bookkeeping (the contract itself is checked by ``lint-imports`` in ``.ci/run``).

import-linter's ``protected`` contracts in ``pyproject.toml`` list each package's private modules by name
(its wildcards cannot match a name prefix such as ``_*``), so a new private module would escape them
silently; these tests keep the lists equal to the modules on disk.
"""

from __future__ import annotations

import pkgutil
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    tomllib = pytest.importorskip("tomli")

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("peelapprox", "exact", "comparisons")


def _contracts() -> dict[str, dict]:
    with open(ROOT / "pyproject.toml", "rb") as fh:
        cfg = tomllib.load(fh)["tool"]["importlinter"]
    return {c["id"]: c for c in cfg["contracts"]}


def _private_modules(package: str) -> set[str]:
    """Every module of ``package`` (at any depth) whose own name starts with one underscore."""
    found = set()
    for info in pkgutil.walk_packages([str(ROOT / package)], package + "."):
        last = info.name.rsplit(".", 1)[1]
        if last.startswith("_") and not last.startswith("__"):
            found.add(info.name)
    return found


@pytest.mark.parametrize("package", PACKAGES)
def test_every_private_module_is_protected(package):
    """Hypothesis: the ``private-<package>`` contract protects exactly the package's private modules (set
    equality: a missing one would be importable from a sibling room unnoticed, an extra one is stale)."""
    c = _contracts()[f"private-{package}"]
    assert c["type"] == "protected" and c["allowed_importers"] == [package]
    assert set(c["protected_modules"]) == _private_modules(package)


def test_the_rooms_are_layered_in_the_documented_order():
    """Hypothesis: the layers contract orders the rooms comparisons > exact > peelapprox, as CONTRIBUTING.md
    and the design card state (exact list equality), and exempts only the CLI."""
    c = _contracts()["rooms"]
    assert c["type"] == "layers" and c["layers"] == ["comparisons", "exact", "peelapprox"]
    assert all(rule.startswith("peelapprox.cli") for rule in c.get("ignore_imports", []))


def test_orbits_stand_below_dynamics_and_both_rooms_are_acyclic():
    """Hypothesis: ``exact.orbits`` may not import ``exact.dynamics`` (directly or through another module), and
    the no-circle contract covers the modules inside each of exact's two sub-packages, not only exact's top
    level (exact list membership)."""
    c = _contracts()
    f = c["orbits-below-dynamics"]
    assert f["type"] == "forbidden" and f["source_modules"] == ["exact.orbits"]
    assert f["forbidden_modules"] == ["exact.dynamics"] and not f.get("allow_indirect_imports", False)
    assert {"exact", "exact.orbits", "exact.dynamics"} <= set(c["acyclic"]["ancestors"])


def test_every_package_is_installed():
    """Hypothesis: ``[tool.setuptools] packages`` lists every package on disk (each directory of the three rooms
    with an ``__init__.py``), so a wheel carries the sub-packages too (set equality)."""
    with open(ROOT / "pyproject.toml", "rb") as fh:
        listed = set(tomllib.load(fh)["tool"]["setuptools"]["packages"])
    on_disk = set(PACKAGES)
    for package in PACKAGES:
        on_disk |= {info.name for info in pkgutil.walk_packages([str(ROOT / package)], package + ".") if info.ispkg}
    assert listed == on_disk


def test_no_private_module_is_an_alias_of_another():
    """Hypothesis: no private module lives on as a compatibility alias of a moved one (the shims
    ``comparisons._benchmark``, ``_stress`` and ``_peers`` were removed in 0.3.0): no module of the three
    packages star-imports another, the form those aliases took, and the removed names stay gone (exact)."""
    aliases = []
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            if "import *" in path.read_text(encoding="utf-8"):
                aliases.append(str(path.relative_to(ROOT)))
    assert aliases == []
    gone = {"comparisons._benchmark", "comparisons._stress", "comparisons._peers"}
    assert gone.isdisjoint(_private_modules("comparisons"))
