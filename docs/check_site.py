"""Open the built documentation site in headless Chromium and check what a reader sees.

Usage::

    python docs/check_site.py docs/_build/html [--screenshot DIR] [--chromium /usr/bin/chromium]

Serves the site on localhost and opens every chapter, the API index and each public module's API page in
a real headless Chromium (driven by playwright; Debian's ``chromium`` package, since playwright cannot
download its own browser here).  Checks, per page:

* math: every formula Sphinx emitted (``.math``) was typeset by MathJax (holds an ``mjx-container``), no raw
  TeX delimiters (``$$``, ``\\(``, ``\\[``) are left in the text outside code, and the pages in
  ``MATH_PAGES`` have formulas at all;
* images: every ``<img>`` loaded (``complete`` and ``naturalWidth > 0``);
* the site is whole and self-contained: every file a page asks for is served (no 404; the browser's own
  ``/favicon.ico`` aside), no request leaves localhost (MathJax is served from ``_static``), and no
  JavaScript error was thrown;
* API reference: each public module's page links every name of its ``__all__`` to an existing page;
* layout, at the 1280 px wide window every page is opened in: the code blocks of the pages in
  ``NO_SCROLL_PAGES`` fit their column (no ``<pre>`` with ``scrollWidth > clientWidth``: a reader of the landing
  page does not scroll sideways), the left column's site navigation links every chapter of the landing page
  (every page but the landing page itself and the generated API pages) and the right column's page contents
  list the sections of the pages in ``TOC_PAGES``.

Prints one line per page and a summary; exits 1 on any failure.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import importlib
import shutil
import sys
import threading
from pathlib import Path
from urllib.parse import urlparse

#: The public modules with an API page (docs/api/<module>.rst); tests/test_docs_api.py keeps it complete.
API_MODULES = (
    "peelapprox", "exact", "comparisons", "peelapprox.plotting", "peelapprox.io", "peelapprox.parallel",
    "peelapprox.validate",
    "peelapprox.errors", "peelapprox.kernels", "peelapprox.cli", "comparisons.atlas", "comparisons.front", "comparisons.sweep",
    "comparisons.stress", "comparisons.benchmark", "comparisons.benchmark.peers",
)
#: Pages that must hold typeset formulas (the landing page states the model's equations; the theory page maps
#: the paper's equations to the code).
MATH_PAGES = ("index.html", "theory.html")
#: Pages whose code blocks must fit the content column at 1280 px (no sideways scrolling).
NO_SCROLL_PAGES = ("index.html",)
#: Pages whose right column ("On this page") must list their sections, at least this many links.
TOC_PAGES = {"theory.html": 10}
#: Chromium's switches for a quiet, offline, sandbox-free headless run.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]

# In the page: wait for MathJax's first typesetting pass (if the page loads MathJax), then report.
_PROBE = """async () => {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) { await MathJax.startup.promise; }
  const imgs = Array.from(document.images);
  for (const img of imgs) { img.loading = 'eager'; }
  await Promise.all(imgs.map(img => img.decode().catch(() => null)));
  const math = Array.from(document.querySelectorAll('.math'));
  const body = document.querySelector('article') || document.body;
  const text = body.cloneNode(true);
  text.querySelectorAll('pre, code, script, style, mjx-container').forEach(e => e.remove());
  return {
    mathjax: !!window.MathJax,
    math: math.length,
    typeset: math.filter(e => e.querySelector('mjx-container')).length,
    containers: document.querySelectorAll('mjx-container').length,
    raw: ['$$', '\\\\(', '\\\\['].filter(d => text.textContent.includes(d)),
    images: imgs.length,
    broken: imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.getAttribute('src')),
    links: Array.from(document.querySelectorAll('table.autosummary a.reference.internal'))
                .map(a => [a.textContent.trim(), a.getAttribute('href')]),
    scrolling: Array.from(document.querySelectorAll('article pre'))
                .filter(p => p.scrollWidth > p.clientWidth)
                .map(p => `${p.scrollWidth} > ${p.clientWidth} px: ${p.textContent.split('\\n')[0].slice(0, 50)}`),
    nav: [...new Set(Array.from(document.querySelectorAll('.bd-sidebar-primary nav.bd-docs-nav a.reference'))
                .filter(a => a.offsetParent !== null).map(a => a.href.split('#')[0]))],
    toc: Array.from(document.querySelectorAll('.bd-sidebar-secondary nav.page-toc a.nav-link')).length,
  };
}"""


def _pages(site: Path) -> list[str]:
    """The chapters (top-level pages and one level down), the API index and the module pages."""
    pages = sorted(p.relative_to(site).as_posix() for p in site.glob("*.html")
                   if p.name not in ("genindex.html", "search.html", "py-modindex.html"))
    pages += sorted(p.relative_to(site).as_posix() for p in site.glob("*/*.html")
                    if p.parent.name not in ("_static", "_sources", "_modules"))
    return pages


def _chapters(site: Path) -> set[str]:
    """The pages the landing page's toctrees list (its ``toctree-wrapper`` blocks), as paths in the site."""
    import re

    html = (site / "index.html").read_text(encoding="utf-8")
    blocks = re.findall(r'<div class="toctree-wrapper compound">(.*?)</div>', html, re.S)
    links = (re.findall(r'<li class="toctree-l1"><a[^>]*href="([^"]+)"', b) for b in blocks)
    return {href.split("#")[0] for hrefs in links for href in hrefs}


