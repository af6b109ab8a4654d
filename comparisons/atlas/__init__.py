"""Where the approximations hold: the (V, I) atlas of the exact attractor against every approximation's
prediction and every reduction's exact-seeded error (``peelapprox atlas``; docs/atlas.md).

:func:`atlas` runs three measures at every grid point on the sweep engine (resumable after a kill, a process
pool or a dask cluster; :mod:`comparisons.sweep`): the exact attractor's
:class:`peelapprox.StickSlipObservables` and class, each reduction of the harness on the window's last exact
stays, and every approximation of :data:`APPROXIMATIONS` (name -> ``fn(params)``; ``"estimate"``'s
quasi-static cycle and ``"approx:default"``, :func:`peelapprox.approximate_attractor`).  :class:`AtlasResult`
gives the relative errors ``|predicted - exact| / |exact|`` where both stick-slip as masked maps saying why each
undefined cell is undefined, summaries (the share within 10 %), tables (CSV/JSON), an xarray Dataset and the
maps.  No status or value is NaN: a point without stick-slip, a breakdown or a failed prediction is a status
with its reason.

Modules: :mod:`~comparisons.atlas.approximations` (the registry, :func:`register_approximation`),
:mod:`~comparisons.atlas.measures` (the three measures and the options, :data:`DEFAULTS`),
:mod:`~comparisons.atlas.engine` (:func:`atlas`), :mod:`~comparisons.atlas.result` (:class:`AtlasResult`,
:func:`load_atlas`), :mod:`~comparisons.atlas.plots` (the maps), :mod:`~comparisons.atlas.cost`
(:func:`atlas_cost`: each part's cost per point, measured, and the projected time),
:mod:`~comparisons.atlas.sets` (opt-in, ``atlas(..., sets=True)``: the exact attractor set against the predicted
set at each point, :func:`match_set`, :data:`SET_DEFAULTS`).
"""

from .approximations import APPROXIMATIONS, OBSERVABLES, TOLERANCE, estimate_observables, register_approximation
from .cost import AtlasCost, atlas_cost
from .engine import atlas
from .measures import DEFAULTS
from .plots import (
    plot_confidence_map,
    plot_dynamics_map,
    plot_error_map,
    plot_multistability_map,
    plot_segment_maps,
    write_maps,
)
from .result import AtlasResult, load_atlas
from .sets import SET_DEFAULTS, match_set

__all__ = ["atlas", "AtlasResult", "load_atlas", "APPROXIMATIONS", "register_approximation", "OBSERVABLES",
           "DEFAULTS", "TOLERANCE", "estimate_observables", "plot_error_map", "plot_dynamics_map",
           "plot_segment_maps", "write_maps", "atlas_cost", "AtlasCost", "match_set", "SET_DEFAULTS",
           "plot_multistability_map", "plot_confidence_map"]
