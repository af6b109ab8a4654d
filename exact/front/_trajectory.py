"""The result of :func:`exact.simulate_front`."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from peelapprox import ForceSeries, FrontParams, front_pattern
from peelapprox.io import optional_import

from .._trajectory import Jumps, SolverStats

if TYPE_CHECKING:  # the burst statistics load scipy.stats: imported when bursts() is called
    from peelapprox import BurstCatalogue

__all__ = ["FrontTrajectory", "LocalSwitches"]

#: The default burst threshold of :meth:`FrontTrajectory.bursts`, as a fraction of the largest stored AE power.
BURST_THRESHOLD_FRACTION = 0.05

_SERIES_UNITS = {"t": "s", "alpha": "rad", "omega": "rad/s", "F": "N", "v": "m/s", "ae_power": "W",
                 "ae_energy": "J", "fraction_peeling": "", "roughness": "", "domain_walls": "", "work_in": "J",
                 "work_peel": "J"}


@dataclass(frozen=True)
class LocalSwitches:
    """The strips' branch changes: ``t`` [s], ``strip`` (index j) and ``to_branch`` (0 = AB, 1 = CD) of each, in
    the order found (time order within a step, steps in order)."""

    t: np.ndarray
    strip: np.ndarray
    to_branch: np.ndarray

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True, eq=False)
class FrontTrajectory:
    """An orbit of the peel front (:func:`exact.simulate_front`).

    Time series, one entry per stored point (every accepted step, or the grid ``k dt_save``):

    * ``t`` [s]; the roller's ``alpha`` [rad] and ``omega`` [rad/s]; the pull force ``F`` = k ū [N] and the mean
      peel velocity ``v`` = v̄ [m/s];
    * ``ae_power`` [W]: the acoustic emission ``R_AE = Γ Σ_bonds (v_{j+1} - v_j)²``; ``ae_energy`` [J]: its
      integral ``E_AE``, a state of the integration (so a burst's energy is a difference of two values);
    * the front's pattern: ``fraction_peeling`` φ (strips with v_j > v_infl), ``roughness`` W = std_j ln v_j,
      ``domain_walls`` (bonds joining strips on different branches);
    * ``work_in`` [J] = ∫ F̄ V dt, the pull's work, and ``work_peel`` [J] = ∫ N⁻¹ Σ f(v_j) v_j dt, the energy
      dissipated at the peel front: states of the integration, so the energy balance
      ``ΔE = Δwork_in - Δwork_peel - Δae_energy`` holds to the solver's accuracy.

    The front itself, ``v_j`` [m/s] and ``u_j`` [m] (and ``F_j = k u_j`` [N]), arrays of shape (points, N), when
    stored (``store_front=True``, the default).  ``jumps``: the mean front's branch changes (v̄ crossing v_infl), as
    :func:`exact.simulate` reports the tape-mass model's (``Jumps``); ``local_switches``: every strip's.
    ``stats``: steps, rejected steps, field evaluations, mean jumps (all), wall time; ``n_local_switches`` all
    local switches (also before ``t_transient``).  ``final_y`` is the full state
    ``(α, ω, E_AE, F_j…, v_j…, W_in, W_peel)``
    at ``t_end`` (or where the run stopped), a valid start for another run (``y0=``).
    """

    params: FrontParams
    t: np.ndarray
    alpha: np.ndarray
    omega: np.ndarray
    F: np.ndarray
    v: np.ndarray
    ae_power: np.ndarray
    ae_energy: np.ndarray
    fraction_peeling: np.ndarray
    roughness: np.ndarray
    domain_walls: np.ndarray
    work_in: np.ndarray
    work_peel: np.ndarray
    front_F: np.ndarray | None
    front_v: np.ndarray | None
    jumps: Jumps
    local_switches: LocalSwitches
    stats: SolverStats
    n_local_switches: int
    rtol: float
    atol: np.ndarray
    t_end: float
    t_transient: float
    dt_save: float | None
    v_inflection: float
    initial_y: np.ndarray
    final_y: np.ndarray
    status: int
    message: str

    @property
    def v_j(self) -> np.ndarray | None:
        """Local peel velocities [m/s], shape (points, N) (None when the front was not stored)."""
        return self.front_v

    @property
    def u_j(self) -> np.ndarray | None:
        """Local stretches u_j = F_j / k [m], shape (points, N) (None when the front was not stored)."""
        return None if self.front_F is None else self.front_F / self.params.base.k

    @property
    def final_t(self) -> float:
        """The time of ``final_y``."""
        return float(self.t[-1]) if len(self.t) and self.status == 0 else float("nan")

    def ae_series(self) -> Any:
        """The AE power as a :class:`peelapprox.ForceSeries` (its ``F`` holds R_AE [W]) for the library's series
        tools: spectrum, return-map and embedding Lyapunov exponents, surrogates.  Those assume uniform sampling:
        run with ``dt_save``.  ValueError for a run stored at its steps or with too few points."""
        return self._series(self.ae_power, "AE power R_AE [W] of simulate_front")

    def force_series(self) -> Any:
        """The pull force F(t) as a :class:`peelapprox.ForceSeries` (uniform sampling: run with ``dt_save``)."""
        return self._series(self.F, "pull force of simulate_front")

    def _series(self, values: np.ndarray, source: str) -> Any:
        if self.dt_save is None:
            raise ValueError("the series tools need uniform sampling: run simulate_front with dt_save")
        return ForceSeries(self.t, values, V=self.params.base.V, source=source)

    def bursts(self, threshold: float | None = None, *, min_gap: float = 0.0) -> BurstCatalogue:
        """The bursts of the AE power R_AE (:func:`peelapprox.burst_catalogue` of ``t``, ``ae_power``; docs/bursts.md).

        Parameters
        ----------
        threshold : float, optional
            The AE power [W] a burst exceeds, finite and >= 0.  None (the default): 0.05 × the largest stored
            ``ae_power`` (``BURST_THRESHOLD_FRACTION``).  Why a fraction of the maximum: R_AE has no noise floor to
            set a level against (it is exactly 0 for N = 1 or a uniform front, and its stuck-phase level depends on
            γ and κ), while a fraction of the peak is scale-free and > 0 whenever there is any AE.  It depends on
            the largest burst of this record, so runs of different length or parameters are not cut at the same
            level: pass an explicit threshold to compare catalogues.  No AE at all: threshold 0, no bursts.
        min_gap : float
            Bursts closer than this [s] are merged (:func:`peelapprox.burst_catalogue`).

        Returns
        -------
        BurstCatalogue
            Energies in J (R_AE in W), times in s.

        Notes
        -----
        The catalogue integrates the piecewise-linear interpolant of the stored samples, which need not be uniform:
        a run stored at its accepted steps (no ``dt_save``) gives a valid catalogue, but its steps may be long
        against a burst's rise, so its peaks and energies are those of a coarser interpolant.  Run with a
        ``dt_save`` well below the bursts' duration for resolved bursts.  The state ``ae_energy`` is exact;
        a burst's ``energy`` agrees with its difference over [start, end] to the interpolation's accuracy.

        Raises
        ------
        ValueError
            A threshold that is not a finite number >= 0, a negative ``min_gap``, fewer than 2 stored points.
        """
        if threshold is None:
            top = float(np.max(self.ae_power)) if len(self.ae_power) else 0.0
            level = BURST_THRESHOLD_FRACTION * top
        else:
            if isinstance(threshold, bool) or not isinstance(threshold, (int, float, np.integer, np.floating)):
                raise TypeError(f"threshold must be a real number >= 0 [W] or None, got {threshold!r}")
            level = float(threshold)
            if not np.isfinite(level) or level < 0:
                raise ValueError(f"threshold must be a finite AE power >= 0 [W] or None, got {threshold!r}")
        from peelapprox import burst_catalogue

        cat = burst_catalogue(self.t, self.ae_power, threshold=level, min_gap=min_gap)
        return dataclasses.replace(cat, source=f"AE power of simulate_front (N={self.params.N}); {cat.source}")

    def pattern(self, **thresholds: Any) -> Any:
        """The front's pattern class over the stored points (:func:`peelapprox.front_pattern`)."""
        return front_pattern(self.t, self.fraction_peeling, self.roughness, self.domain_walls, **thresholds)

    def to_dataframe(self) -> Any:
        """The time series as a pandas DataFrame (units in ``df.attrs["units"]``); needs pandas."""
        pd = optional_import("pandas", "FrontTrajectory.to_dataframe")
        df = pd.DataFrame({c: getattr(self, c) for c in _SERIES_UNITS})
        df.attrs["units"] = dict(_SERIES_UNITS)
        df.attrs["params"] = self.params.as_dict()
        return df

    def __repr__(self) -> str:
        return (f"FrontTrajectory(N={self.params.N}, points={len(self.t)}, t_end={self.t_end!r}, "
                f"jumps={len(self.jumps)}, local_switches={self.n_local_switches}, steps={self.stats.n_steps}, "
                f"status={self.status}, message={self.message!r})")
