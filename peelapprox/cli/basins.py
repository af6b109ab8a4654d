"""``peelapprox basins``: which attractor each start of a grid over (α0, F0) or (α0, ω0) reaches
(:func:`exact.basins`)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .. import WINDOW_DEFAULTS
from ..io import write_csv
from ._checks import add_pool_options, check_output_path, grid_range, nonnegative_float, positive_float
from ._common import (
    FORMATS,
    HYBRID_ONLY,
    add_max_wall_option,
    add_params,
    params_from_args,
    say,
    subcommand,
    write_table,
)

__all__ = ["add_parser", "run"]


def add_parser(sub) -> argparse.ArgumentParser:
    w = WINDOW_DEFAULTS
    sp = subcommand(
        sub, "basins", help="basins of attraction: the attractor (period and cycle, aperiodic, breakdown) each start "
                            "of an (alpha0, F0) or (alpha0, omega0) grid reaches",
        description="Basins of attraction: every start of a grid over the initial peel angle alpha0 and the initial "
                    "pull force F0 (or roller speed omega0) is run past a transient and classified by its return "
                    "map in a window: a periodic attractor (period-n and its cycle of forces, numbered A0, A1, ... "
                    "across the grid), aperiodic, breakdown (the model stops), undetermined (no stick-slip), an "
                    "invalid start (no consistent initial state) or a failure; with --orbits each attractor's "
                    "periodic orbit and Floquet multipliers.",
        examples=["peelapprox basins --V 1.2 --I 1e-5 --force-family cubic --alpha0=-0.4:0.4:9 --omega0 10:25:7 "
                  "--plot basins.png",
                  "peelapprox basins --V 1 --I 1e-2 --alpha0 0:0.3:4 --F0 200:290:4 --orbits --out basins.json"])
    add_params(sp)
    sp.add_argument("--alpha0", required=True, metavar="LO:HI[:N]",
                    help="initial peel angles [rad] (default N: 11; a negative LO needs the = form: "
                         "--alpha0=-0.3:0.3); the grid holds at most 1000000 starts (exact.MAX_BASIN_STARTS)")
    axis = sp.add_mutually_exclusive_group(required=True)
    axis.add_argument("--F0", metavar="LO:HI[:N]", help="initial pull forces [N] (default N: 11)")
    axis.add_argument("--omega0", metavar="LO:HI[:N]", help="initial roller speeds [rad/s] (default N: 11)")
    sp.add_argument("--t-transient", type=nonnegative_float, default=w["t_transient"],
                    help="time discarded per start [s]")
    sp.add_argument("--window", type=positive_float, default=w["window"], help="time classified per start [s]")
    add_pool_options(sp, dask=False)
    sp.add_argument("--orbits", action="store_true",
                    help="also find each attractor's periodic orbit and its Floquet multipliers")
    sp.add_argument("--format", choices=FORMATS, default="table",
                    help="what is printed: table (one line an attractor or outcome), csv (one row a start) or json")
    sp.add_argument("--out", help="write one row per start to this .csv, or everything to this .json")
    sp.add_argument("--plot", help="draw the label map to this image file")
    add_max_wall_option(sp, what="the whole grid and the orbits",
                        spent="when it is spent the starts not run are failures (failure:max_wall), what was "
                              "computed is printed and written, and the exit status is 3")
    return sp


def run(args: argparse.Namespace) -> int:
    from exact import MAX_BASIN_STARTS, basins

    a_spec = _axis(args.alpha0, "--alpha0")
    name, text = ("F0", args.F0) if args.F0 is not None else ("omega0", args.omega0)
    v_spec = _axis(text, f"--{name}")
    if a_spec[2] * v_spec[2] > MAX_BASIN_STARTS:  # before the axes are made
        raise ValueError(f"--alpha0 x --{name}: the grid must hold at most {MAX_BASIN_STARTS} starts "
                         f"(exact.MAX_BASIN_STARTS: a 1000 x 1000 picture is days of runs, more is most likely a "
                         f"typo), got {a_spec[2]} x {v_spec[2]} = {a_spec[2] * v_spec[2]}")
    out = check_output_path(args.out, "table", "--out") if args.out else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    p = params_from_args(args)
    if args.orbits and p.variant is not None:
        raise ValueError(f"--orbits with --tape-mass / --loading load: --orbits {HYBRID_ONLY}; drop --orbits to "
                         "classify the variant's attractors by runs alone")
    a = np.linspace(*a_spec)
    values = np.linspace(*v_spec)
    axes = dict(F0=values, omega0=None) if name == "F0" else dict(F0=None, omega0=values)
    r = basins(p, alpha0=a, F0=axes["F0"], omega0=axes["omega0"], t_transient=args.t_transient,
               window=args.window, orbits=args.orbits, executor=args.pool, max_workers=args.workers,
               progress=True,
               max_wall=args.max_wall)
    if args.format == "json":
        print(r.to_json())
    elif args.format == "csv":
        write_csv(sys.stdout, r.rows())
    else:
        for a_ in r.attractors:
            mu = ""
            if a_.orbit is not None:
                mu = "  |mu| = " + ", ".join(f"{abs(m):.4g}" for m in a_.orbit.multipliers)
            cyc = ", ".join(f"{c:.6g}" for c in a_.cycle[:6]) + (" ..." if len(a_.cycle) > 6 else "")
            print(f"A{a_.id} period-{a_.n}: {a_.count} start{'s' * (a_.count != 1)}, F at the jumps [N]: {cyc}{mu}")
        others = {k: v for k, v in r.counts().items() if not k.startswith("A")}
        for k, v in others.items():
            print(f"{k}: {v} start{'s' * (v != 1)}")
        print(f"{a.size * values.size} starts in {r.wall_time:.1f} s")
    if out:
        if out.endswith(".json"):
            with open(out, "w") as fh:
                fh.write(r.to_json())
            say(f"wrote {out}")
        else:
            write_table(out, r.rows(), p.force)
    if plot:
        from ..plotting import save_figure

        save_figure(r.plot(title=f"basins, V = {p.V} m/s, I = {p.I:g} kg m²"), plot, dpi=130)
        say(f"wrote {plot}")
    cut = int(np.count_nonzero(r.texts == "failure:max_wall"))
    if cut:
        say(f"stopped: the --max-wall budget of {args.max_wall:g} s was spent; {cut} of the {r.texts.size} starts "
            "were not run or were cut (failure:max_wall)")
        return 3
    return 0


def _axis(text: str, option: str) -> tuple[float, float, int]:
    return grid_range(text, option, default_n=11)


