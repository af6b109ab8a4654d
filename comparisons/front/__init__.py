"""Ensembles of peel fronts and their reproduction report (docs/peel-front.md, "Ensembles" and "Reproduction").

* :mod:`~comparisons.front.measure`: the sweep measure ``front`` (:func:`measure_front`, registered in
  :data:`comparisons.sweep.MEASURES` on import): pattern, fraction peeling, bursts, a chaos indicator;
* :mod:`~comparisons.front.ensemble`: :func:`front_ensemble`, seeds × V × γ × inertia ratio on the sweep
  engine (resumable, any executor: dask one argument away), and its result :class:`FrontEnsemble`;
* :mod:`~comparisons.front.report`: the reproduction report, ``python -m comparisons.front --size small|full``:
  pattern maps, burst exponents against V (one regime or two), the window of chaotic V, burst-exponent
  stability; figures and tables in one directory.
"""

from .ensemble import ENSEMBLE_COLUMNS, FrontEnsemble, front_ensemble, inertia_of_ratio
from .measure import FRONT_DEFAULTS, check_front_options, measure_front, twin_lyapunov

__all__ = ["front_ensemble", "FrontEnsemble", "ENSEMBLE_COLUMNS", "inertia_of_ratio", "FRONT_DEFAULTS",
           "measure_front", "check_front_options", "twin_lyapunov"]
