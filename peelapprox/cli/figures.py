"""``peelapprox figures``: the paper's Figs. 2-9 from our exact solutions (:func:`comparisons.make_figures`)."""

from __future__ import annotations

import argparse
import os
import sys

from ._checks import check_output_path
from ._common import say

__all__ = ["add_parser", "run"]


def add_parser(sub) -> argparse.ArgumentParser:
    fg = sub.add_parser("figures", help="the paper's Figs. 2-9 from our exact solutions")
    fg.add_argument("--only", action="append", metavar="NAME", help="draw only this figure (repeatable): fig2 … fig9")
    fg.add_argument("--out", default="docs/figures", help="output directory (docs/figures)")
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
