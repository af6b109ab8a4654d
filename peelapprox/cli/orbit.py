"""``peelapprox orbit`` and ``peelapprox bifurcation``: periodic orbits as objects (:func:`exact.periodic_orbit`,
:func:`exact.continue_orbit`, :func:`exact.orbit_diagram`)."""

from __future__ import annotations

import argparse

import numpy as np

from .. import WINDOW_DEFAULTS
from ..errors import WallBudget
from . import _common
from ._checks import check_output_path, grid_range, nonnegative_float, nonnegative_int, positive_float, positive_int
from ._common import (
    FORMATS,
    add_format,
    add_max_wall_option,
    add_params,
    params_from_args,
    print_mapping,
    say,
    subcommand,
    wall_left,
    wall_spent,
    write_table,
)
from ._force import law_fields

__all__ = ["add_bifurcation_parser", "add_orbit_parser", "run_bifurcation", "run_orbit"]


def _seed_options(sp: argparse.ArgumentParser) -> None:
    w = WINDOW_DEFAULTS
    sp.add_argument("--alpha0", type=float, default=w["alpha0"], help="initial peel angle of the seed run [rad]")
    sp.add_argument("--t-transient", type=nonnegative_float, default=w["t_transient"],
                    help="transient of the seed run [s]")
    sp.add_argument("--window", type=positive_float, default=w["window"],
                    help="its window [s], where the period is read")


def add_orbit_parser(sub) -> argparse.ArgumentParser:
    sp = subcommand(
        sub, "orbit", help="a periodic orbit by Newton on the AB->CD section: period, Floquet multipliers, "
                           "stability, one period drawn",
        description="A periodic orbit of the exact model as an object: a seed run gives the period n (AB->CD jumps "
                    "per period) and a start; Newton's method on the return map to the AB->CD section closes the "
                    "orbit; its period [s], Floquet multipliers (stable when all |mu| < 1) and the force at its "
                    "jumps are printed.",
        examples=["peelapprox orbit --V 1 --I 1e-5 --plot orbit.png     # periodic orbit, multipliers, stability",
                  "peelapprox orbit --V 1 --I 1e-2 --n 8 --format json"])
    add_params(sp, variants=_common.HYBRID_ONLY)
    _seed_options(sp)
    sp.add_argument("--n", type=positive_int, help="AB->CD jumps per period (default: the seed run's period)")
    add_format(sp)
    sp.add_argument("--out", help="also write the summary row to this .csv or .json")
    sp.add_argument("--plot", help="draw one period (F, alpha, v against t and the v-F plane) to this image file")
    add_max_wall_option(sp, what="the seed run and Newton's method",
                        spent="when it is spent the command stops with exit status 3")
    return sp


def run_orbit(args: argparse.Namespace) -> int:
    from exact import State, initial_state, periodic_orbit

    out = check_output_path(args.out, "table", "--out") if args.out else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    p = params_from_args(args)
    start: State | None = initial_state(p, alpha0=args.alpha0) if args.alpha0 else None
    o = periodic_orbit(p, start=start, n=args.n, t_transient=args.t_transient, window=args.window,
                       max_wall=args.max_wall)
    row: dict = dict(V=p.V, I=p.I, n=o.n, period=o.period, stable=o.stable, residual=o.residual,
                     newton_iterations=len(o.newton))
    for i, mu in enumerate(o.multipliers):
        row[f"multiplier_{i + 1}"] = f"{mu.real:.10g}{mu.imag:+.10g}j"
        row[f"multiplier_{i + 1}_abs"] = float(abs(mu))
    row["F_at_jumps"] = [float(x) for x in o.return_map_values]
    row["wall_time"] = o.wall_time
    row.update(law_fields(p.force, spec=args.format == "json"))
    print_mapping(row, args.format)
    if out:
        write_table(out, [{k: v for k, v in row.items() if k not in ("law", "law_key", "law_spec")}], p.force)
    if plot:
        from ..plotting import plot_trajectory
        from ..plotting._figure import params_label
        from .simulate import PLOT_SAMPLES

        mus = ", ".join(f"{abs(m):.4g}" for m in o.multipliers)
        # one period, its steps and (smooth curves) the same period sampled densely by the solver's dense output
        plot_trajectory(o.trajectory(), plot, cycles=None,
                        dense=o.trajectory(t_eval=np.linspace(0.0, o.period, PLOT_SAMPLES)),
                        title=f"period-{o.n} orbit, {params_label(p)}\nT = {o.period:.6g} s, "
                              f"|μ| = {mus} ({'stable' if o.stable else 'unstable'})")
        say(f"wrote {plot}")
    return 0


