"""``peelapprox orbit`` and ``peelapprox bifurcation``: periodic orbits as objects (:func:`exact.periodic_orbit`,
:func:`exact.continue_orbit`, :func:`exact.orbit_diagram`)."""

from __future__ import annotations

import argparse

import numpy as np

from .. import WINDOW_DEFAULTS, PeelParams
from ._checks import check_output_path, nonnegative_float, positive_float, positive_int
from ._common import add_params, print_mapping, say, write_table
from ._force import force_from_args, law_fields

__all__ = ["add_bifurcation_parser", "add_orbit_parser", "run_bifurcation", "run_orbit"]


def _seed_options(sp: argparse.ArgumentParser) -> None:
    w = WINDOW_DEFAULTS
    sp.add_argument("--alpha0", type=float, default=w["alpha0"], help="start of the seed run [rad] (0)")
    sp.add_argument("--t-transient", type=nonnegative_float, default=w["t_transient"],
                    help=f"transient of the seed run [s] ({w['t_transient']:g})")
    sp.add_argument("--window", type=positive_float, default=w["window"], help=f"its window [s] ({w['window']:g})")


def add_orbit_parser(sub) -> argparse.ArgumentParser:
    sp = sub.add_parser("orbit", help="a periodic orbit by Newton on the AB->CD section: period, Floquet "
                                      "multipliers, stability, one period drawn")
    add_params(sp)
    _seed_options(sp)
    sp.add_argument("--n", type=positive_int, help="AB->CD jumps per period (default: the seed run's period)")
    sp.add_argument("--format", choices=("table", "json"), default="table")
    sp.add_argument("--out", help="also write the summary row to this .csv or .json")
    sp.add_argument("--plot", help="draw one period (F, α, v against t and the v-F plane) to this image file")
    return sp


def _params(args: argparse.Namespace) -> PeelParams:
    return PeelParams(V=args.V, I=args.I, k=args.k, R=args.R, force=force_from_args(args))


def run_orbit(args: argparse.Namespace) -> int:
    from exact import State, initial_state, periodic_orbit

    out = check_output_path(args.out, "table", "--out") if args.out else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    p = _params(args)
    start: State | None = initial_state(p, alpha0=args.alpha0) if args.alpha0 else None
    o = periodic_orbit(p, start=start, n=args.n, t_transient=args.t_transient, window=args.window)
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

        mus = ", ".join(f"{abs(m):.4g}" for m in o.multipliers)
        plot_trajectory(o.trajectory(), plot, title=f"period-{o.n} orbit, V = {p.V} m/s, I = {p.I:g} kg m²: "
                        f"T = {o.period:.6g} s, |μ| = {mus} ({'stable' if o.stable else 'unstable'})")
        say(f"wrote {plot}")
    return 0


def add_bifurcation_parser(sub) -> argparse.ArgumentParser:
    sp = sub.add_parser("bifurcation", help="the brute-force orbit diagram over a parameter with continued "
                                            "branches of periodic orbits drawn over it")
    add_params(sp)
    _seed_options(sp)
    sp.add_argument("--param", default="V", help="V, I, k or force.<coefficient> of a family law (V)")
    sp.add_argument("--range", required=True, metavar="LO:HI[:N]",
                    help="the parameter's range and the diagram's number of values (N = 40)")
    sp.add_argument("--seeds", metavar="X,X,...|auto",
                    help="parameter values at which orbits are found and continued both ways; auto (the default): "
                         "each diagram value whose run is periodic with another period than the value before (at "
                         "most --max-seeds)")
    sp.add_argument("--max-seeds", type=positive_int, default=20, help="most automatic seeds (20)")
    sp.add_argument("--max-points", type=positive_int, default=200, help="most orbits per branch (200)")
    sp.add_argument("--out", help="write every diagram point and branch point to this .csv or .json")
    sp.add_argument("--plot", help="draw the diagram and the branches to this image file")
    return sp


def _range(text: str) -> tuple[float, float, int]:
    parts = text.split(":")
    if len(parts) not in (2, 3):
        raise ValueError(f"--range must be LO:HI or LO:HI:N, got {text!r}")
    try:
        lo, hi = float(parts[0]), float(parts[1])
        n = int(parts[2]) if len(parts) == 3 else 40
    except ValueError:
        raise ValueError(f"--range must be LO:HI[:N] with numbers, got {text!r}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi and n >= 2):
        raise ValueError(f"--range needs finite LO < HI and N >= 2, got {text!r}")
    return lo, hi, n


def run_bifurcation(args: argparse.Namespace) -> int:
    from exact import continue_orbit, orbit_diagram, periodic_orbit, with_parameter

    out = check_output_path(args.out, "table", "--out") if args.out else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    lo, hi, n = _range(args.range)
    p = _params(args)
    auto = args.seeds in (None, "auto")
    try:
        seeds = [] if auto else [float(x) for x in args.seeds.split(",")]
    except ValueError:
        raise ValueError(f"--seeds must be numbers X,X,... or auto, got {args.seeds!r}") from None
    for s in seeds:
        if not lo <= s <= hi:
            raise ValueError(f"--seeds must lie in --range [{lo}, {hi}], got {s}")
    diagram = orbit_diagram(p, args.param, np.linspace(lo, hi, n), t_transient=args.t_transient,
                            window=args.window, alpha0=args.alpha0, progress=True)
    if auto:  # where the brute-force period changes to a periodic one
        prev = None
        for x, lab in zip(diagram.values, diagram.labels):
            if lab.startswith("period-") and lab != prev and len(seeds) < args.max_seeds:
                seeds.append(float(x))
            prev = lab
    branches = []
    for s in seeds:
        ps = with_parameter(p, args.param, s)
        say(f"orbit at {args.param} = {s:g} ...")
        try:
            o = periodic_orbit(ps, t_transient=args.t_transient, window=args.window)
        except (ValueError, RuntimeError) as exc:  # no periodic orbit closes there (or the run breaks down)
            say(f"  no orbit: {exc}")
            continue
        for stop in (lo, hi):
            if stop != s:
                b = continue_orbit(o, args.param, stop=stop, max_points=args.max_points)
                say(f"  branch to {args.param} = {stop:g}: {len(b.points)} orbits, stopped: {b.stopped}; "
                    + (", ".join(f"{x.kind} at {x.value:.8g}" for x in b.bifurcations) or "no bifurcation"))
                branches.append(b)
    if out:
        rows = [dict(kind="diagram", **r) for r in diagram.rows()]
        for k, b in enumerate(branches):
            rows += [dict(kind=f"branch {k + 1}", **r) for r in b.rows()]
            rows += [dict(kind=f"branch {k + 1} {x.kind}", **{args.param: x.value}) for x in b.bifurcations]
        write_table(out, rows, p.force)
    if plot:
        from ..plotting import plot_bifurcation

        plot_bifurcation(diagram, branches, plot, title=f"{args.param} in [{lo:g}, {hi:g}]")
        say(f"wrote {plot}")
    return 0
