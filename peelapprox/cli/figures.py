"""``peelapprox figures``: the paper's Figs. 2-9 from our exact solutions (:func:`comparisons.make_figures`)."""

from __future__ import annotations

import argparse
import os
import sys

from ._checks import check_output_path
from ._common import say, subcommand

__all__ = ["DEFAULT_OUT", "add_parser", "run"]

#: Where ``peelapprox figures`` writes without ``--out``: a directory of its own in the working directory (never
#: into a ``docs/`` that happens to be there).
DEFAULT_OUT = "peelapprox-figures"


def add_parser(sub) -> argparse.ArgumentParser:
    fg = subcommand(
        sub, "figures", help="the paper's Figs. 2-9 from our exact solutions",
        description="The paper's Figs. 2-9 redrawn from our exact solutions (Fig. 2: f(v, V); 3-5 and 7: orbits in "
                    "time and in the v-F plane; 6: mean force drops against V; 8-9: the approximate-vs-exact "
                    "overlays of compare), as PNG files, with a captioned markdown page on request.  All of them "
                    "take ~12 s with the kernels compiled (measured on 2 cores).",
        examples=["peelapprox figures --list",
                  f"peelapprox figures --only fig4                        # into ./{DEFAULT_OUT}/",
                  "peelapprox figures --out docs/figures --markdown docs/figures.md   # regenerates the repository's "
                  "page"])
    fg.add_argument("--only", action="append", metavar="NAME",
                    help="draw only this figure (repeatable; default: all): fig2, fig3, ..., fig9 (see --list)")
    fg.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help="output directory (created)")
    fg.add_argument("--markdown", metavar="PATH", help="also write the captioned page, e.g. docs/figures.md")
    fg.add_argument("--list", action="store_true", help="list the figures and exit")
    return fg


def run(args: argparse.Namespace) -> int:
    from comparisons import FIGURES, figures_markdown, make_figures

    if args.list:
        for name, fig in FIGURES.items():
            print(f"{name}: {fig.caption}  [{fig.params}]")
        return 0
    check_output_path(args.out, "dir", "--out")
    markdown = check_output_path(args.markdown, "file", "--markdown") if args.markdown else None
    files = make_figures(args.only, args.out, progress=say)
    for name, paths in files.items():
        print(f"{name}: {', '.join(paths)}")
    if markdown:
        rel = os.path.relpath(args.out, os.path.dirname(os.path.abspath(markdown)) or ".")
        with open(markdown, "w") as fh:
            fh.write(figures_markdown(files, rel=rel))
        print(f"wrote {markdown}", file=sys.stderr)
    return 0
