"""``peelapprox series FILE`` and ``peelapprox infer FILE``: one's own measured force trace on the command line.

``series`` reads a trace (:meth:`peelapprox.ForceSeries.from_csv`) and prints what the library reads off it: the
slips (:meth:`ForceSeries.slips`, optionally written per slip), the attractor observables, the return map's
period, optionally the Lyapunov exponent (:meth:`ForceSeries.lyapunov`) and the plots.  ``infer`` fits the
model's parameters to it (:func:`exact.infer`), reporting each exact run on stderr.
"""

from __future__ import annotations

import argparse
from typing import Any

from ._checks import check_output_path, positive_float
from ._common import add_format, add_params, params_from_args, print_mapping, say, subcommand, write_table

__all__ = ["add_infer_parser", "add_series_parser", "run_infer", "run_series"]


def _trace_options(sp: argparse.ArgumentParser) -> None:
    sp.add_argument("file", metavar="FILE", help="the trace: a CSV file whose header names the time and force "
                                                 "columns (default t and F; units in the header: t [ms], F [kN])")
    sp.add_argument("--columns", default="t,F", metavar="T,F",
                    help="the header names of the time and force columns (default t,F)")
    sp.add_argument("--threshold", type=positive_float, default=None,
                    help="the fall [N] that confirms a slip (default 12 sigma/sqrt(5) from the trace's noise)")


def _read(args: argparse.Namespace, V: float | None) -> Any:
    from .. import ForceSeries

    cols = tuple(c.strip() for c in str(args.columns).split(","))
    if len(cols) != 2 or not all(cols):
        raise ValueError(f"--columns must name two columns, time and force (e.g. t,F), got {args.columns!r}")
    return ForceSeries.from_csv(args.file, columns=(cols[0], cols[1]), V=V)


def add_series_parser(sub: Any) -> argparse.ArgumentParser:
    sp = subcommand(
        sub, "series", help="a measured force trace: its slips, observables, return map, Lyapunov exponent",
        description="Reads a force trace F(t) from a CSV file and prints what peelapprox reads off it "
                    "(ForceSeries): the noise level, the slips (threshold, count), the attractor observables "
                    "(slip interval, force drop, stick and slip times, the return map's period) and optionally "
                    "the largest Lyapunov exponent of the returns with its surrogate test.",
        examples=["peelapprox series trace.csv --V 1",
                  "peelapprox series trace.csv --V 1 --slips-out slips.csv --plot trace.png --format json",
                  "peelapprox series trace.csv --columns time,force --lyapunov --out summary.json"])
    _trace_options(sp)
    sp.add_argument("--V", type=positive_float, default=None, help="the pull speed [m/s], if known (a label)")
    sp.add_argument("--lyapunov", action="store_true", help="also the largest Lyapunov exponent of the returns")
    sp.add_argument("--slips-out", metavar="FILE", help="write the slips, one row each, to this .csv or .json")
    sp.add_argument("--out", metavar="FILE", help="also write the summary row to this .csv or .json")
    sp.add_argument("--plot", metavar="FILE", help="plot the trace with its slips marked to this image")
    sp.add_argument("--plot-return-map", metavar="FILE", help="plot the return map to this image")
    sp.add_argument("--max-wall", type=positive_float, default=300.0, metavar="S",
                    help="wall-clock budget of the Lyapunov exponent [s] (default 300)")
    add_format(sp)
    return sp


def run_series(args: argparse.Namespace) -> int:
    outs = {name: check_output_path(getattr(args, name), kind, "--" + name.replace("_", "-"))
            for name, kind in (("out", "table"), ("slips_out", "table"), ("plot", "image"),
                               ("plot_return_map", "image")) if getattr(args, name)}
    series = _read(args, args.V)
    slips = series.slips(args.threshold)
    obs = series.observables(args.threshold, slips=slips)
    row: dict[str, Any] = {"file": args.file, "samples": len(series), "duration": series.duration,
                           "rate": series.rate, "noise": series.noise, "threshold": slips.threshold,
                           **obs.as_dict()}
    if args.lyapunov:
        def progress(done: int, total: int) -> None:
            say(f"series: Lyapunov surrogates {done}/{total}")

        lyap = series.lyapunov(threshold=args.threshold, max_wall=args.max_wall, progress=progress)
        row.update({f"lyapunov_{k}": v for k, v in lyap.as_dict().items() if not isinstance(v, (list, dict))})
    print_mapping(row, args.format)
    if "slips_out" in outs:
        slips.write(outs["slips_out"])
        say(f"wrote {outs['slips_out']}")
    if "out" in outs:
        write_table(outs["out"], [row])
    for key, method in (("plot", "plot"), ("plot_return_map", "plot_return_map")):
        if key in outs:
            ax = getattr(series, method)(threshold=args.threshold)
            ax.figure.savefig(outs[key], dpi=120, bbox_inches="tight")
            say(f"wrote {outs[key]}")
    return 0