def add_bifurcation_parser(sub) -> argparse.ArgumentParser:
    sp = subcommand(
        sub, "bifurcation", help="the brute-force orbit diagram over a parameter with continued branches of "
                                 "periodic orbits drawn over it",
        description="The orbit diagram over one parameter (V, I, k or a coefficient of a family law): at each "
                    "value, F at the AB->CD jumps after the transient; then periodic orbits found at seed values "
                    "and continued both ways (pseudo-arclength through folds), their bifurcations (fold, period "
                    "doubling, Neimark-Sacker) and non-smooth ends (grazing, crest event, breakdown) reported; "
                    "at each period doubling the doubled branch is followed.  Prints one line a branch (--format); "
                    "progress on stderr.",
        examples=["peelapprox bifurcation --V 1 --I 1e-2 --param V --range 0.5:1.5:21 --plot bif.png --out bif.csv",
                  "peelapprox bifurcation --V 1 --I 1e-5 --param I --range 1e-5:1e-4:10 --seeds 2e-5,5e-5",
                  "peelapprox bifurcation --V 1 --I 1e-5 --force-family cubic --param force.c --range 280:320:9"])
    add_params(sp, variants=_common.HYBRID_ONLY)
    _seed_options(sp)
    sp.add_argument("--param", default="V", help="the parameter: V, I, k or force.NAME (a coefficient of "
                                                 "--force-family)")
    sp.add_argument("--range", required=True, metavar="LO:HI[:N]",
                    help="the parameter's range (in its unit: V [m/s], I [kg m^2], k [N/m]) and the diagram's "
                         "number of values (default N: 40; at most 100000, exact.MAX_DIAGRAM_VALUES)")
    sp.add_argument("--seeds", metavar="X,X,...|auto",
                    help="parameter values at which orbits are found and continued both ways; auto (the default): "
                         "each periodic diagram value that no branch found so far explains (exact.explain), in "
                         "order, at most --max-seeds")
    sp.add_argument("--max-seeds", type=positive_int, default=20, help="most automatic seeds")
    sp.add_argument("--max-points", type=positive_int, default=200, help="most orbits per branch")
    sp.add_argument("--switch", type=nonnegative_int, default=1,
                    help="levels of period doubling followed: at each period doubling found, the doubled branch "
                         "is started (exact.switch_branch) and continued, to this depth (0: none)")
    sp.add_argument("--format", choices=FORMATS, default="table",
                    help="how the branches are printed: table (one line a branch: period, points, parameter span "
                         "[unit of --param], bifurcations, end), csv or json (the same as rows)")
    sp.add_argument("--out", help="write every diagram point and branch point to this .csv or .json")
    sp.add_argument("--plot", help="draw the diagram and the branches to this image file")
    sp.add_argument("--plot-branches", type=positive_int, default=12, metavar="N",
                    help="--plot draws at most N branches, the first ones (the title says how many of how many)")
    sp.add_argument("--plot-select", metavar="K,K,...",
                    help="--plot draws only these branches, numbered from 1 as printed")
    add_max_wall_option(sp, what="the whole command (the diagram's runs, the orbits, the branches)",
                        spent="when it is spent the diagram's values left are labelled budget:max_wall, no branch "
                              "is started and a running one ends (stopped: max_wall); what was computed is "
                              "printed and written, and the exit status is 3")
    return sp


