"""The second, finer pass of :func:`exact.infer`, where the first pass says that the comb was not resolved.

An attractor's statistics along a parameter are a comb of periodic windows; a window (a "tooth") narrower than
the grid's node spacing (ln I, ln k steps of ~0.27: nodes 32 % apart) holds no node, and the local steps (the
least-squares fit, the valley walk) cannot cross the comb to it.  At ``infer_targets`` seed 8 trace 2 the truth's
period-1 window is ±10 % wide in I (χ² 1.31 at the truth) while the fit ended on a period-4 attractor at I -78.5 %
(χ² 5.01, flagged by the period check); at seed 8 trace 3 the best point found had χ² 162 on 4 dof (docs/your-data.md).

The pass runs only where the first pass failed in a way that says so (:func:`trigger`): the best point's χ² is
improbable at the outcome's ``poor_fit``, or the best point's attractor has clearly another period than the data's
(``period_check``), judged after the first pass's verdicts and only where they identify nothing, so it cannot
lose a hit (a hit is identified).  It then evaluates, at a quarter of the first grid's spacing (offsets ``{-2..2}``
quarters per axis, as ``refine``), the cells of at most :data:`FINE_CENTRES` coarse-grid nodes
(:func:`fine_centres`): the start, then the nodes whose attractor has the data's period (best χ² first), then the
others (best first), skipping a node whose cell was mostly evaluated already; a least-squares fit follows from
the best new point.  The verdict machinery (replicate check, valley walk, period check, intervals) then applies to
the best point as to any.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from peelapprox.io import fmt_number

from ._infer_result import Outcome, assemble
from ._infer_search import Point, Problem, best, nodes, values_of
from ._infer_stats import data_period

__all__ = ["FINE_CENTRES", "FINE_STEPS", "cell_points", "coarse_nodes", "fine_centres", "fine_points", "second_pass",
           "trigger"]

#: The most coarse-grid nodes whose cells the second pass evaluates (24 points each for two parameters, 72 in all):
#: at seed 8 trace 2 the truth lies in the cell of the best node on the data's period (the 4th-best node), at
#: seed 8 trace 3 in the start's cell.  0: no second pass.
FINE_CENTRES = 3
#: The offsets per axis, in units of the first grid's node spacing (a quarter of it; half with three parameters or
#: more, to bound the runs as ``refine`` does).
FINE_STEPS = (-0.5, -0.25, 0.0, 0.25, 0.5)
_FINE_STEPS_3D = (-0.5, 0.0, 0.5)


def trigger(chi2: float, dof: int, poor_fit: float, periods: Sequence[str],
            replicate: tuple[float, int] | None = None) -> str | None:
    """Why the second pass runs, or None: the best χ² improbable at ``poor_fit`` (dof below 1 judged on 1), or its
    neighbours' (``replicate``: χ² and dof, an aperiodic fit's), or the period check's disagreements ``periods``
    (non-empty).  ``infer`` asks it only where the first pass identified nothing."""
    from scipy.stats import chi2 as chi2_dist

    p = float(chi2_dist.sf(chi2, max(dof, 1)))
    if p < poor_fit:
        return f"the best fit is poor (chi2 = {chi2:.4g} on {dof} dof, probability {p:.2g} < {poor_fit:g})"
    if replicate is not None:
        q = float(chi2_dist.sf(replicate[0], max(replicate[1], 1)))
        if q < poor_fit:
            return (f"the best point's neighbours fit poorly (chi2 = {replicate[0]:.4g} on {replicate[1]}, "
                    f"probability {q:.2g} < {poor_fit:g})")
    if periods:
        return "the best point's attractor has another period than the data's (" + "; ".join(periods) + ")"
    return None


def coarse_nodes(x0: np.ndarray, spacing: np.ndarray, evaluated: Sequence[Point]) -> list[Point]:
    """The evaluated points on the first grid's lattice ``x0 + n · spacing`` (an axis of spacing 0: at ``x0``)."""
    out = []
    for e in evaluated:
        u = np.divide(e.x - x0, spacing, out=np.zeros_like(x0), where=spacing > 0)
        if np.allclose(u, np.round(u), rtol=0.0, atol=1e-6) and np.allclose(e.x[spacing <= 0], x0[spacing <= 0]):
            out.append(e)
    return out


def cell_points(centre: np.ndarray, spacing: np.ndarray, box: tuple[np.ndarray, np.ndarray]) -> list[np.ndarray]:
    """The second pass's points of one node's cell: per axis :data:`FINE_STEPS` times the spacing (an axis of
    spacing 0 kept), inside ``box``, the centre left out."""
    steps = FINE_STEPS if centre.size <= 2 else _FINE_STEPS_3D
    out = []
    for off in nodes([np.array(steps) * s if s > 0 else np.zeros(1) for s in spacing]):
        x = centre + off
        if not np.any(off != 0) or np.any(x < box[0] - 1e-12) or np.any(x > box[1] + 1e-12):
            continue
        out.append(x)
    return out


