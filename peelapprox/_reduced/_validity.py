"""How often the approximate attractor is right, as measured on the atlas's grid: the validity
:func:`peelapprox.estimate` reports, and the calibration of the confidence rule that reads it.

The numbers are the rows of ``docs/atlas/approx_grid_regimes.csv``, written by
``python -m comparisons.benchmark.approx_grid --n 40 --tables docs/atlas`` (docs/atlas.md, "The 40 x 40 grid against
the exact set"): :func:`peelapprox.approximate_attractor` with its defaults on the atlas's 40 x 40 grid over V in
[0.2, 5] m/s and I in [1e-6, 1e-1] kg m^2, k = 1000 N/m, R = 0.1 m, against :func:`exact.attractor_observables`
(30 s of transient, 20 s measured) from the solver's start and, where they can change the answer, four more starts.
Per regime label of :func:`peelapprox.estimate`: the points whose solver's start stick-slips, the fraction of them
where the predicted slip interval, force drop, and both, are within 10 % of that start's attractor
(``approx:default``), and the points no confidence rule but this table's flags with the fraction of them whose
prediction matches some attractor of the set (``approx:default:unflagged``).  The table is written by
``python -m comparisons.atlas.validity --from docs/atlas/approx_grid_regimes.csv``, never by hand; a test checks it
equals the file.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["SOURCE", "VALIDITY", "Validity", "validity_text"]

#: Where the numbers come from (the module docstring's command), as a reader of :attr:`RegimeEstimate.validity`
#: is told.
SOURCE = ("the atlas's 40 x 40 grid of V and I against the exact set (benchmark approx_grid): docs/atlas.md")


class Validity(NamedTuple):
    """The measured accuracy of the default approximate attractor in one regime."""

    points: int
    """Stick-slip points of the exact solution with this label."""
    slip_interval: float
    """Fraction of them with the predicted slip interval within 10 % of the exact one."""
    force_drop: float
    """The same for the force drop."""
    both: float
    """The same for both at once."""
    unflagged_points: int = 0
    """Stick-slip points of this label where no confidence rule but this table's flags the prediction (0: not
    measured)."""
    unflagged_match: float = 0.0
    """Fraction of those whose prediction matches an attractor of the exact set (both within 10 %): the
    calibration the regime rule of :func:`peelapprox._reduced._approx_result.confidence` reads."""


#: Per regime label (:attr:`peelapprox.RegimeEstimate.label`).
VALIDITY: dict[str, Validity] = {
    'high inertia, high V': Validity(315, 0.8825396825396825, 0.8507936507936508, 0.8380952380952381,
                                     195, 0.9333333333333333),
    'high inertia, low V': Validity(345, 0.9855072463768116, 0.8927536231884058, 0.8927536231884058,
                                    239, 1.0),
    'intermediate inertia, high V': Validity(153, 0.9934640522875817, 0.9934640522875817, 0.9934640522875817,
                                             151, 1.0),
    'intermediate inertia, low V': Validity(231, 0.961038961038961, 0.961038961038961, 0.961038961038961,
                                            203, 0.9802955665024631),
    'low inertia, high V': Validity(92, 1.0, 1.0, 1.0,
                                    92, 1.0),
    'low inertia, low V': Validity(283, 0.9858657243816255, 0.9858657243816255, 0.9858657243816255,
                                   282, 0.9929078014184397),
    'no stick-slip (stable fixed point)': Validity(23, 1.0, 1.0, 1.0,
                                                   23, 1.0),
}


def validity_text(label: str) -> dict[str, str]:
    """``{observable: sentence}`` for a regime label: "within 10 % of the exact attractor on 77 % of the 283
    'low inertia, low V' points measured (...)"; a label not measured says so."""
    v = VALIDITY.get(label)
    if v is None or v.points == 0:
        return {name: f"not measured for {label!r} points" for name in ("slip_interval", "force_drop")}
    return {name: (f"within 10 % of the exact attractor on {100 * frac:.0f} % of the {v.points} {label!r} points "
                   f"measured ({SOURCE})") for name, frac in (("slip_interval", v.slip_interval),
                                                             ("force_drop", v.force_drop))}
