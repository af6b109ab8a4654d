"""The exact runs behind the paper's scenes: parameters, initial state, transient, window, and the check
that the stored window is past the transient.

Every scene reads one of :data:`RUNS`; :func:`exact_run` integrates each at most once per process
(``functools.lru_cache``), so scenes that share a simulation share the run.  A run stores its
window with ``save="steps"`` (the α periods and the Fig. 8/9 overlays need the step points, not
dense output) and nothing before ``t_transient``.

How a run proves it is past the transient (:func:`check_past_transient`)
------------------------------------------------------------------------
The sequence ``x_j`` of pull forces at the AB→CD jumps in the stored window is tested for

* **periodicity**: the smallest ``n`` with ``max_j |x_{j+n} - x_j| <= rtol · max|x|`` over the
  whole window (at least two repeats of the ``n``-jump pattern), or else
* **stationarity**: the envelopes ``(min x, max x)`` of the two halves of the window agree to
  ``envelope_tol`` of the range of ``x``.

If neither holds the run raises :class:`TransientNotPassed` (the window is still drifting; the
transient must be longer).  The defaults are measured, not guessed: at V=1, I=1e-2 the period-8
pattern holds to 1e-6 from t ≈ 24 s; at V=4, I=1e-2 from α0 = 0.3 the orbit settles on its large
attractor by t ≈ 12 s, but from the default α0 = 0 a slowly growing small oscillation lasts ≈ 70 s
(``docs/paper-notes.md``), which is why that run names its initial angle.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import numpy as np

from exact import Trajectory, simulate
from peelapprox import PeelForce, PeelParams, periodicity

from ._segments import Segment, segments

__all__ = ["RunSpec", "RUNS", "ExactRun", "exact_run", "check_past_transient", "TransientNotPassed",
           "TransientCheck"]


class TransientNotPassed(RuntimeError):
    """The stored window of an exact run is neither periodic nor stationary: the transient is not over.

    Attributes ``t_transient`` [s], ``window`` [s] and ``detail`` (the measured numbers).
    """

    def __init__(self, message: str, *, t_transient: float, window: float, detail: dict):
        super().__init__(message)
        self.t_transient = t_transient
        self.window = window
        self.detail = detail


@dataclass(frozen=True)
class TransientCheck:
    """Outcome of :func:`check_past_transient`: ``kind`` is "periodic" (``period`` jumps AB→CD per
    repeat, ``mismatch`` the largest relative recurrence error) or "stationary" (``mismatch`` the
    envelope difference relative to the range)."""

    kind: str
    period: int | None
    mismatch: float
    n_jumps: int

    def describe(self) -> str:
        if self.kind == "periodic":
            return (f"periodic: the F sequence at AB→CD jumps repeats every {self.period} jumps to "
                    f"{self.mismatch:.1e} (relative), over {self.n_jumps} jumps")
        return (f"stationary: the F envelope at AB→CD jumps agrees between the window's halves to "
                f"{self.mismatch:.1e} of its range, over {self.n_jumps} jumps")


def check_past_transient(trajectory, *, rtol: float = 1e-6, envelope_tol: float = 0.02) -> TransientCheck:
    """Check that an exact trajectory's stored window is past the transient.

    Parameters
    ----------
    trajectory : exact.Trajectory
    rtol : float
        Relative recurrence tolerance of the periodicity test (module docstring).
    envelope_tol : float
        Allowed envelope difference between the window halves, as a fraction of the range.

    Raises
    ------
    TransientNotPassed
        If the window has fewer than 6 AB→CD jumps, or is neither periodic nor stationary.
    """
    J = trajectory.jumps
    x = np.asarray(J.F)[np.asarray(J.from_branch) == 0]
    ctx = dict(t_transient=trajectory.t_transient, window=trajectory.t_end - trajectory.t_transient)
    if len(x) < 6:
        raise TransientNotPassed(f"only {len(x)} AB→CD jumps in the stored window: too short to judge",
                                 detail={"n_jumps": len(x)}, **ctx)
    per = periodicity(x, rtol=rtol, max_period=len(x) // 2, min_repeats=1)
    if per.kind == "periodic":
        return TransientCheck("periodic", per.period, per.mismatch, len(x))
    h = len(x) // 2
    rng = float(np.ptp(x)) or float(np.max(np.abs(x)))
    mis = max(abs(x[:h].min() - x[h:].min()), abs(x[:h].max() - x[h:].max())) / rng
    if mis <= envelope_tol:
        return TransientCheck("stationary", None, mis, len(x))
    raise TransientNotPassed(
        f"window [{ctx['t_transient']}, {trajectory.t_end}] s is not past the transient: no period "
        f"<= {len(x) // 2} jumps repeats to {rtol:g}, and the F envelope at AB→CD jumps differs by "
        f"{mis:.3g} of its range between the halves (> {envelope_tol:g})",
        detail={"n_jumps": len(x), "envelope_mismatch": mis}, **ctx)


@dataclass(frozen=True)
class RunSpec:
    """One exact simulation shared by scenes.

    ``alpha0`` is the initial peel angle (the rest of the initial state is
    :func:`exact.initial_state`'s default), ``t_transient`` [s] is integrated
    and discarded, ``window`` [s] is stored, ``rtol`` is the hybrid solver's,
    ``force`` the peel-force law (default the paper's fvV: the runs of
    :data:`RUNS`); a run of another law is passed to :func:`exact_run` (and
    :func:`comparisons.statistics`) as its RunSpec, and every reduction of
    its segments is seeded from that law's exact run and integrated with
    that law.
    """

    name: str
    V: float
    I: float
    t_transient: float
    window: float
    alpha0: float = 0.0
    rtol: float = 1e-10
    regime: str = ""
    force: PeelForce = PeelForce.paper()

    @property
    def params(self) -> PeelParams:
        return PeelParams(V=self.V, I=self.I, force=self.force)


#: The runs of the paper's three cases (Sec. V) and an intermediate-inertia point for the statistics.
RUNS = {r.name: r for r in (
    RunSpec("V1-I1e-5", V=1.0, I=1e-5, t_transient=10.0, window=2.0, regime="Case I: low inertia, low V"),
    RunSpec("V1-I1e-3", V=1.0, I=1e-3, t_transient=30.0, window=2.0, regime="intermediate inertia, low V"),
    RunSpec("V1-I1e-2", V=1.0, I=1e-2, t_transient=30.0, window=1.0, regime="Case II: high inertia, low V"),
    RunSpec("V4-I1e-2", V=4.0, I=1e-2, t_transient=20.0, window=1.0, alpha0=0.3,
            regime="Case III: high inertia, high V"),
)}


@dataclass(frozen=True)
class ExactRun:
    """A finished run: its spec, trajectory, complete segments, transient check and wall time [s]."""

    spec: RunSpec
    trajectory: Trajectory
    segments: list[Segment]
    transient: TransientCheck
    wall_time: float

    def __repr__(self) -> str:
        """One line: the run's name, the segments' count, the transient check and the wall time (the segments
        themselves are in ``segments``; printing each made the repr pages long)."""
        return (f"ExactRun({self.spec.name!r}: V={self.spec.V:g} m/s, I={self.spec.I:g} kg m^2, "
                f"{len(self.segments)} segments, {len(self.trajectory.jumps)} jumps, transient {self.transient.kind}, "
                f"{self.wall_time:.3g} s)")


def exact_run(name: str | RunSpec) -> ExactRun:
    """The exact run ``RUNS[name]`` (or the run a :class:`RunSpec` describes, of any peel-force law), integrated
    once per process and checked past its transient.

    Raises
    ------
    ValueError
        Unknown ``name`` (the valid names are listed); a law the hybrid solver cannot run (naming
        ``params.force``).
    TransientNotPassed
        See :func:`check_past_transient`.
    """
    if isinstance(name, RunSpec):
        return _exact_run(name)
    if name not in RUNS:
        raise ValueError(f"run must be one of {sorted(RUNS)} or a RunSpec, got {name!r}")
    return _exact_run(RUNS[name])


@functools.cache
def _exact_run(spec: RunSpec) -> ExactRun:
    """:func:`exact_run` of one spec (cached per spec: equal specs share the run)."""
    t0 = time.perf_counter()
    tr = simulate(spec.params, spec.t_transient + spec.window, alpha0=spec.alpha0, rtol=spec.rtol,
                  t_transient=spec.t_transient, save="steps")
    check = check_past_transient(tr)
    segs = segments(tr)
    return ExactRun(spec, tr, segs, check, time.perf_counter() - t0)