def _continue(o, param: str, stop: float, lo: float, hi: float, max_points: int, depth: int, indent: str,
              wall: WallBudget) -> list:
    """The branch of ``o`` towards ``stop`` and, to ``depth`` levels, the doubled branches of its period
    doublings (each continued to the end of the range on the side where it lies), within the command's budget
    ``wall``."""
    from exact import SolverBudgetExceeded, continue_orbit, parameter_value, switch_branch

    b = continue_orbit(o, param, stop=stop, max_points=max_points, max_wall=wall_left(wall))
    say(f"{indent}  period-{o.n} branch to {param} = {stop:g}: {len(b.points)} orbits, stopped: {b.stopped} at "
        f"{b.end_value:.8g}; " + (", ".join(f"{x.kind} at {x.value:.8g}" for x in b.bifurcations)
                                  or "no bifurcation"))
    out = [b]
    for x in b.bifurcations:
        if not x.doubles or depth < 1:
            continue
        if wall_spent(wall):
            say(f"{indent}    no doubled branch: --max-wall spent")
            continue
        try:
            o2 = switch_branch(x, max_wall=wall_left(wall))
        except (ValueError, SolverBudgetExceeded) as exc:
            say(f"{indent}    no doubled branch: {exc}")
            continue
        v2 = parameter_value(o2.params, param)
        out += _continue(o2, param, hi if v2 > x.value else lo, lo, hi, max_points, depth - 1, indent + "  ", wall)
    return out


def run_bifurcation(args: argparse.Namespace) -> int:
    from exact import orbit_diagram

    wall = WallBudget(args.max_wall)
    lo, hi, n, out, plot, select, p, seeds = _bifurcation_arguments(args)
    auto = args.seeds in (None, "auto")
    diagram = orbit_diagram(p, args.param, np.linspace(lo, hi, n), t_transient=args.t_transient,
                            window=args.window, alpha0=args.alpha0, progress=True, max_wall=wall_left(wall))
    branches: list = []
    explained: list = [None] * n
    if auto:  # every periodic value no branch so far explains, in order
        for j, (x, lab) in enumerate(zip(diagram.values, diagram.labels)):
            if len(seeds) >= args.max_seeds:
                break
            if lab.startswith("period-") and explained[j] is None:
                seeds.append(float(x))
                _grow(float(x), args, p, lo, hi, diagram, branches, explained, wall)
    else:
        for s in seeds:
            _grow(s, args, p, lo, hi, diagram, branches, explained, wall)
    periodic = [j for j, lab in enumerate(diagram.labels) if lab.startswith("period-")]
    missing = [f"{diagram.values[j]:.6g} ({diagram.labels[j]})" for j in periodic if explained[j] is None]
    say(f"explained: {len(periodic) - len(missing)} of the {len(periodic)} periodic values of the diagram lie on a "
        "stable continued branch of the same period (exact.explain)"
        + (f"; not: {', '.join(missing)}" if missing else ""))
    _print_branches(branches, args.param, args.format)
    if out:
        write_table(out, _bifurcation_rows(args.param, diagram, branches, explained), p.force)
    if plot:
        _plot_bifurcation(plot, p, diagram, branches, select, args.plot_branches)
    if wall_spent(wall) or "budget:max_wall" in diagram.labels or any(b.stopped == "max_wall" for b in branches):
        say(f"stopped: the --max-wall budget of {args.max_wall:g} s was spent; the output holds what was computed "
            "(diagram values labelled budget:max_wall, branches stopped: max_wall)")
        return 3
    return 0


def _bifurcation_arguments(args: argparse.Namespace) -> tuple:
    """``bifurcation``'s range, output paths, ``--plot-select``, parameters and ``--seeds`` checked, in this order
    (before any run): ``(lo, hi, n, out, plot, select, params, seeds)``, ``seeds`` empty for ``auto``."""
    from exact import MAX_DIAGRAM_VALUES

    lo, hi, n = grid_range(args.range, "--range")
    if n > MAX_DIAGRAM_VALUES:  # before the values are made
        raise ValueError(f"--range: N must be at most {MAX_DIAGRAM_VALUES} (exact.MAX_DIAGRAM_VALUES: 1e5 runs are "
                         f"about a day at ~1 s each, more is most likely a typo), got {n} in {args.range!r}")
    out = check_output_path(args.out, "table", "--out") if args.out else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    try:
        select = None if args.plot_select is None else [int(k) for k in args.plot_select.split(",")]
        if select is not None and min(select) < 1:
            raise ValueError
    except ValueError:
        raise ValueError(f"--plot-select must be branch numbers K,K,..., got {args.plot_select!r}") from None
    p = params_from_args(args)
    try:
        seeds = [] if args.seeds in (None, "auto") else [float(x) for x in args.seeds.split(",")]
    except ValueError:
        raise ValueError(f"--seeds must be numbers X,X,... or auto, got {args.seeds!r}") from None
    for s in seeds:
        if not lo <= s <= hi:
            raise ValueError(f"--seeds must lie in --range [{lo}, {hi}], got {s}")
    return lo, hi, n, out, plot, select, p, seeds


