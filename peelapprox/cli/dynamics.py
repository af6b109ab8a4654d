"""``peelapprox dynamics``: the return map's period, force drops, settle time, attractors and the largest
Lyapunov exponent at one (V, I) (:mod:`exact` and the core's return-map analysis)."""

from __future__ import annotations

import argparse
import json
import sys

from .. import EPS_DEFAULT, WINDOW_DEFAULTS
from ..io import write_csv
from ._checks import check_output_path, finite_float_list, nonnegative_float, positive_float, positive_int
from ._common import (
    add_format,
    add_params,
    params_from_args,
    print_mapping,
    say,
    subcommand,
    variant_summary,
    write_table,
)
from ._force import law_fields

__all__ = ["LYAPUNOV_ALIASES", "LYAPUNOV_METHODS", "add_parser", "run"]

#: ``peelapprox dynamics --lyapunov-method`` choices: the methods of ``exact.lyapunov``
#: (``exact.dynamics._lyapunov_options.LYAPUNOV_METHODS``, not imported here: the parser is built without loading
#: ``exact``; tests/test_cli.py keeps the two equal).
LYAPUNOV_METHODS = ("two-trajectory", "tangent", "return-map", "variational")
#: Earlier names of two of them, still accepted: alias -> method.
LYAPUNOV_ALIASES = {"saltation": "tangent", "regularized": "variational"}


def add_parser(sub) -> argparse.ArgumentParser:
    dy = subcommand(
        sub, "dynamics", help="period of the return map, force drops, settle time, attractors, Lyapunov exponent at "
                              "one (V, I)",
        description="The dynamics at one (V, I): one exact run, its return map (F at the AB->CD jumps) after the "
                    "transient, the map's period (period-n or aperiodic), the force drops, the time the orbit takes "
                    "to settle; on request the largest Lyapunov exponent [bits/s] with its standard error (batch "
                    "means), and the attractors reached from several initial peel angles.  Lyapunov methods: "
                    "two-trajectory (Benettin renormalisation; the default), tangent (tangent dynamics with "
                    "saltation matrices; alias saltation), return-map (tangent of the jump-to-jump map), "
                    "variational (variational equations of the eps-system; alias regularized; needs pydiffsol).  "
                    "Model variants (--tape-mass, --loading load): the run is exact.simulate's with the model's "
                    "method; a measure that does not run a variant says so (exit status 2).",
        examples=["peelapprox dynamics --V 2 --I 1e-4 --lyapunov            # period, force drops, lambda [bits/s]",
                  "peelapprox dynamics --V 2.5 --I 1e-4 --lyapunov-method tangent",
                  "peelapprox dynamics --V 1 --I 1e-2 --attractors 0,0.1,-0.2 --format json"])
    add_params(dy)
    w = WINDOW_DEFAULTS
    dy.add_argument("--alpha0", type=float, default=w["alpha0"], help="initial peel angle [rad]")
    dy.add_argument("--t-transient", type=nonnegative_float, default=w["t_transient"], help="discarded time [s]")
    dy.add_argument("--window", type=positive_float, default=w["window"], help="analysed time [s]")
    dy.add_argument("--rtol", type=float, default=w["rtol"], help="relative tolerance of the window's run")
    dy.add_argument("--max-period", type=positive_int, default=32,
                    help="longest period of the return map tried [returns]")
    dy.add_argument("--lyapunov", action="store_true", help="also the largest Lyapunov exponent (a few s)")
    dy.add_argument("--lyapunov-method", choices=(*LYAPUNOV_METHODS, *LYAPUNOV_ALIASES), metavar="METHOD",
                    help="how (implies --lyapunov), a method of exact.lyapunov: two-trajectory renormalisation "
                         "(the default), tangent (tangent dynamics with saltation matrices; alias saltation), "
                         "return-map (tangent of the jump-to-jump map, its returns as many as the window's "
                         "return rate gives in --lyapunov-time), variational (variational equations of the "
                         "eps-system; alias regularized; needs pydiffsol)")
    dy.add_argument("--lyapunov-time", type=positive_float, default=50.0, help="measured time [s]")
    dy.add_argument("--eps", type=float, default=EPS_DEFAULT,
                    help="the regularisation parameter epsilon of --lyapunov-method variational")
    dy.add_argument("--attractors", type=finite_float_list, metavar="A0,A0,...",
                    help="sample these initial peel angles [rad] for coexisting attractors")
    add_format(dy)
    dy.add_argument("--out", help="also write the summary row to this .csv or .json")
    dy.add_argument("--max-wall", type=positive_float, default=600.0, metavar="S",
                    help="wall-clock budget of each computation (run, Lyapunov exponent, attractors) [s]")
    return dy


