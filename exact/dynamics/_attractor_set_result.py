"""What :func:`exact.attractor_set` returns: the starts, their outcomes, the attractors and the set.

:class:`SetStart` is one start, :class:`SetOutcome` what one start's run reached, :class:`SetAttractor` one attractor
of the set (with its observables, share and stability) and :class:`AttractorSet` all of it, with the counters, the
table (:meth:`AttractorSet.to_dataframe`), a plot of each attractor's return map and
:meth:`AttractorSet.closest`, the attractor nearest to given observables.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from peelapprox import PeelParams, StickSlipObservables
from peelapprox.io import fmt_number, jsonable, optional_import
from peelapprox.validate import ArgumentTypeError, in_range, real

from ._escape import EscapePrediction

__all__ = ["KINDS", "SET_STATUSES", "OUTCOMES", "SetStart", "SetOutcome", "SetAttractor", "AttractorSet"]

#: The classes of :attr:`SetAttractor.kind`.
KINDS = ("periodic", "quasi-periodic", "chaotic", "aperiodic", "steady", "breakdown")
#: The values of :attr:`AttractorSet.status`.
SET_STATUSES = ("ok", "transient only", "breakdown only", "max_wall", "no attractor")
#: The values of :attr:`SetOutcome.outcome`.
OUTCOMES = ("attractor", "transient", "breakdown", "invalid start", "failure", "max_wall")


@dataclass(frozen=True)
class SetStart:
    """One start of :func:`exact.attractor_set`: a name and the initial state's free values (None: the
    :func:`exact.initial_state` default: ω = V/R, F = 1.01 f(V, V), the branch with the lowest root)."""

    name: str
    alpha0: float = 0.0
    omega0: float | None = None
    F0: float | None = None
    branch0: str | None = None

    def kwargs(self) -> dict[str, Any]:
        """The keywords of :func:`exact.initial_state` and :func:`exact.simulate` for this start."""
        kw: dict[str, Any] = {"alpha0": self.alpha0}
        for name in ("omega0", "F0", "branch0"):
            if getattr(self, name) is not None:
                kw[name] = getattr(self, name)
        return kw

    @property
    def alpha_only(self) -> bool:
        """True when only α0 is set (the start :func:`exact.lyapunov` can run from)."""
        return self.omega0 is None and self.F0 is None and self.branch0 is None


@dataclass(frozen=True)
class SetOutcome:
    """What one start reached.

    Attributes
    ----------
    start : SetStart
    outcome : str
        One of :data:`OUTCOMES`: ``"attractor"`` (``attractor`` is its id), ``"transient"`` (the run still sits on
        an unstable orbit at the end of its transient, ``escape`` its predicted escape; or its jumps stop),
        ``"breakdown"`` (a ``ModelBreakdown``; its attractor entry is of kind ``"breakdown"``), ``"invalid
        start"`` (no consistent state there), ``"failure"`` (the solver failed), ``"max_wall"`` (the call's
        budget left it out or cut it).
    attractor : int or None
        The id of the attractor reached (also for breakdowns), else None.
    message : str
        Why, in a sentence (e.g. ``"transient: weakly unstable period-1, |μ|=1.0018, predicted escape after ~745
        returns / at t = 2.59 s"``).
    observables : StickSlipObservables or None
        The window's, where the run finished.
    escape : EscapePrediction or None
        For a transient on an unstable orbit.
    wall_time : float
        Seconds of the start's run.
    """

    start: SetStart
    outcome: str
    attractor: int | None
    message: str
    observables: StickSlipObservables | None = None
    escape: EscapePrediction | None = None
    wall_time: float = 0.0


@dataclass(frozen=True)
class SetAttractor:
    """One attractor of an :class:`AttractorSet`.

    Attributes
    ----------
    id : int
        Its index in ``AttractorSet.attractors`` (numbered in the order of the starts that first reach it).
    kind : str
        One of :data:`KINDS`: ``"periodic"`` (a stable period-n orbit), ``"quasi-periodic"`` (aperiodic returns,
        largest Lyapunov exponent below ``CHAOS_BITS``: a torus, or a period above ``max_period``),
        ``"chaotic"`` (a positive exponent), ``"aperiodic"`` (no exponent measured, or one at least
        ``CHAOS_BITS`` yet within three standard errors of 0: undecided), ``"steady"`` (no jump),
        ``"breakdown"`` (the starts break down; ``label`` the reason).
    label : str
        ``"period-n"``, ``"quasi-periodic"``, ``"chaotic"``, ``"aperiodic"``, ``"steady"`` or ``"breakdown:<reason>"``.
    period : int or None
    share : float
        Its starts over the starts that ran (invalid starts and starts left out by ``max_wall`` not counted).
    starts : tuple of str
        The names of the starts that reach it.
    observables : StickSlipObservables or None
        Of its first start's window (None for a breakdown).
    cycle : tuple of float
        The sorted return-map values [N] of the periodic orbit (Newton's, else the window's last n returns);
        for an aperiodic attractor ``(min, max, mean)`` of its window's returns; empty for steady or breakdown.
    multipliers : tuple of complex or None
        The nontrivial Floquet multipliers of a periodic orbit (:func:`exact.periodic_orbit`), by decreasing
        modulus.
    stable : bool or None
        Both multipliers inside the unit circle (None unmeasured).
    lyapunov : float or None
        The largest Lyapunov exponent [bits/s] of an aperiodic attractor (:func:`exact.lyapunov`), and
        ``lyapunov_stderr`` its standard error.
    note : str
        How the stability was obtained, or why it was not.
    returns : ndarray
        The window's return map of its first start (the force at the AB→CD jumps [N], at most 2000), for plots.
    """

    id: int
    kind: str
    label: str
    period: int | None
    share: float
    starts: tuple[str, ...]
    observables: StickSlipObservables | None
    cycle: tuple[float, ...] = ()
    multipliers: tuple[complex, ...] | None = None
    stable: bool | None = None
    lyapunov: float | None = None
    lyapunov_stderr: float | None = None
    note: str = ""
    returns: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False, repr=False)

    @property
    def is_stick_slip(self) -> bool:
        """True for the periodic, quasi-periodic, chaotic and aperiodic kinds."""
        return self.kind in ("periodic", "quasi-periodic", "chaotic", "aperiodic")

    @property
    def max_multiplier(self) -> float | None:
        """The largest ``|μ|`` (None without multipliers)."""
        return None if not self.multipliers else float(max(abs(m) for m in self.multipliers))

    def describe(self) -> str:
        """One line: ``"A0 period-3 (60 %), |μ| 0.4857: slip_interval 0.08023 s, force_drop 71 N"``."""
        text = f"A{self.id} {self.label} ({fmt_number(100 * self.share, 3)} %)"
        if self.max_multiplier is not None:
            text += f", |μ| {fmt_number(self.max_multiplier, 5)}"
        if self.lyapunov is not None:
            text += f", λ {fmt_number(self.lyapunov, 3)} ± {fmt_number(self.lyapunov_stderr, 2)} bits/s"
        o = self.observables
        if o is not None and o.slip_interval is not None:
            text += f": slip_interval {fmt_number(o.slip_interval, 4)} s, force_drop {fmt_number(o.force_drop, 4)} N"
        return text

    def row(self) -> dict[str, Any]:
        """One flat row of plain data (the table's): ``id``, ``kind``, ``label``, ``period``, ``share``,
        ``n_starts``, ``starts`` (the names, space-separated), ``stable``, ``max_multiplier``, ``multipliers``
        (``"re+imj"``, space-separated), ``lyapunov_bits_per_s``, ``lyapunov_stderr``, ``cycle`` (floats,
        space-separated), ``note``; then, where the attractor has observables (not a breakdown), the fields of
        :meth:`peelapprox.StickSlipObservables.as_dict` but ``status``, ``reason``, ``method``, ``V`` and ``I``
        (``n_slips``, ``period`` as ``window_period``: the window's own, None where it had not settled,
        ``period_label``, ``slip_interval``, ``force_drop``, ... ``t_start``, ``t_end``).  None where a value is
        undefined, never NaN."""
        row: dict[str, Any] = {"id": self.id, "kind": self.kind, "label": self.label, "period": self.period,
                               "share": self.share, "n_starts": len(self.starts), "starts": " ".join(self.starts),
                               "stable": self.stable, "max_multiplier": self.max_multiplier,
                               "multipliers": " ".join(f"{m.real:.10g}{m.imag:+.10g}j" for m in self.multipliers or ()),
                               "lyapunov_bits_per_s": self.lyapunov, "lyapunov_stderr": self.lyapunov_stderr,
                               "cycle": " ".join(repr(c) for c in self.cycle), "note": self.note}
        if self.observables is not None:
            obs = self.observables.as_dict()
            for name in ("status", "reason", "method", "V", "I"):
                obs.pop(name)
            # the window's own period (None where it had not settled) beside the attractor's (Newton's), not over it
            row.update({("window_period" if k == "period" else k): v for k, v in obs.items()})
        return row


_COMPARED = ("slip_interval", "force_drop")
#: The observables :meth:`AttractorSet.closest` can compare: the numeric fields of StickSlipObservables.
_COMPARABLE = tuple(f.name for f in dataclasses.fields(StickSlipObservables)
                    if f.name not in ("status", "reason", "method", "period_label", "V", "I"))


def _fields(fields: Any) -> tuple[str, ...]:
    """``fields`` checked: a non-empty tuple or list of names of :data:`_COMPARABLE`."""
    if isinstance(fields, str) or not isinstance(fields, (tuple, list)) or not fields:
        raise ArgumentTypeError(f"fields must be a non-empty tuple of observable names (of {_COMPARABLE}), got "
                                f"{fields!r}")
    bad = [f for f in fields if f not in _COMPARABLE]
    if bad:
        raise ValueError(f"fields: {bad!r} are not observables; choose among {_COMPARABLE}")
    return tuple(fields)


@dataclass(frozen=True, eq=False)
class AttractorSet:
    """The coexisting attractors reached from a set of starts (:func:`exact.attractor_set`).

    Attributes
    ----------
    params : PeelParams
    status : str
        One of :data:`SET_STATUSES`: ``"ok"`` (at least one attractor other than a breakdown), ``"transient
        only"`` (every run that finished is still in a transient: lengthen ``t_transient``), ``"breakdown only"``
        (every start that ran breaks down), ``"max_wall"`` (the budget ran out before every start was read: the
        attractors are those of the starts read; or before a stability step, whose attractor's ``note`` says so:
        its class is then unchecked), ``"no attractor"`` (every start invalid or failed).
    message : str
        A sentence saying why.
    attractors : tuple of SetAttractor
        In the order first reached; the first start (the solver's default in the default design) reaches
        :attr:`primary`.
    outcomes : tuple of SetOutcome
        One per start, in the order of the starts.
    t_transient, t_window, rtol : float
        Of every start's run.
    counters : dict
        ``runs`` (solver runs), ``steps`` (accepted steps of the runs and the Newton iterations), ``rhs``
        (right-hand-side evaluations of the runs), ``orbits`` (Newton solves), ``lyapunov`` (exponents measured),
        ``run_wall`` (seconds of the runs, summed over the workers).
    wall_time : float
        Seconds of the whole call.
    """

    params: PeelParams
    status: str
    message: str
    attractors: tuple[SetAttractor, ...]
    outcomes: tuple[SetOutcome, ...]
    t_transient: float
    t_window: float
    rtol: float
    counters: dict[str, float]
    wall_time: float

    # ------------------------------------------------------------------------------------------ queries
    @property
    def primary(self) -> SetAttractor | None:
        """The attractor the first start reaches (the solver's default start in the default design), or None."""
        k = self.outcomes[0].attractor if self.outcomes else None
        return None if k is None else self.attractors[k]

    @property
    def transients(self) -> tuple[SetOutcome, ...]:
        """The outcomes still in a transient at the end of ``t_transient``."""
        return tuple(o for o in self.outcomes if o.outcome == "transient")

    def stick_slip(self, min_share: float = 0.0) -> tuple[SetAttractor, ...]:
        """The stick-slip attractors (periodic, quasi-periodic, chaotic, aperiodic) with ``share >= min_share``."""
        return tuple(a for a in self.attractors if a.is_stick_slip and a.share >= min_share)

    def closest(self, observables: StickSlipObservables | Mapping[str, float | None], *,
                fields: tuple[str, ...] = _COMPARED, min_share: float = 0.0) -> tuple[SetAttractor, float] | None:
        """The stick-slip attractor of the set whose observables are nearest to ``observables``, and the distance.

        Parameters
        ----------
        observables : StickSlipObservables or mapping
            Anything with the ``fields`` as attributes or keys (a prediction, statistics of a measured trace).
        fields : tuple of str
            The observables compared (the numeric :class:`peelapprox.StickSlipObservables` field names, at least
            one; default slip interval and force drop).
        min_share : float
            Only attractors reached from at least this share of the starts, in [0, 1].

        Returns
        -------
        (SetAttractor, float) or None
            The distance is the largest relative difference ``|mine - theirs| / |mine|`` over ``fields``; None
            when no attractor (or ``observables``) defines them.

        Raises
        ------
        ValueError, TypeError
            ``min_share`` outside [0, 1], ``fields`` empty or naming no numeric observable, a value of
            ``observables`` not a finite number (each named).
        """
        min_share, fields = in_range("min_share", min_share, 0.0, 1.0), _fields(fields)
        get = (observables.get if isinstance(observables, Mapping)
               else lambda name: getattr(observables, name, None))
        theirs = [get(f) for f in fields]
        if any(v is None for v in theirs):
            return None
        for f, v in zip(fields, theirs, strict=True):  # a number, finite: a NaN distance is no answer
            if not math.isfinite(real(f"observables[{f!r}]", v)):
                raise ValueError(f"observables[{f!r}] must be finite, got {v!r}")
        best: tuple[SetAttractor, float] | None = None
        for a in self.stick_slip(min_share):
            mine = [None if a.observables is None else getattr(a.observables, f) for f in fields]
            if any(v is None or v == 0 for v in mine):
                continue
            d = max(abs(float(m) - float(t)) / abs(float(m))  # type: ignore[arg-type]  # None excluded above
                    for m, t in zip(mine, theirs, strict=True))
            if best is None or d < best[1]:
                best = (a, d)
        return best

    # ------------------------------------------------------------------------------------------ output
    def rows(self) -> list[dict[str, Any]]:
        """One row per attractor (:meth:`SetAttractor.row`), plain data for CSV or JSON."""
        return [a.row() for a in self.attractors]

    def outcome_rows(self) -> list[dict[str, Any]]:
        """One row per start: its name and state, outcome, attractor id, message, predicted escape."""
        rows = []
        for o in self.outcomes:
            e = o.escape
            rows.append({"start": o.start.name, "alpha0": o.start.alpha0, "omega0": o.start.omega0,
                         "F0": o.start.F0, "branch0": o.start.branch0, "outcome": o.outcome,
                         "attractor": o.attractor, "message": o.message,
                         "escape_multiplier": None if e is None else abs(e.multiplier),
                         "escape_returns": None if e is None else e.returns,
                         "escape_time": None if e is None else e.time, "wall_time": o.wall_time})
        return rows

    def to_dataframe(self):
        """The attractors as a :class:`pandas.DataFrame`, one row per attractor with the columns of
        :meth:`SetAttractor.row` (a breakdown's observables' columns empty); ``attrs`` hold the status, message,
        parameters and counters.  ImportError without pandas (``pip install 'peelapprox[data]'``)."""
        pd = optional_import("pandas", "AttractorSet.to_dataframe")
        df = pd.DataFrame(self.rows())
        df.attrs.update(status=self.status, message=self.message, V=self.params.V, I=self.params.I,
                        counters=dict(self.counters), wall_time=self.wall_time)
        return df

    def to_json(self) -> str:
        """The set as JSON text (strict: no NaN): status, settings, counters, attractors, outcomes."""
        doc = {"params": repr(self.params), "status": self.status, "message": self.message,
               "t_transient": self.t_transient, "t_window": self.t_window, "rtol": self.rtol,
               "counters": self.counters, "wall_time": self.wall_time, "attractors": self.rows(),
               "outcomes": self.outcome_rows()}
        return json.dumps(jsonable(doc), indent=1, allow_nan=False)

    def plot(self, ax: Any = None, *, title: str | None = None) -> Any:
        """Each attractor's return map ``x_{k+1}`` against ``x_k`` (the force at the AB→CD jumps of its first
        start's window), one colour each, the legend giving label and share (an attractor without a map, a transient,
        or the status where there is neither, in the legend only); returns the figure drawn into."""
        from peelapprox.plotting import new_figure

        if ax is None:
            ax = new_figure(figsize=(7.0, 5.0)).subplots()
        for a in self.attractors:
            x = a.returns
            if x.size >= 2:
                ax.plot(x[:-1], x[1:], ".", ms=4 if x.size < 200 else 2, label=a.describe()[:70])
            else:  # steady, a breakdown, a window of fewer than two returns: named in the legend only
                ax.plot([], [], " ", label=a.describe()[:70])
        for o in self.transients:
            ax.plot([], [], " ", label=f"{o.start.name}: {o.message[:60]}")
        if not self.attractors and not self.transients:  # nothing to draw: the status says why
            ax.plot([], [], " ", label=f"{self.status}: {self.message[:60]}")
        ax.set_xlabel("F at AB→CD jump k [N]")
        ax.set_ylabel("F at AB→CD jump k+1 [N]")
        ax.legend(fontsize="small")
        ax.set_title(title or f"attractor set, V = {self.params.V:g} m/s, I = {self.params.I:g} kg m²")
        return ax.figure

    def summary(self) -> str:
        """A few lines: the status and message, one line per attractor, one per transient."""
        lines = [f"{self.status}: {self.message}"]
        lines += [f"  {a.describe()}" for a in self.attractors]
        lines += [f"  {o.start.name}: {o.message}" for o in self.transients]
        lines.append(f"  {self.counters.get('runs', 0):g} runs, {fmt_number(self.wall_time, 3)} s")
        return "\n".join(lines)

    def __repr__(self) -> str:
        atts = "; ".join(f"{a.label} {fmt_number(100 * a.share, 3)} %" for a in self.attractors)
        tr = f", {len(self.transients)} transient" if self.transients else ""
        return (f"AttractorSet({self.status}, V={self.params.V:g}, I={self.params.I:g}: {atts or 'none'}{tr}; "
                f"{len(self.outcomes)} starts, {fmt_number(self.wall_time, 3)} s)")