def fine_centres(x0: np.ndarray, spacing: np.ndarray, evaluated: Sequence[Point], box: tuple[np.ndarray, np.ndarray],
                 on_period: Callable[[Point], bool], n: int = FINE_CENTRES) -> list[np.ndarray]:
    """The (at most ``n``) coarse nodes whose cells the second pass evaluates, in order: the start ``x0`` (clipped
    to ``box``), the nodes with ``on_period`` true by χ², then the others by χ²; a node whose cell has half its
    points or more evaluated already (the first pass's ``refine`` around its best nodes) is skipped."""
    def done(c: np.ndarray) -> bool:
        pts = cell_points(c, spacing, box)
        hit = sum(any(np.allclose(p, e.x, rtol=0.0, atol=1e-9) for e in evaluated) for p in pts)
        return bool(pts) and 2 * hit >= len(pts)

    grid = sorted(coarse_nodes(x0, spacing, evaluated), key=lambda e: e.chi2)
    order = [np.clip(x0, box[0], box[1])] + [e.x for e in grid if on_period(e)] + [e.x for e in grid
                                                                                    if not on_period(e)]
    out: list[np.ndarray] = []
    for c in order:
        if len(out) >= n:
            break
        if any(np.allclose(c, o, rtol=0.0, atol=1e-9) for o in out) or done(c):
            continue
        out.append(np.array(c))
    return out


def fine_points(centres: Sequence[np.ndarray], spacing: np.ndarray, box: tuple[np.ndarray, np.ndarray],
                evaluated: Sequence[Point]) -> list[np.ndarray]:
    """The cells' points of ``centres`` in order, each once, the evaluated ones left out."""
    out: list[np.ndarray] = []
    for c in centres:
        for x in cell_points(c, spacing, box):
            if any(np.allclose(x, o, rtol=0.0, atol=1e-9) for o in out) or any(
                    np.allclose(x, e.x, rtol=0.0, atol=1e-9) for e in evaluated):
                continue
            out.append(x)
    return out


def second_pass(problem: Problem, run: Any, outcome: Outcome, first: Outcome, x0: np.ndarray,
                spent: type[Exception], options: dict[str, float]) -> tuple[Outcome | None, Outcome]:
    """The finer second pass (``exact/dynamics/_infer_fine.py``) where the first pass identified nothing because its
    best fit is poor or on an attractor of another period than the data's: the cells of a few coarse nodes at a
    quarter of the grid's spacing, then a least-squares fit from the best new point.  Returns the first pass's
    search outcome ``first`` with the new Jacobian and a note where it found a better point (the verdict machinery
    then runs again on it), else None; and ``outcome``, with the note where it ran and found none.  Its runs are
    all in ``run.evaluated``.  ``run`` is ``infer``'s search (its ``evaluated``, ``fits``, ``left``, ``progress``,
    ``run_nodes``, ``residuals``, raising ``spent`` past the budget); ``options``, the least-squares fit's
    ``diff_step`` and ``xtol``."""
    from scipy.optimize import least_squares

    res = assemble(problem, run.fits, outcome)
    rep = outcome.replicate
    spacing = outcome.spacing
    why = None if any(res.identified.values()) or spacing is None else trigger(
        res.chi2, res.dof, outcome.poor_fit, outcome.periods, rep)
    if why is None or spacing is None or run.left() <= 0:
        return None, outcome
    before = best(run.evaluated)
    wanted = [data_period(f.series)[0] for f in run.fits]

    def on_period(e: Point) -> bool:
        return any(p is not None for p in wanted) and all(p is None or r.period == p
                                                          for p, r in zip(wanted, e.readings))

    centres = fine_centres(x0, spacing, run.evaluated, outcome.box, on_period, FINE_CENTRES)
    points = fine_points(centres, spacing, outcome.box, run.evaluated)
    if run.progress is not None:
        run.progress(f"infer: a second pass, {len(points)} points around {len(centres)} nodes at a quarter of the "
                     f"grid's spacing: {why}")
    n0, jac, status, message = len(run.evaluated), first.jac, first.status, first.message
    try:
        run.run_nodes(points)
        new = min(run.evaluated[n0:], key=lambda e: e.chi2, default=None)
        if new is not None:
            sol = least_squares(run.residuals, new.x, bounds=outcome.box, max_nfev=100, **options)
            jac = sol.jac
    except spent:
        status, message = "budget", f"max_wall = {fmt_number(run.max_wall, 3)} s spent; the best point so far"
    after = best(run.evaluated)
    note = (f"a second pass, since {why}: {len(run.evaluated) - n0} runs (the cells of {len(centres)} nodes, the "
            "start, then the nodes on the data's period, then the best, at a quarter of the grid's spacing, and a "
            "least-squares fit from the best of them): ")
    if after.chi2 >= before.chi2:  # the verdicts stand (nothing identified); the note joins them
        low = min((e.chi2 for e in run.evaluated[n0:]), default=math.inf)
        return None, dataclasses.replace(outcome, notes=outcome.notes + (
            note + f"no better point (its best chi2 {fmt_number(low, 4)} against {fmt_number(before.chi2, 4)})",),
            status=status if status == "budget" else outcome.status,
            message=message if status == "budget" else outcome.message)
    note += ("it found a better point, " + ", ".join(f"{n} = {fmt_number(v, 5)}" for n, v in
                                                     zip(problem.names, values_of(problem.names, after.x)))
             + f" (chi2 {fmt_number(after.chi2, 4)} against {fmt_number(before.chi2, 4)})")
    return dataclasses.replace(first, jac=jac, status=status, message=message, notes=first.notes + (note,)), outcome
