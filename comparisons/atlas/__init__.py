"""Where the approximations hold: the (V, I) atlas of the exact attractor against every approximation's
prediction and every reduction's exact-seeded error (``peelapprox atlas``).

``atlas(I_values, V_values, *, out, approximations=None, force=None, k=None, R=None, options=None, ...)
-> AtlasResult`` runs three sweep measures (:mod:`comparisons.atlas.measures`) at every grid point on the sweep
engine (:mod:`comparisons.sweep`: resumable after a kill, a local process pool or a dask cluster, progress on
stderr, a manifest):

* ``atlas_exact`` — the exact attractor's :class:`peelapprox.StickSlipObservables`
  (:func:`exact.attractor_observables`, 100 s of transient then 20 s measured, rtol 1e-10) and its class:
  ``period-n``, ``aperiodic``, ``too short`` where it stick-slips; ``steady``, ``transient``, ``too few slips``,
  ``breakdown`` (with the reason) where it does not;
* ``atlas_segments`` — each reduction of the harness (:data:`comparisons.DEFAULT_MODELS`, an α model and a v
  equation per branch) on the window's last 8 complete stays of each branch, seeded from their exact entries
  (:func:`comparisons.compare`): per point the median and worst ``|Δt|`` and ``|ΔF|`` relative errors;
* ``atlas_approx`` — every approximation of :data:`APPROXIMATIONS` (name -> ``fn(params)`` returning a
  :class:`peelapprox.StickSlipObservables` or a dict of its fields; ``"estimate"``: the quasi-static cycle
  :func:`peelapprox.estimate` predicts; ``"approx:default"``: ``peelapprox.approximate_attractor``, skipped
  while it is not importable) and :func:`peelapprox.estimate`'s regime label.

:class:`AtlasResult` computes the relative errors (``|predicted - exact| / |exact|`` where both stick-slip),
gives them as masked maps with why each undefined cell is undefined, summaries (the share within 10 % over the
exact stick-slip points), tables (``points``, ``errors``, ``segments``, ``summary``; CSV/JSON), an xarray
Dataset and the maps (:mod:`comparisons.atlas.plots`).  No status or value is ever NaN: a point without
stick-slip, a breakdown, a prediction that failed is a status with its reason.

Modules
-------
:mod:`~comparisons.atlas.approximations`
    The registry :data:`APPROXIMATIONS`, :func:`register_approximation`, the observables compared.
:mod:`~comparisons.atlas.measures`
    The three sweep measures and the atlas's options (:data:`DEFAULTS`).
:mod:`~comparisons.atlas.engine`
    :func:`atlas`.
:mod:`~comparisons.atlas.result`
    :class:`AtlasResult`, :func:`load_atlas`.
:mod:`~comparisons.atlas.plots`
    The maps.
:mod:`~comparisons.atlas.cost`
    :func:`atlas_cost`: each part's cost per point, measured at sample points, and the projected time.
"""

from .approximations import APPROXIMATIONS, OBSERVABLES, TOLERANCE, estimate_observables, register_approximation
from .cost import AtlasCost, atlas_cost
from .engine import atlas
from .measures import DEFAULTS
from .plots import plot_dynamics_map, plot_error_map, plot_segment_maps, write_maps
from .result import AtlasResult, load_atlas

__all__ = ["atlas", "AtlasResult", "load_atlas", "APPROXIMATIONS", "register_approximation", "OBSERVABLES",
           "DEFAULTS", "TOLERANCE", "estimate_observables", "plot_error_map", "plot_dynamics_map",
           "plot_segment_maps", "write_maps", "atlas_cost", "AtlasCost"]
