"""Burst catalogues and their statistics: the bursts of any power time series (an acoustic-emission power, a
dissipation rate) or a measured catalogue, and power-law fits of their sizes.

The modules (private: the public names are offered by :mod:`peelapprox`):

* ``_catalogue`` — :func:`burst_catalogue` (threshold crossings of a sampled power) and :class:`BurstCatalogue`
  (its table; :meth:`BurstCatalogue.from_csv` for a measured AE or force-drop catalogue);
* ``_laws`` — the power law's likelihood, maximum and KS distance (continuous, or exact discrete); ``_scan`` —
  the bounded KS scan for xmin;
* ``_fit`` — :func:`fit_power_law` and :class:`PowerLawFit` (bootstrap intervals, goodness of fit);
* ``_alternatives`` — :func:`compare_power_law` and :class:`LikelihoodRatio` (lognormal, exponential, truncated
  power law; Vuong's test, the nested χ̄² test); ``_discrete`` — the same laws on the integers, for a discrete fit;
* ``_broken`` — :func:`fit_broken_power_law` and :class:`BrokenPowerLawFit` (two regimes against one).

The chapter is ``docs/bursts.md``.
"""

from __future__ import annotations

from ._alternatives import ALTERNATIVES, LikelihoodRatio, compare_power_law
from ._broken import BrokenPowerLawFit, fit_broken_power_law
from ._catalogue import BURST_COLUMNS, BurstCatalogue, burst_catalogue
from ._fit import MAX_XMIN_CANDIDATES, PowerLawFit, fit_power_law

__all__ = ["ALTERNATIVES", "BURST_COLUMNS", "BrokenPowerLawFit", "BurstCatalogue", "LikelihoodRatio",
           "MAX_XMIN_CANDIDATES", "PowerLawFit", "burst_catalogue", "compare_power_law", "fit_broken_power_law",
           "fit_power_law"]