def add_infer_parser(sub: Any) -> argparse.ArgumentParser:
    ip = subcommand(
        sub, "infer", help="fit the model's parameters (I, k, ...) to a measured force trace",
        description="The parameters of the exact model whose force traces read like the measured one (exact.infer): "
                    "a grid search around the given parameters, then least squares on the trace's statistics; "
                    "each exact run is reported on stderr.  The model parameters given (--V, --I, --k, ...) are "
                    "the centre of the search; --free names those fitted.",
        examples=["peelapprox infer trace.csv --V 1 --I 1.3e-2 --k 900 --free I,k",
                  "peelapprox infer trace.csv --V 1 --I 1e-2 --k 900 --free k --search 1.5 --out fit.json"])
    _trace_options(ip)
    add_params(ip, variants="fits the paper's massless model under velocity control (tape_mass none, --loading "
                            "velocity)")
    ip.add_argument("--free", default="I,k", metavar="P,P",
                    help="the fitted parameters, comma-separated: I, k, R, force.<coefficient> (default I,k)")
    ip.add_argument("--search", type=float, default=3.0,
                    help="the grid spans params/SEARCH to params*SEARCH (default 3)")
    ip.add_argument("--t-transient", type=positive_float, default=30.0, help="time of each model run before its "
                                                                             "sampled window [s] (default 30)")
    ip.add_argument("--max-wall", type=positive_float, default=600.0, metavar="S",
                    help="wall-clock budget [s] (default 600): then the best point so far, status budget")
    ip.add_argument("--attractors", type=int, default=1, choices=range(1, 9), metavar="N",
                    help="at each trial point, the attractor closest to the data among those reached from the first "
                         "N starts of exact.attractor_set's design, 1-8 (default 1: the solver's start)")
    ip.add_argument("--replicates", type=int, default=1, choices=range(1, 9), metavar="N",
                    help="for a chaotic or quasi-periodic trace, the model's statistics at each trial point are the "
                         "mean over N replicates, 1-8 (default 1)")
    ip.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    ip.add_argument("--out", metavar="FILE", help="also write the result to this .json (or its residuals to .csv)")
    add_format(ip, "the result")
    return ip


def run_infer(args: argparse.Namespace) -> int:
    from exact import infer

    out = check_output_path(args.out, "table", "--out") if args.out else None
    params0 = params_from_args(args)
    free = tuple(x.strip() for x in str(args.free).split(",") if x.strip())
    series = _read(args, params0.V)
    progress = None if args.quiet else say  # its lines begin with "infer: "
    res = infer(series, params0, free, search=args.search, t_transient=args.t_transient, max_wall=args.max_wall,
                attractors=args.attractors, replicates=args.replicates, progress=progress)
    if args.format == "table":
        print(res.report())
    else:
        d = res.as_dict()
        print_mapping(d if args.format == "json" else _flat(d), args.format)
    if out:
        if out.endswith(".json"):
            write_table(out, [res.as_dict()])
        else:
            write_table(out, res.residuals)
    return 0


def _flat(d: dict[str, Any]) -> dict[str, Any]:
    """The result's scalars and its per-parameter values, standard errors and verdicts as one CSV row."""
    row: dict[str, Any] = {k: v for k, v in d.items() if not isinstance(v, (dict, list))}
    for name, value in d["values"].items():
        row[name] = value
        row[f"{name}_stderr_ln"] = d["stderr"].get(name)
        row[f"{name}_identified"] = d["identified"].get(name)
    return row
