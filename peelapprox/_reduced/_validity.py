"""How often the approximate attractor is right, as the atlas measured it: the validity :func:`peelapprox.estimate`
reports.

The numbers are the ``approx:default`` rows of ``docs/atlas/atlas_regimes.csv``, written by the atlas of the paper's
law (``peelapprox atlas --V 0.2:5:40 --I 1e-6:1e-1:40:log --out DIR``, then ``load_atlas(DIR).write_tables(DIR)``;
docs/atlas.md): :func:`peelapprox.approximate_attractor` with its defaults against the exact attractor (100 s of
transient, 20 s measured) on the 40 x 40 grid over V in [0.2, 5] m/s and I in [1e-6, 1e-1] kg m^2, k = 1000 N/m,
R = 0.1 m.  Per regime label of :func:`peelapprox.estimate`: the exact stick-slip points with that label and the
fraction of them where the predicted slip interval, force drop, and both, are within 10 % of the exact ones.  A
test checks that this table equals the file; a new atlas is copied here by hand, with the file.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["SOURCE", "VALIDITY", "Validity", "validity_text"]

#: Where the numbers come from (the module docstring's command), as a reader of :attr:`RegimeEstimate.validity`
#: is told.
SOURCE = ("the atlas of the paper's law, 40 x 40 over V in [0.2, 5] m/s and I in [1e-6, 1e-1] kg m^2, k = 1000 N/m, "
          "R = 0.1 m: docs/atlas.md")


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
    'high inertia, high V': Validity(315, 0.5079365079365079, 0.49206349206349204, 0.4666666666666667, 0, 0.0),
    'high inertia, low V': Validity(345, 0.7420289855072464, 0.8521739130434782, 0.7130434782608696, 0, 0.0),
    'intermediate inertia, high V': Validity(153, 0.9150326797385621, 0.9215686274509803, 0.9150326797385621, 0, 0.0),
    'intermediate inertia, low V': Validity(231, 0.8008658008658008, 0.8225108225108225, 0.7965367965367965, 0, 0.0),
    'low inertia, high V': Validity(92, 0.9891304347826086, 0.9891304347826086, 0.9891304347826086, 0, 0.0),
    'low inertia, low V': Validity(283, 0.9399293286219081, 0.9363957597173145, 0.9363957597173145, 0, 0.0),
    'no stick-slip (stable fixed point)': Validity(23, 0.782608695652174, 0.782608695652174, 0.6521739130434783, 0, 0.0),
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
