"""``peelapprox atlas``: where the approximations hold over a (V, I) grid (:func:`comparisons.atlas.atlas`)."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Callable

from .. import PeelForce
from ._checks import add_pool_options, check_output_path, nonnegative_int, positive_int, worker_pool
from ._common import FORMATS, add_grid_params, add_max_wall_option, subcommand
from ._force import add_force_options, force_from_args

__all__ = ["add_parser", "run"]


def add_parser(sub) -> argparse.ArgumentParser:
    at = subcommand(
        sub, "atlas", help="where the approximations hold: exact attractor vs every approximation over a (V, I) grid; "
                           "resumable maps and tables",
        description="At every (V, I) grid point: the exact attractor's observables (slip interval, force drop, slip "
                    "and stick times, the force range at the jumps; 100 s of transient, 20 s measured) and its class "
                    "(period n, aperiodic, steady, breakdown); every approximation's prediction of the same "
                    "observables (estimate: the quasi-static cycle of peelapprox.estimate; approx:default: "
                    "peelapprox.approximate_attractor, the reduced return map iterated to its attractor); and each "
                    "reduction of the "
                    "harness (an alpha model and a v equation per branch) seeded from the exact branch entries of the "
                    "window's last stays, with its median and worst |dt| and |dF| relative errors.  Each finished "
                    "point is appended to DIR/results.jsonl, so a killed atlas resumes where it stopped.\n\n"
                    "Writes DIR/atlas_points, atlas_errors, atlas_segments and atlas_summary (.csv and .json), and "
                    "with --plot the maps under DIR/maps/: one per approximation and observable of the relative "
                    "error with the cells within 10 % outlined, the exact dynamics with the regimes of estimate, the "
                    "reductions' median per-segment errors.  Prints the summary: per approximation and observable "
                    "the share of the exact stick-slip points predicted within 10 %.  --cost N instead times each "
                    "part at N sample points of the grid and prints the projected time, computing nothing else.",
        examples=["peelapprox atlas --V 0.2:5:8 --I 1e-6:1e-1:8:log --out atlas/ --plot   # 64 points, ~80 s",
                  "peelapprox atlas --V 0.2:5:40 --I 1e-6:1e-1:40:log --out atlas40/ --workers 2 --max-wall 900",
                  "peelapprox atlas --V 0.2:5:40 --I 1e-6:1e-1:40:log --cost 16   # the projected time first",
                  "peelapprox atlas --V 0.5:4:6 --I 1e-5:1e-2:6:log --force-family cubic --out cubic/ --plot"])
    at.add_argument("--V", required=True, metavar="SPEC",
                    help="pull speeds [m/s]: start:stop:num[:log] or a comma list, e.g. 0.2:5:40")
    at.add_argument("--I", required=True, metavar="SPEC",
                    help="roller inertias [kg m^2], same syntax, e.g. 1e-6:1e-1:40:log; the grid holds at most "
                         "1000000 points")
    at.add_argument("--out", metavar="DIR",
                    help="output directory (required unless --cost): sweep.json, results.jsonl, the atlas tables, "
                         "maps/; an existing DIR with the same grid and options is resumed")
    at.add_argument("--approximations", metavar="NAMES",
                    help="comma-separated names of comparisons.atlas.APPROXIMATIONS (default: every registered one "
                         "whose function is importable)")
    add_pool_options(at)
    w = at.add_argument_group("the exact window and the segments (left out: the default given)")
    w.add_argument("--t-transient", type=float, default=None,
                   help="transient skipped [s] (default: 100: the slowest orbits of the (0.2-5 m/s, 1e-6-0.1 kg m^2) "
                        "plane drift for ~100 s)")
    w.add_argument("--window", type=float, default=None, help="measured window [s] (default: 20)")
    w.add_argument("--rtol", type=float, default=None, help="tolerance of the exact runs (default: 1e-10)")
    w.add_argument("--alpha0", type=float, default=None, help="initial peel angle [rad] (default: 0)")
    w.add_argument("--segments", type=nonnegative_int, default=None, metavar="N",
                   help="complete stays of each branch compared per point, the last ones of the window (default: "
                        "8; 0: no segment errors)")
    w.add_argument("--segment-rtol", type=float, default=None,
                   help="tolerance of the reduced solves (default: 1e-10)")
    add_grid_params(at)
    add_force_options(at)
    st = at.add_argument_group("attractor sets (opt-in; comparisons.atlas.sets)")
    st.add_argument("--sets", action="store_true",
                    help="also compare sets: at each point the exact attractor set (exact.attractor_set, its default "
                         "starts, the same window; about 8 runs more per point) and the predicted set "
                         "(approximate_attractor's primary and alternatives); records the number of attractors, the "
                         "primary's confidence, whether it matches ANY attractor of the set (slip interval and force "
                         "drop within 10 %%) and the default start's; writes DIR/atlas_sets and atlas_set_summary, "
                         "and with --plot maps/multistability.png and maps/confidence.png")
    st.add_argument("--set-min-share", type=float, default=None, metavar="S",
                    help="with --sets: an attractor counts when reached from at least this share of the starts "
                         "(default: 0.1)")
    st.add_argument("--set-stability", action="store_true",
                    help="with --sets: also the exact multipliers and exponents (attractor_set's stability), so the "
                         "multipliers are compared where both are periodic (about twice the cost)")
    at.add_argument("--retry-failed", action="store_true",
                    help="compute again the points of DIR whose status is an error (else they count as done)")
    at.add_argument("--plot", action="store_true", help="write every map as a PNG under DIR/maps/")
    at.add_argument("--cost", type=positive_int, default=None, metavar="N",
                    help="time each part (exact run, segments, each approximation) at about N sample points of the "
                         "grid (1 to 400) in this process, within --max-wall, and print the projected time of the grid "
                         "on --workers (default 2) processes; nothing is written")
    at.add_argument("--format", choices=FORMATS, default="table",
                    help="how the summary is printed: table (markdown), csv or json")
    at.add_argument("--quiet", action="store_true", help="no per-point progress on stderr")
    add_max_wall_option(at, what="this run",
                        spent="when it is spent no point is started, the points done stay in DIR, the exit status "
                              "is 3, and the same command again resumes the rest")
    return at


#: Option -> the atlas option it sets (each only when given: a resumed atlas's options must match).
_WINDOW = {"t_transient": "t_transient", "window": "t_window", "rtol": "rtol", "alpha0": "alpha0",
           "segments": "segments_per_branch", "segment_rtol": "segment_rtol"}


def run(args: argparse.Namespace) -> int:
    from comparisons.atlas import atlas, atlas_cost
    from comparisons.atlas.cost import MAX_SAMPLE
    from comparisons.sweep import check_grid_size, parse_grid

    V_values = parse_grid(args.V, name="--V")
    I_values = parse_grid(args.I, name="--I")
    check_grid_size({"--I": I_values.size, "--V": V_values.size})
    options = {key: getattr(args, opt) for opt, key in _WINDOW.items() if getattr(args, opt) is not None}
    if (args.set_min_share is not None or args.set_stability) and not args.sets:
        raise ValueError("--set-min-share and --set-stability need --sets")
    if args.set_min_share is not None:
        options["set_min_share"] = args.set_min_share
    if args.set_stability:
        options["set_stability"] = True
    model = {key: getattr(args, key) for key in ("k", "R", "l", "geometry")}
    approximations = None if args.approximations is None else \
        [a.strip() for a in args.approximations.split(",") if a.strip()]
    force = force_from_args(args)
    if args.cost is not None:
        if force != PeelForce.paper() or args.out or args.plot or args.sets:
            raise ValueError("--cost times the paper's law and writes nothing: leave out --out, --plot, --sets and "
                             "the law options")
        if args.cost > MAX_SAMPLE:
            raise ValueError(f"--cost must be an integer in [1, {MAX_SAMPLE}] (sample points timed), got {args.cost}")
        cost = atlas_cost(I_values, V_values, sample=args.cost, workers=args.workers or 2,
                          approximations=approximations, k=args.k, R=args.R, options=options,
                          progress=not args.quiet, max_wall=args.max_wall)
        if args.format == "table":
            print(cost)
        else:
            _print_rows(cost.rows(), args.format)
        return 0
    if not args.out:
        raise ValueError("--out DIR is required (the atlas's records, tables and maps go there), unless --cost")
    check_output_path(args.out, "dir", "--out", read_only_ok=True)
    t0 = time.perf_counter()
    try:
        with worker_pool(args) as (executor, max_workers):
            result = atlas(I_values, V_values, out=args.out, approximations=approximations, force=force,
                           options=options, executor=executor, max_workers=max_workers, progress=not args.quiet,
                           retry_failed=args.retry_failed, max_wall=args.max_wall, sets=args.sets, **model)
    except RuntimeError as exc:
        print(f"peelapprox atlas: error: {exc}", file=sys.stderr)
        return 3
    print(f"atlas: {len(result.sweep.records)} points in {args.out} ({time.perf_counter() - t0:.1f} s)"
          + (f"; skipped (not importable yet): {', '.join(result.skipped)}" if result.skipped else ""),
          file=sys.stderr)
    def told(what: str) -> Callable[[int, int, str], None] | None:
        if args.quiet:
            return None
        return lambda i, n, path: print(f"atlas: {what} {i}/{n}: wrote {path}", file=sys.stderr, flush=True)

    try:
        if not args.quiet:
            print("atlas: writing the tables", file=sys.stderr, flush=True)
        result.write_tables(args.out, progress=told("table"))
        if args.plot:
            paths = result.write_maps(os.path.join(args.out, "maps"), progress=told("map"))
            print(f"wrote {len(paths)} maps in {os.path.join(args.out, 'maps')}", file=sys.stderr)
    except OSError as exc:  # e.g. a complete atlas in a read-only directory: still report it
        print(f"note: cannot write into {args.out} ({exc}); the summary is printed only", file=sys.stderr)
    _print_rows(result.summary(), args.format)
    return 1 if result.failed() else 0


def _print_rows(rows: list[dict], fmt: str) -> None:
    """``rows`` as JSON, CSV or a markdown table (floats to 4 significant digits)."""
    from ..io import fmt_number, write_csv

    if fmt == "json":
        print(json.dumps(rows, indent=2))
        return
    if fmt == "csv":
        write_csv(sys.stdout, rows)
        return
    cols = list(dict.fromkeys(k for r in rows for k in r))
    print("| " + " | ".join(cols) + " |")
    print("|" + "|".join("---" for _ in cols) + "|")
    for r in rows:
        print("| " + " | ".join(fmt_number(r.get(c), 4, missing="") for c in cols) + " |")
