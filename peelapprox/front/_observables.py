"""The peel front's patterns: time averages of the front's roughness, mixing and domain walls, and the class
they put it in (docs/peel-front.md, "Observables")."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import in_range

__all__ = ["FrontPattern", "front_pattern", "PATTERN_THRESHOLDS", "PATTERN_CLASSES"]

#: Default thresholds of :func:`front_pattern` (the design study's, to be revisited with measurements).
PATTERN_THRESHOLDS = {"w_smooth": 0.05, "mix_smooth": 0.01, "mix_stuck": 0.10, "walls_stuck": 2.0}
#: The classes, in the order the rules are tried.
PATTERN_CLASSES = ("smooth", "stuck-peeled", "rugged", "unclassified")


@dataclass(frozen=True)
class FrontPattern:
    """The class of a front's orbit and the averages it rests on.

    Attributes
    ----------
    label : str
        One of :data:`PATTERN_CLASSES`.
    roughness : float
        ⟨W⟩, the time average of ``W = std_j ln v_j``.
    mixed_fraction : float
        Φ_mix, the fraction of the time with ``0 < φ < 1`` (some strips on AB, some on CD).
    walls : float
        ⟨n_dw⟩ over the mixed time: the mean number of domain walls while the front is mixed (0 if never).
    duration : float
        The time span averaged over [s].
    thresholds : dict
        The thresholds used.
    """

    label: str
    roughness: float
    mixed_fraction: float
    walls: float
    duration: float
    thresholds: dict


def _weights(t: np.ndarray) -> np.ndarray:
    """Trapezoid weights of the points t (the stored points of an adaptive run are not equally spaced)."""
    w = np.zeros_like(t)
    if t.size > 1:
        d = np.diff(t)
        w[:-1] += d / 2
        w[1:] += d / 2
    return w


def front_pattern(t: Any, fraction_peeling: Any, roughness: Any, domain_walls: Any, *, w_smooth: float = 0.05,
                  mix_smooth: float = 0.01, mix_stuck: float = 0.10, walls_stuck: float = 2.0) -> FrontPattern:
    """Classify a front's orbit as smooth, rugged or stuck-peeled (the classes of Kumar, De & Ananthakrishna,
    PRE 78, 066119 (2008); the rules are ours, docs/peel-front.md).

    Rules, tried in order, with time averages weighted by the trapezoid rule over the points:

    * **smooth**: ``⟨W⟩ < w_smooth`` and ``Φ_mix < mix_smooth``: the strips move together;
    * **stuck-peeled**: ``Φ_mix ≥ mix_stuck`` and ``⟨n_dw⟩ ≥ walls_stuck`` (over the mixed time): stuck and
      peeling domains side by side for a sizeable part of the time;
    * **rugged**: ``⟨W⟩ ≥ w_smooth`` and ``Φ_mix < mix_stuck``: a rough front that still jumps nearly as one;
    * otherwise **unclassified** (say, a rough front mixed for long with a single wall).

    Parameters
    ----------
    t, fraction_peeling, roughness, domain_walls : array_like
        The series of a :class:`exact.FrontTrajectory` (``t``, φ, W, n_dw), equal lengths, at least 2 points.
    w_smooth, mix_smooth, mix_stuck, walls_stuck : float
        The thresholds (defaults :data:`PATTERN_THRESHOLDS`); ``w_smooth`` > 0, the fractions in (0, 1],
        ``walls_stuck`` ≥ 0.

    Returns
    -------
    FrontPattern

    Raises
    ------
    ValueError
        Arrays of unequal lengths, fewer than 2 points, non-finite values, a threshold out of range.
    """
    th = {"w_smooth": in_range("w_smooth", w_smooth, 0.0, 1e3, lo_open=True),
          "mix_smooth": in_range("mix_smooth", mix_smooth, 0.0, 1.0, lo_open=True),
          "mix_stuck": in_range("mix_stuck", mix_stuck, 0.0, 1.0, lo_open=True),
          "walls_stuck": in_range("walls_stuck", walls_stuck, 0.0, 1e9)}
    arrs = [np.asarray(a, dtype=float).ravel() for a in (t, fraction_peeling, roughness, domain_walls)]
    names = ("t", "fraction_peeling", "roughness", "domain_walls")
    for name, a in zip(names, arrs):
        if a.size != arrs[0].size:
            raise ValueError(f"{name} must have as many points as t ({arrs[0].size}), got {a.size}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite")
    tt, phi, W, ndw = arrs
    if tt.size < 2 or not tt[-1] > tt[0]:
        raise ValueError(f"t must hold at least 2 increasing points, got {tt.size}")
    w = _weights(tt)
    span = float(tt[-1] - tt[0])
    mixed = (phi > 0.0) & (phi < 1.0)
    W_mean = float(np.sum(w * W) / span)
    mix = float(np.sum(w[mixed]) / span)
    wm = float(np.sum(w[mixed]))
    walls = float(np.sum(w[mixed] * ndw[mixed]) / wm) if wm > 0.0 else 0.0
    if W_mean < th["w_smooth"] and mix < th["mix_smooth"]:
        label = "smooth"
    elif mix >= th["mix_stuck"] and walls >= th["walls_stuck"]:
        label = "stuck-peeled"
    elif W_mean >= th["w_smooth"] and mix < th["mix_stuck"]:
        label = "rugged"
    else:
        label = "unclassified"
    return FrontPattern(label, W_mean, mix, walls, span, th)
