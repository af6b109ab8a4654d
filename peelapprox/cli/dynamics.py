"""``peelapprox dynamics``: the return map's period, force drops, settle time, attractors and the largest
Lyapunov exponent at one (V, I) (:mod:`exact` and the core's return-map analysis)."""

from __future__ import annotations

import argparse
import json
import sys

from .. import LYAPUNOV_TAU, T_TRANSIENT, PeelParams
from ._checks import check_output_path, finite_float_list, nonnegative_float, positive_float, positive_int
from ._common import add_params, print_mapping, say, write_table

__all__ = ["LYAPUNOV_METHODS", "add_parser", "run"]

#: ``peelapprox dynamics --lyapunov-method`` choices.
LYAPUNOV_METHODS = ("two-trajectory", "saltation", "return-map", "regularized")


def add_parser(sub) -> argparse.ArgumentParser:
    dy = sub.add_parser("dynamics", help="period of the return map, force drops, settle time, attractors, "
                                         "Lyapunov exponent at one (V, I)")
    add_params(dy)
    dy.add_argument("--alpha0", type=float, default=0.0)
    dy.add_argument("--t-transient", type=nonnegative_float, default=T_TRANSIENT,
                    help=f"discarded [s] ({T_TRANSIENT:g})")
    dy.add_argument("--window", type=positive_float, default=20.0, help="analysed [s] (20)")
    dy.add_argument("--rtol", type=float, default=1e-10)
    dy.add_argument("--max-period", type=positive_int, default=32)
    dy.add_argument("--lyapunov", action="store_true", help="also the largest Lyapunov exponent (a few s)")
    dy.add_argument("--lyapunov-method", choices=LYAPUNOV_METHODS,
                    help="how (implies --lyapunov): two-trajectory renormalisation (the default), saltation "
                         "(tangent dynamics with saltation matrices), return-map (tangent of the jump-to-jump "
                         "map), regularized (variational equations of the ε-system; needs pydiffsol)")
    dy.add_argument("--lyapunov-time", type=positive_float, default=50.0, help="measured time [s] (50)")
    dy.add_argument("--eps", type=float, default=1e-7, help="ε of --lyapunov-method regularized (1e-7)")
    dy.add_argument("--attractors", type=finite_float_list, metavar="A0,A0,...",
                    help="sample these initial peel angles for coexisting attractors")
    dy.add_argument("--format", choices=("table", "json"), default="table")
    dy.add_argument("--out", help="also write the summary row to this .csv or .json")
    dy.add_argument("--max-wall", type=positive_float, default=600.0, metavar="S",
                    help="wall-clock budget of each computation (run, two-trajectory λ, attractors) [s] (600)")
    return dy


def run(args: argparse.Namespace) -> int:
    from exact import ModelBreakdown, attractors, simulate

    from .. import force_drops, periodicity, return_map, settle_time

    out = check_output_path(args.out, "table", "--out") if args.out else None
    if args.lyapunov_method == "return-map" and args.alpha0 != 0.0:
        raise ValueError("--lyapunov-method return-map starts from alpha0 = 0 only; drop --alpha0")
    p = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R)
    if args.attractors:  # checked before the run, named as the user wrote it
        from ..validate import states

        states("--attractors", args.attractors, "alpha")
    row: dict = dict(V=args.V, I=args.I, alpha0=args.alpha0, t_transient=args.t_transient, window=args.window)
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
    if args.lyapunov or args.lyapunov_method:
        method = args.lyapunov_method or "two-trajectory"
        print(f"lyapunov ({method}, {args.lyapunov_time:g} s after {args.t_transient:g} s) ...", file=sys.stderr,
              flush=True)
        ly = _lyapunov_by_method(p, method, args, row.get("returns"))
        row.update(lyapunov_method=method, lyapunov_time=args.lyapunov_time, lyapunov_bits_per_s=ly.bits_per_s,
                   lyapunov_stderr=ly.stderr_bits, lyapunov_wall_time=ly.benettin.wall_time)
        if method == "regularized":
            row.update(eps=args.eps)
    print_mapping(row, args.format)
    if args.attractors:
        a0s = args.attractors
        res = attractors(p, a0s, t_transient=args.t_transient, window=args.window, max_wall=args.max_wall,
                         progress=say)
        rows = [dict(attractor=a.label, starts=" ".join(f"{s:g}" for s in a.starts), F_min=a.F_range[0],
                     F_max=a.F_range[1]) for a in res]
        if args.format == "json":
            print(json.dumps(rows, indent=2))
        else:
            print(f"{len(res)} attractor(s) from {len(a0s)} starts:")
            for r in rows:
                print(f"  {r['attractor']:>14}  F at AB→CD jumps {r['F_min']:.4g}…{r['F_max']:.4g} N  "
                      f"from alpha0 = {r['starts']}")
    if out:
        write_table(out, [row])
    return 0


def _lyapunov_by_method(p: PeelParams, method: str, args: argparse.Namespace, returns):
    """The largest Lyapunov exponent at ``p`` by one of :data:`LYAPUNOV_METHODS` over ``args.lyapunov_time`` s."""
    import exact

    T, common = args.lyapunov_time, dict(t_transient=args.t_transient, alpha0=args.alpha0)
    if method == "two-trajectory":
        tau = LYAPUNOV_TAU
        return exact.lyapunov(p, tau=tau, n=max(2, int(round(T / tau))), max_wall=args.max_wall, **common)
    if method == "saltation":
        return exact.lyapunov_tangent(p, T=T, **common)
    if method == "return-map":  # alpha0 = 0: checked by the subcommand before the run
        if not returns:
            raise ValueError("--lyapunov-method return-map needs AB→CD returns in the window; there are none")
        return exact.lyapunov_return_map(p, t_transient=args.t_transient, max_wall=args.max_wall,
                                         n_returns=max(2, int(round(returns / args.window * T))))

    step = max(args.t_transient + T, 1e-9) / 10.0
    mark = [step]

    def progress(t_done, t_total):
        if t_done >= mark[0] - 1e-9 or t_done >= t_total:
            print(f"  {t_done:g}/{t_total:g} s", file=sys.stderr, flush=True)
            mark[0] += step

    return exact.lyapunov_variational(p, eps=args.eps, T=T, progress=progress, **common)