def _grow(s: float, args: argparse.Namespace, p, lo: float, hi: float, diagram, branches: list, explained: list,
          wall: WallBudget) -> None:
    """Branches from the orbit at ``s`` both ways, added to ``branches``; the diagram values they explain marked
    in ``explained`` (the index of the first branch that does)."""
    from exact import explain, initial_state, periodic_orbit, with_parameter

    if wall_spent(wall):
        say(f"orbit at {args.param} = {s:g}: not looked for, --max-wall spent")
        return
    ps = with_parameter(p, args.param, s)
    say(f"orbit at {args.param} = {s:g} ...")
    start = initial_state(ps, alpha0=args.alpha0) if args.alpha0 else None
    try:
        o = periodic_orbit(ps, start=start, t_transient=args.t_transient, window=args.window,
                           max_wall=wall_left(wall))
    except (ValueError, RuntimeError) as exc:  # no periodic orbit closes there (or the run breaks down)
        say(f"  no orbit: {exc}")
        return
    new = []
    for stop in (lo, hi):
        if stop != s:
            new += _continue(o, args.param, stop, lo, hi, args.max_points, args.switch, "", wall)
    for j, i in enumerate(explain(diagram, new, max_wall=wall_left(wall))):
        if explained[j] is None and i is not None:
            explained[j] = len(branches) + i
    branches.extend(new)


def _bifurcation_rows(param: str, diagram, branches: list, explained: list) -> list[dict]:
    """Every diagram point (with the branch that explains it, numbered from 1) and every branch's points,
    bifurcations and end, as rows for ``--out``."""
    rows = [dict(kind="diagram", **r) for r in diagram.rows()]
    by_value = {float(x): (None if e is None else e + 1) for x, e in zip(diagram.values, explained)}
    for r in rows:
        r["explained_by_branch"] = by_value[r[param]]
    for k, b in enumerate(branches):
        rows += [dict(kind=f"branch {k + 1}", **r) for r in b.rows()]
        rows += [dict(kind=f"branch {k + 1} {x.kind}", **{param: x.value}) for x in b.bifurcations]
        rows.append(dict(kind=f"branch {k + 1} end: {b.stopped}", **{param: b.end_value}))
    return rows


def _plot_bifurcation(plot: str, p, diagram, branches: list, select: list[int] | None, max_branches: int) -> None:
    """``--plot``: the diagram and the branches (those of ``select`` that exist)."""
    from ..plotting import plot_bifurcation

    if select is not None and max(select) > len(branches):  # known only now: drawn without them
        say(f"--plot-select: no branch {', '.join(str(k) for k in select if k > len(branches))} "
            f"(there are {len(branches)})")
        select = [k for k in select if k <= len(branches)]
    plot_bifurcation(diagram, branches, plot, params=p, select=select, max_branches=max_branches)
    say(f"wrote {plot}")


def _print_branches(branches: list, param: str, fmt: str) -> None:
    """One row per continued branch on stdout: its period n, orbits, parameter span, bifurcations and end."""
    import json
    import sys

    from ..io import write_csv

    rows = [dict(branch=k + 1, n=b.points[0].orbit.n, orbits=len(b.points), start=b.points[0].value,
                 end=b.end_value, stopped=b.stopped,
                 bifurcations="; ".join(f"{x.kind} at {x.value:.8g}" for x in b.bifurcations))
            for k, b in enumerate(branches)]
    if fmt == "json":
        print(json.dumps(rows, indent=2))
    elif fmt == "csv":
        write_csv(sys.stdout, rows, fields=["branch", "n", "orbits", "start", "end", "stopped", "bifurcations"])
    else:
        unit = {"V": " m/s", "I": " kg m^2", "k": " N/m"}.get(param, "")
        over = f"{param} [{unit.strip()}]" if unit else param
        print(f"{len(branches)} branch{'es' * (len(branches) != 1)} over {over}:")
        for r in rows:
            print(f"  branch {r['branch']}: period-{r['n']}, {r['orbits']} orbits, {param} = {r['start']:.6g} -> "
                  f"{r['end']:.6g}{unit}, stopped: {r['stopped']}; {r['bifurcations'] or 'no bifurcation'}")