def run(args: argparse.Namespace) -> int:
    from exact import ModelBreakdown, attractors, check_lyapunov_options, lyapunov, simulate

    from .. import force_drops, periodicity, return_map, settle_time

    out = check_output_path(args.out, "table", "--out") if args.out else None
    wants_lyapunov = bool(args.lyapunov or args.lyapunov_method)
    if wants_lyapunov:  # the method's options, checked before the window run (named as the CLI spells them)
        method, options = _lyapunov_options(args, returns=None)
        check_lyapunov_options(method, **options)
    p = params_from_args(args)
    law = p.force
    if wants_lyapunov and method == "variational":  # the method's laws, checked before the window run
        from exact import VARIATIONAL_LAWS

        from ..validate import params as check_params

        check_params("params", p, laws=VARIATIONAL_LAWS, where="--lyapunov-method variational (its DiffSL model "
                     "needs a closed-form law)")
    if args.attractors:  # checked before the run, named as the user wrote it
        from ..validate import states

        states("--attractors", args.attractors, "alpha")
    row: dict = dict(V=args.V, I=args.I, alpha0=args.alpha0, t_transient=args.t_transient, window=args.window)
    row.update(variant_summary(p))  # the model variant, if any
    try:
        # one run from t = 0: the window's jumps for the return map and force drops, all of them for the
        # settle time
        full = simulate(p, args.t_transient + args.window, alpha0=args.alpha0, rtol=args.rtol, save="jumps",
                        max_wall=args.max_wall)
        t_k, x_all = return_map(full, with_times=True)
        in_window = t_k >= args.t_transient
        x = x_all[in_window]
        per = periodicity(x, max_period=args.max_period) if x.size > 1 else None
        d = force_drops(full)
        d = d[in_window[: d.size]] if d.size else d
        row.update(returns=int(x.size), period=per.label if per else "no stick-slip",
                   period_mismatch=per.mismatch if per else None,
                   settle_time=settle_time(full, max_period=args.max_period),
                   mean_force_drop=float(d.mean()) if d.size else None,
                   force_drop_std=float(d.std()) if d.size else None,
                   F_min_at_jumps=float(x.min()) if x.size else None, F_max_at_jumps=float(x.max()) if x.size else None)
    except ModelBreakdown as exc:
        row.update(status=f"breakdown:{exc.reason} at t={exc.t:.6g}")
    if wants_lyapunov:
        name = args.lyapunov_method or "two-trajectory"
        print(f"lyapunov ({name}, {args.lyapunov_time:g} s after {args.t_transient:g} s) ...", file=sys.stderr,
              flush=True)
        method, options = _lyapunov_options(args, returns=row.get("returns", 0))
        ly = lyapunov(p, method, t_transient=args.t_transient, alpha0=args.alpha0, max_wall=args.max_wall,
                            **options)
        row.update(lyapunov_method=name, lyapunov_time=args.lyapunov_time, lyapunov_bits_per_s=ly.bits_per_s,
                   lyapunov_stderr=ly.stderr_bits, lyapunov_wall_time=ly.benettin.wall_time)
        if method == "variational":
            row.update(eps=args.eps)
    print_mapping({**row, **law_fields(law, spec=args.format == "json")}, args.format)
    if args.attractors:
        a0s = args.attractors
        res = attractors(p, a0s, t_transient=args.t_transient, window=args.window, max_wall=args.max_wall,
                         progress=say)
        rows = [dict(attractor=a.label, starts=" ".join(f"{s:g}" for s in a.starts), F_min=a.F_range[0],
                     F_max=a.F_range[1]) for a in res]
        if args.format == "json":
            print(json.dumps(rows, indent=2))
        elif args.format == "csv":
            write_csv(sys.stdout, rows)
        else:
            print(f"{len(res)} attractor(s) from {len(a0s)} starts:")
            for r in rows:
                print(f"  {r['attractor']:>14}  F at AB→CD jumps {r['F_min']:.4g}…{r['F_max']:.4g} N  "
                      f"from alpha0 = {r['starts']}")
    if out:
        write_table(out, [row], law)
    return 0


def _lyapunov_options(args: argparse.Namespace, returns: int | None) -> tuple[str, dict]:
    """``(method, options)`` of ``exact.lyapunov`` for ``--lyapunov-method`` (aliases mapped) and
    ``--lyapunov-time`` T: T itself where the method measures a time; for return-map as many returns as the
    window's return rate gives in T (``returns`` in the window; None: not known yet, before the window run)."""
    name = args.lyapunov_method or "two-trajectory"
    method = LYAPUNOV_ALIASES.get(name, name)
    T = args.lyapunov_time
    if method == "return-map":
        if returns is None:
            return method, {}
        if not returns:
            raise ValueError(f"--lyapunov-method {name} needs AB→CD returns in the window; there are none")
        return method, {"n_returns": max(2, int(round(returns / args.window * T)))}
    if method != "variational":
        return method, {"T": T}
    step = max(args.t_transient + T, 1e-9) / 10.0
    mark = [step]

    def progress(t_done, t_total):
        if t_done >= mark[0] - 1e-9 or t_done >= t_total:
            print(f"  {t_done:g}/{t_total:g} s", file=sys.stderr, flush=True)
            mark[0] += step

    return method, {"eps": args.eps, "T": T, "progress": progress}