def _serve(site: Path) -> http.server.ThreadingHTTPServer:
    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args: object) -> None:
            pass

    handler = functools.partial(Quiet, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def check(site: Path, *, chromium: str, screenshot: Path | None = None) -> list[str]:
    """Check the site; return the failures (empty when it passes)."""
    from playwright.sync_api import sync_playwright

    failures: list[str] = []
    pages = _pages(site)
    for required in ("index.html", "theory.html", "api/index.html", *MATH_PAGES,
                     *(f"api/{m}.html" for m in API_MODULES)):
        if required not in pages:
            failures.append(f"{required}: not built")
    server = _serve(site)
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    external: list[str] = []
    errors: list[str] = []
    missing: list[str] = []

    def route(r) -> None:  # noqa: ANN001 - playwright's Route
        if urlparse(r.request.url).hostname in ("127.0.0.1", "localhost"):
            r.continue_()
        else:
            external.append(r.request.url)
            r.abort()

    totals = {"pages": 0, "math": 0, "images": 0}
    chapters = _chapters(site)
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        page.route("**/*", route)
        page.on("pageerror", lambda e: errors.append(f"{page.url}: {e}"))
        page.on("response", lambda r: missing.append(f"{r.status} {r.url}")
                if r.status >= 400 and urlparse(r.url).path != "/favicon.ico" else None)
        for name in pages:
            page.goto(base + name, wait_until="load")
            r = page.evaluate(_PROBE)
            totals["pages"] += 1
            totals["math"] += r["typeset"]
            totals["images"] += r["images"] - len(r["broken"])
            bad = []
            if r["math"] and not r["mathjax"]:
                bad.append("MathJax not loaded")
            if r["typeset"] != r["math"]:
                bad.append(f"{r['math'] - r['typeset']} of {r['math']} formulas not typeset")
            if r["raw"]:
                bad.append(f"raw TeX delimiters {r['raw']}")
            if name in MATH_PAGES and r["typeset"] == 0:
                bad.append("no typeset formula")
            if r["broken"]:
                bad.append(f"images not loaded: {r['broken']}")
            if name in NO_SCROLL_PAGES and r["scrolling"]:
                bad.append(f"code blocks wider than their column at 1280 px: {r['scrolling']}")
            unlisted = chapters - {urlparse(h).path.lstrip("/") for h in r["nav"]}
            if name != "index.html" and not name.startswith("api/generated/") and unlisted:
                bad.append(f"the left column's navigation lacks the chapters {sorted(unlisted)}")
            if name in TOC_PAGES and r["toc"] < TOC_PAGES[name]:
                bad.append(f"the right column lists {r['toc']} sections (at least {TOC_PAGES[name]} expected)")
            module = name.removeprefix("api/").removesuffix(".html")
            if name.startswith("api/") and module in API_MODULES:
                bad += _check_api(site, name, module, r["links"])
            print(f"{'FAIL' if bad else 'ok  '} {name}: {r['typeset']}/{r['math']} formulas typeset "
                  f"({r['containers']} mjx-container), {r['images'] - len(r['broken'])}/{r['images']} images"
                  + (f", {len(r['links'])} API entries" if r["links"] else "") + ("; " + "; ".join(bad) if bad else ""))
            failures += [f"{name}: {b}" for b in bad]
            if screenshot is not None and name in ("theory.html", "index.html"):
                screenshot.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=str(screenshot / name.replace(".html", ".png")))
        browser.close()
    server.shutdown()
    failures += [f"request outside localhost: {u}" for u in sorted(set(external))]
    failures += [f"JavaScript error: {e}" for e in errors]
    failures += [f"not served: {m}" for m in sorted(set(missing))]
    print(f"{totals['pages']} pages, {totals['math']} formulas typeset, {totals['images']} images loaded, "
          f"{len(set(missing))} files not served, {len(set(external))} external requests, "
          f"{len(errors)} JavaScript errors: "
          + ("PASS" if not failures else f"FAIL ({len(failures)})"))
    return failures


def _check_api(site: Path, name: str, module: str, links: list[list[str]]) -> list[str]:
    """Every name of the module's ``__all__`` is an entry of its page, linked to a page that exists."""
    listed = {}
    for text, href in links:
        listed[text] = href
    names = importlib.import_module(module).__all__
    bad = []
    missing = [n for n in names if n not in listed]
    if missing:
        bad.append(f"public names without an entry: {missing}")
    for n in names:
        href = listed.get(n)
        if href is not None and not (site / Path(name).parent / href.split("#")[0]).is_file():
            bad.append(f"{n}: its page {href} is missing")
    return bad


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("site", type=Path, help="the built HTML site (docs/_build/html)")
    parser.add_argument("--screenshot", type=Path, default=None,
                        help="directory for screenshots of the landing and theory pages (PNG)")
    parser.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium",
                        help="the Chromium executable (default: chromium on PATH, else /usr/bin/chromium)")
    args = parser.parse_args(argv)
    if not (args.site / "index.html").is_file():
        parser.error(f"site: no index.html in {args.site}; build it first")
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout the site documents
    failures = check(args.site, chromium=args.chromium, screenshot=args.screenshot)
    for f in failures:
        print("FAIL", f, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
