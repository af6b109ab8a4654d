"""Sphinx configuration of the peelapprox documentation site.

Build (warnings are errors): ``pip install -e ".[docs]" && python -m sphinx -W --keep-going -b html docs
docs/_build/html``; check it in a headless browser: ``python docs/check_site.py docs/_build/html``.

Why Sphinx: the docstrings are numpydoc, native to Sphinx through the numpydoc extension;
autosummary writes one page per public name from each public module's ``__all__`` (``docs/api/``, checked
complete by ``tests/test_docs_api.py``); myst-parser reads the existing markdown chapters as they are.
mkdocstrings' numpy style renders fewer numpydoc sections.  MathJax is served from the site itself
(``sphinx-mathjax-offline`` ships MathJax 3 and copies it into ``_static``): the pages render their math
without internet.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # document this checkout, whatever peelapprox is installed

import peelapprox  # noqa: E402

project = "peelapprox"
author = "peelapprox developers"
copyright = "peelapprox developers"  # noqa: A001 - Sphinx's name
release = peelapprox.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 vendored into _static/mathjax: no CDN
    "numpydoc",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "sweep"]
templates_path = ["_templates"]

# markdown chapters: $...$ / $$...$$ math, heading anchors for the in-page links
myst_enable_extensions = ["dollarmath", "amsmath", "deflist"]
myst_heading_anchors = 3
myst_dmath_double_inline = True
suppress_warnings = ["myst.header"]  # a few chapters open with a level-2 heading under their title

# API reference: one page per public name (docs/api/*.rst list them; autosummary writes docs/api/generated/)
autosummary_generate = True
autosummary_imported_members = True  # the packages re-export names defined in private modules
autosummary_ignore_module_all = False  # a module listed as a name (peelapprox.kernels.status): its __all__
autodoc_default_options = {"members": False}
autodoc_typehints = "none"  # the signature shows the hints; numpydoc's Parameters section describes them
autodoc_member_order = "bysource"
numpydoc_show_class_members = False  # the class template lists the members itself
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = False
numpydoc_validation_checks: set[str] = set()



def _constant_docs() -> dict[str, str]:
    """The ``#:`` description of each re-exported public constant, from the module that defines it.

    autodoc looks for a constant's ``#:`` comment in the module it documents the constant under
    (``peelapprox`` for ``peelapprox.PARAM_RANGES``), but the comment is where the constant is written
    (``peelapprox._ranges``; ``peelapprox.MEASURES`` in ``comparisons.sweep.measures``).  Find that module: a
    module of the three packages whose attribute of that name is this very object and carries a ``#:``
    comment.  The API pages' template adds the text (``_templates/autosummary/base.rst``).
    """
    import importlib
    import inspect

    from sphinx.pycode import ModuleAnalyzer

    def attr_docs(modname: str) -> dict:
        try:
            return ModuleAnalyzer.for_module(modname).find_attr_docs()
        except Exception:  # noqa: BLE001 - no source to read (an alias module): nothing to offer
            return {}

    docs = {}
    for page in sorted((ROOT / "docs" / "api").glob("*.rst")):
        if page.stem == "index":
            continue
        module = importlib.import_module(page.stem)
        own = attr_docs(page.stem)
        for name in module.__all__:
            obj = getattr(module, name)
            if inspect.isclass(obj) or inspect.ismodule(obj) or callable(obj) or ("", name) in own:
                continue
            for modname in sorted(m for m in sys.modules if m.split(".")[0] in ("peelapprox", "exact", "comparisons")):
                if getattr(sys.modules[modname], name, None) is obj and ("", name) in (found := attr_docs(modname)):
                    docs[f"{page.stem}.{name}"] = "\n".join(found[("", name)]).strip()
                    break
    return docs


autosummary_context = {"constant_docs": _constant_docs()}

html_theme = "pydata_sphinx_theme"
html_title = f"peelapprox {release}"
html_static_path = ["_static"]
html_css_files = ["peelapprox.css"]
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": [],
}
html_show_sourcelink = False


def _reexport_targets() -> dict[str, str]:
    """``{"peelapprox.periodic_orbit": "exact.periodic_orbit", ...}``: each name an API page lists as a
    pointer (``~home.name`` in an autosummary list without ``:toctree:``) -> the one page it points to."""
    import re

    targets = {}
    for page in sorted((ROOT / "docs" / "api").glob("*.rst")):
        for home_name in re.findall(r"^   ~([\w.]+)$", page.read_text(encoding="utf-8"), re.M):
            targets[f"{page.stem}.{home_name.rpartition('.')[2]}"] = home_name
    return targets


def setup(app):
    """Resolve a re-export's name to its home's page, and let one module's two names of a class each have one.

    A name offered by several modules has one page, in its home module (``docs/api/*.rst``; a cross-reference
    to ``peelapprox.periodic_orbit`` or ``peelapprox.SolverFailure`` in a docstring finds no page of that name:
    it is sent to the home's, ``exact.periodic_orbit``'s).  autodoc marks each page's entry with the object's
    canonical (defining) name, so a module's alias of its own class (``peelapprox.Folds`` of
    ``peelapprox.BranchStructure``, canonical ``peelapprox.law._folds.BranchStructure``) would be reported as a
    second description of one canonical name: two names of one object are not a duplicate, keep the first.
    Real duplicates (two entries of one documented name) still warn.
    """
    from sphinx.domains.python import PythonDomain

    class Python(PythonDomain):
        def note_object(self, name, objtype, node_id, aliased=False, location=None):  # type: ignore[override]
            other = self.objects.get(name)
            if aliased and other is not None and other.aliased:
                return
            super().note_object(name, objtype, node_id, aliased=aliased, location=location)

    app.add_domain(Python, override=True)
    targets = _reexport_targets()

    def to_home(app, env, node, contnode):
        home = targets.get(node.get("reftarget", "")) if node.get("refdomain") == "py" else None
        if home is None:
            return None
        node["reftarget"] = home
        return env.domains["py"].resolve_xref(env, node["refdoc"], app.builder, node["reftype"], home, node,
                                              contnode)

    app.connect("missing-reference", to_home)
