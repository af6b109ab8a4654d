"""The regime labels of :func:`peelapprox.estimate`: the rules, and the labels of a point without the branch
quadratures (:func:`regime`, which the reduced return map reads to pick its default reductions).

Kept apart from :mod:`peelapprox._reduced._estimate` so that the approximate attractor (which reads the labels) and the
estimate (which offers the approximate attractor) import it, not each other.
"""

from __future__ import annotations

from .._params import PeelParams
from ..law import BranchStructure, FixedPoint, branch_structure, fixed_point
from ..validate import params as _params
from ._alpha import InertialPeriods, cd_damping_time, inertial_periods

__all__ = ["INERTIA_RULE", "VELOCITY_RULE", "regime"]

#: How :func:`estimate` labels inertia (stated once, printed by the CLI).
INERTIA_RULE = (
    "r = T_mean / tau_CD, the inertial period 2*pi*sqrt(I/(F_mean R)) over the CD damping time R f'(v_land_cd)/F_mean "
    "(coefficient of Airy2): low if r < 1 (alpha oscillates freely through the short CD stays: Case I), "
    "intermediate if 1 <= r < 5, high if r >= 5 (CD stays damp alpha-dot and alpha sweeps slowly on AB: Case II)"
)
#: How :func:`estimate` labels the pull speed.
VELOCITY_RULE = (
    "stable if f'(V,V) > 0 (fixed point stable, no stick-slip; Hopf criterion); otherwise g = (f_max - f_min)/f_max: "
    "low V if g >= 0.1, high V if g < 0.1 (f nearly flat: a peel angle of 0.1 rad changes F = f/(1+sin alpha) by "
    "more than the fold window, so alpha sets the force bounds: Case III)"
)


def _checked(params: PeelParams, where: str) -> PeelParams:
    """``params`` validated, any law (ValueError naming ``params.force`` for a law whose folds cannot be found),
    the paper's model only (ValueError naming ``params.tape_mass`` / ``params.loading`` for a variant, and
    ``where``, the public function called)."""
    return _params("params", params, where=where, variants=False)


def _law_structure(params: PeelParams) -> BranchStructure:
    """The law's branch structure at V (:func:`peelapprox.branch_structure` with ``force=params.force``)."""
    return branch_structure(params.V, force=params.force)


def _labels(params: PeelParams, bs: BranchStructure, fp: FixedPoint
            ) -> tuple[InertialPeriods, float, float, str, float, str]:
    """The regime labels of :data:`INERTIA_RULE` and :data:`VELOCITY_RULE` at a point with folds, and the numbers
    they are read from: ``(periods, tau_cd, ratio, inertia, gap, velocity)``."""
    assert bs.f_max is not None and bs.f_min is not None  # the caller's: has_folds
    if not bs.f_min > 0.0:  # a law with a negative dip: no inertial period at F = f_min (sqrt(F R / I))
        raise ValueError(f"params.force: {params.force!r} at V={params.V} has its lower fold force f_min={bs.f_min} N "
                         "not positive (the pull force would reach 0 before the CD->AB jump): no stick-slip regime; "
                         "choose coefficients with f > 0 on the folds")
    per = inertial_periods(params)
    if bs.v_land_cd is None:  # a table that stops below f_max on CD: no AB->CD landing, no CD damping time
        raise ValueError(f"params.force: {params.force!r} at V={params.V} never reaches f_max={bs.f_max} N on its "
                         "fast branch within its domain: an AB->CD jump could not land (extend the table)")
    tau_cd = cd_damping_time(params, per.F_mean, bs.v_land_cd)
    ratio = per.at_mean / tau_cd
    inertia = "low" if ratio < 1.0 else ("intermediate" if ratio < 5.0 else "high")
    gap = (bs.f_max - bs.f_min) / bs.f_max
    velocity = "stable" if fp.stable else ("low" if gap >= 0.1 else "high")
    return per, tau_cd, ratio, inertia, gap, velocity


def regime(params: PeelParams) -> tuple[str, str]:
    """``(inertia, velocity)``: the labels of :func:`estimate` (:data:`INERTIA_RULE`, :data:`VELOCITY_RULE`)
    without its branch times and bounds; ``("n/a", "stable")`` where the law has no folds at V.

    Raises
    ------
    ValueError
        As :func:`estimate`, for a law whose folds or CD landing cannot be found.
    """
    params = _checked(params, "regime")
    bs = _law_structure(params)
    fp = fixed_point(params.V, params.R, force=params.force)
    if not bs.has_folds:
        return "n/a", "stable"
    _, _, _, inertia, _, velocity = _labels(params, bs, fp)
    return inertia, velocity
