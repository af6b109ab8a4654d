"""The observables of a stick-slip attractor, one definition for the exact and the approximate sides.

:class:`StickSlipObservables` is what a user asks of a stick-slip run: how often the front slips, how much the
force drops, how long a slip and a stick last, between which forces the orbit moves and how many slips make
a cycle.  :meth:`StickSlipObservables.from_trajectory` reads them off the jump sequence of any trajectory
(the protocol :class:`peelapprox._returnmap.HasJumps`, which :class:`exact.Trajectory` satisfies, so this module
need not import ``exact``); :func:`exact.attractor_observables` runs the exact solver's window and reads it.

The definitions (docs/dynamics.md, "Attractor observables"), over the jumps with ``t >= t_start`` of the window
``[t_start, t_end]``; only complete stays count, those between two jumps inside the window (the stays cut by
the window's edges are never measured):

* ``slip_interval`` — mean time between consecutive AB→CD jumps [s];
* ``force_drop`` — mean of F at an AB→CD jump minus F at the next CD→AB jump [N]
  (:func:`peelapprox.force_drops`);
* ``slip_time`` — mean CD stay (an AB→CD jump to the next CD→AB jump) [s];
* ``stick_time`` — mean AB stay (a CD→AB jump to the next AB→CD jump) [s];
* ``F_max``, ``F_min`` — the largest and smallest F at any jump of the window [N];
* ``period`` — the return map's period n (:func:`peelapprox.periodicity`), None if it has none; where the whole
  sample repeats after n but its last half already after a divisor d of n, d (a period-d orbit still settling along
  a multiplier near -1, whose decaying transient repeats after 2d sooner than after d:
  :func:`peelapprox._returnmap.settled_period`).

On a periodic attractor (period n) each mean is taken over the last whole cycles of its sample (its last
``n·floor(size/n)`` values, n the repeat found over the whole sample, a multiple of the period), so it is the
orbit's mean, independent of where the window cuts the cycle.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from ._returnmap import HasJumps, _trajectory, periodicity, settled_period
from .io import fmt_number, html_table, jsonable, optional_import
from .law import BRANCHES, fixed_point
from .validate import duration, integer, positive

__all__ = ["StickSlipObservables", "STATUSES", "QUIET_FACTOR", "jump_statistics"]

_AB, _CD = BRANCHES.index("AB"), BRANCHES.index("CD")

#: The values of :attr:`StickSlipObservables.status`.
STATUSES = ("stick-slip", "steady", "too few slips", "transient", "no attractor", "breakdown")

#: The jumps have stopped ("transient") when the open stay after the window's last jump is longer than this
#: many times the longest complete stay of the window.  A periodic orbit's open stay is at most its longest
#: stay; a chaotic one's rarely exceeds a few times the longest seen over a window of many slips.
QUIET_FACTOR = 10.0



def _quantity(unit: str, role: str) -> Any:
    """A field of :class:`StickSlipObservables` with its unit and role (``"mean"``, ``"spread"``, ``"extreme"``:
    the observables; ``"where"``: the point and the window) in its metadata: the one schema of the observables,
    which :attr:`StickSlipObservables.OBSERVABLES`, ``SPREADS`` and ``UNITS`` are read from."""
    return field(metadata={"unit": unit, "role": role})


def _mean_spread(x: np.ndarray) -> tuple[float | None, float | None]:
    """The mean and the sample standard deviation (ddof 1; 0 for one value) of ``x``, (None, None) if empty.

    numpy's ``mean`` and ``std`` arithmetic without their per-call cost (a reduced map reads the observables of
    every orbit it finds): the sum by ``np.add.reduce`` divided by the size, the squared deviations from that mean
    summed the same way, divided by ``size - 1``, and the square root (bitwise ``float(np.mean(x))`` and
    ``float(np.std(x, ddof=1))`` of a float array)."""
    n = x.size
    if n == 0:
        return None, None
    mean = np.add.reduce(x) / n
    if n == 1:
        return float(mean), 0.0
    d = x - mean
    return float(mean), math.sqrt(float(np.add.reduce(d * d) / (n - 1)))


def _whole_cycles(x: np.ndarray, n: int | None) -> np.ndarray:
    """The last ``n·floor(size/n)`` values of ``x`` (its last whole cycles of period n); ``x`` itself if n is
    None or ``x`` holds less than one cycle."""
    if n is None or x.size < n:
        return x
    return x[x.size - (x.size // n) * n:]


def jump_statistics(t: np.ndarray, F: np.ndarray, fb: np.ndarray, *, period_rtol: float, max_period: int
                    ) -> tuple[dict[str, Any], int | None]:
    """The statistics of a jump sequence: the fields of :class:`StickSlipObservables` that its jumps define.

    The one place of the definitions in the module docstring, shared by the exact side
    (:meth:`StickSlipObservables.from_trajectory`) and the reduced return map
    (:func:`peelapprox.approximate_attractor`).

    Parameters
    ----------
    t, F, fb : ndarray
        Jump times [s], pull forces [N] and branches left (codes of :data:`peelapprox.BRANCHES`): 1-D, one
        length, at least one jump, in time order, alternating (checked by the caller).
    period_rtol, max_period
        Of :func:`peelapprox.periodicity`.

    Returns
    -------
    (dict, int or None)
        ``n_slips``, ``period``, ``period_label``, each mean and ``<mean>_spread``, ``F_max``, ``F_min``; and the
        number of whole cycles the means were taken over (None without a period).
    """
    slips = np.flatnonzero(fb == _AB)
    to_cd = slips[slips + 1 < t.size]  # AB→CD jumps followed by a CD→AB jump: complete CD stays
    to_ab = np.flatnonzero(fb[:-1] == _CD)  # CD→AB jumps followed by an AB→CD jump: complete AB stays
    samples = {"slip_interval": np.diff(t[slips]), "force_drop": F[to_cd] - F[to_cd + 1],
               "slip_time": t[to_cd + 1] - t[to_cd], "stick_time": t[to_ab + 1] - t[to_ab]}
    if slips.size >= 2:
        per = periodicity(F[slips], rtol=period_rtol, max_period=max_period)
        repeat, period, label = per.period, per.period, per.label
        if repeat is not None and repeat > 1:  # a decaying flip transient of a shorter orbit read as its double
            period = settled_period(np.ascontiguousarray(F[slips]), repeat, period_rtol)
            label = f"period-{period}"
    else:
        repeat, period, label = None, None, "too short" if slips.size else "no stick-slip"
    values: dict[str, Any] = {"n_slips": int(slips.size), "period": period, "period_label": label,
                              "F_max": float(F.max()), "F_min": float(F.min())}
    for name, x in samples.items():  # whole cycles of the repeat found over the whole sample (of the period too)
        values[name], values[f"{name}_spread"] = _mean_spread(_whole_cycles(x, repeat))
    cycles = None if period is None else len(_whole_cycles(samples["slip_interval"], repeat)) // period
    return values, cycles


def _window_text(start: float, end: float | None) -> str:
    return f"[{fmt_number(start, 6)}, {fmt_number(end, 6, missing='…')}] s"


def _describe(tr: Any, start: float, end: float | None, period_rtol: float) -> str:
    """How a trajectory's observables were obtained: its method, solver, rtol (where it has them), the window."""
    parts = []
    if getattr(tr, "method", None) is not None:
        solver = getattr(tr, "solver", None)
        parts.append(f"{tr.method}" + (f" ({solver})" if solver else ""))
    if getattr(tr, "rtol", None) is not None:
        parts.append(f"rtol {fmt_number(tr.rtol, 3)}")
    parts += [f"window {_window_text(start, end)}", f"period_rtol {fmt_number(period_rtol, 3)}"]
    return "trajectory: " + ", ".join(parts)


def _steady_reason(tr: Any, start: float, end: float | None) -> str:
    """Why a window without jumps is steady peeling: the branch it rests on and, for the paper's model under
    velocity control, whether the law has folds at V and the fixed point's stability."""
    text = f"no jump in the window {_window_text(start, end)}: steady peeling"
    final = getattr(tr, "final_state", None)
    branch, v = getattr(final, "branch", None), getattr(final, "v", None)
    if branch is not None and v is not None:
        text += f" on {branch} (v = {fmt_number(v, 4)} m/s at the end)"
    params = getattr(tr, "params", None)
    if params is not None and getattr(params, "variant", "?") is None:
        try:
            folds = params.force.folds(params.V)
            fp = fixed_point(params.V, params.R, force=params.force)
        except ValueError:  # a law the fold search cannot read at this V: say no more than the jumps do
            return text
        if not folds.has_folds:
            text += f"; the law has no folds at V = {fmt_number(params.V, 4)} m/s (f increases in v)"
        else:
            text += (f"; the fixed point is {'stable' if fp.stable else 'unstable'} "
                     f"(f'(V, V) = {fmt_number(fp.fprime, 4)} N s/m)")
    return text


@dataclass(frozen=True, kw_only=True)
class StickSlipObservables:
    """The observables of a stick-slip attractor (module docstring: the definitions).

    Every mean comes with its spread, the sample standard deviation (``ddof=1``) of the values it averages,
    0 for a single value.  A quantity the window cannot define (no slip, one slip, no complete stay) is None,
    never NaN.

    The fields are the one schema of the observables: each measured field carries its unit and role in its
    metadata, and the class attributes ``OBSERVABLES`` (the four means and the force range: what a prediction is
    compared on, :data:`comparisons.atlas.OBSERVABLES` being this very tuple), ``MEANS``, ``SPREADS`` and
    ``UNITS`` (field -> unit) are read from them.

    Attributes
    ----------
    status, reason : str
        One of ``STATUSES``: ``"stick-slip"`` (two AB→CD jumps or more, still slipping at the window's end),
        ``"steady"`` (no jump: every mean None), ``"too few slips"`` (lengthen the window), ``"transient"`` (the
        jumps stop inside the window: the means are of the jumps seen, not of an attractor);
        :func:`peelapprox.approximate_attractor` adds ``"no attractor"`` and ``"breakdown"``.  ``reason`` is a
        sentence saying why.
    method : str
        How the observables were obtained, e.g. ``"exact: hybrid (DOP853), rtol 1e-10, ..."``.
    V, I : float or None
        Pull speed [m/s] and moment of inertia [kg m²], from the trajectory's ``params`` when it has them.
    n_slips : int
        The number of AB→CD jumps in the window.
    period : int or None
        The return map's period n (:func:`peelapprox.periodicity`), None when it has none.
    period_label : str
        ``"period-n"``, ``"aperiodic"``, ``"too short"`` (:class:`peelapprox.Periodicity`'s labels) or
        ``"no stick-slip"`` (no AB→CD jump).
    slip_interval, force_drop, slip_time, stick_time : float or None
        Means of the time between consecutive AB→CD jumps [s], of F at an AB→CD jump minus F at the next CD→AB
        jump [N], of the CD stays [s] and of the AB stays [s]; each ``*_spread`` is its spread.
    F_max, F_min : float or None
        The largest and smallest pull force at the window's jumps [N].
    t_start, t_end : float or None
        The window [s]: jumps at ``t >= t_start`` are read; ``t_end`` is the trajectory's end (None when the
        trajectory does not say).
    """

    # The schema read off the fields' metadata below the class (class attributes, not fields: unannotated, so
    # that neither dataclasses.fields nor __dataclass_fields__ lists them).
    #: The observables a prediction is compared on, in field order (the means and the force range):
    #: ``("slip_interval", "force_drop", "slip_time", "stick_time", "F_max", "F_min")``.
    OBSERVABLES = cast("tuple[str, ...]", ())
    #: The four means, in field order (the repr's and the summary's).
    MEANS = cast("tuple[str, ...]", ())
    #: The spreads of the means, ``"<mean>_spread"``, in field order.
    SPREADS = cast("tuple[str, ...]", ())
    #: Field -> unit, of every field with one (the DataFrame's ``attrs["units"]``).
    UNITS = cast("dict[str, str]", {})

    status: str
    reason: str
    method: str
    V: float | None = _quantity("m/s", "where")
    I: float | None = _quantity("kg m^2", "where")
    n_slips: int
    period: int | None
    period_label: str
    slip_interval: float | None = _quantity("s", "mean")
    slip_interval_spread: float | None = _quantity("s", "spread")
    force_drop: float | None = _quantity("N", "mean")
    force_drop_spread: float | None = _quantity("N", "spread")
    slip_time: float | None = _quantity("s", "mean")
    slip_time_spread: float | None = _quantity("s", "spread")
    stick_time: float | None = _quantity("s", "mean")
    stick_time_spread: float | None = _quantity("s", "spread")
    F_max: float | None = _quantity("N", "extreme")
    F_min: float | None = _quantity("N", "extreme")
    t_start: float | None = _quantity("s", "where")
    t_end: float | None = _quantity("s", "where")

    # ------------------------------------------------------------------------------------------ building
    @classmethod
    def from_trajectory(cls, tr: HasJumps, t_transient: float = 0.0, *, period_rtol: float = 1e-6,
                        max_period: int = 32, method: str | None = None) -> StickSlipObservables:
        """The observables of a trajectory's window, read off its jumps (no solver runs).

        Parameters
        ----------
        tr : HasJumps
            An :class:`exact.Trajectory` (from ``exact.simulate(..., save="jumps")`` or
            :func:`exact.window_run`), or anything with ``jumps.t``, ``jumps.F`` and ``jumps.from_branch``
            (alternating AB→CD and CD→AB jumps in time order).  Its ``params`` give V and I, its
            ``t_transient`` and ``t_end`` the window, its ``method``, ``solver`` and ``rtol`` the default
            ``method`` text, where it has them.
        t_transient : float
            Jumps before this time [s] (absolute, like the trajectory's times) are dropped as transient, in
            addition to those the trajectory did not store, in [0, 1e6] and below the trajectory's
            ``t_end``.
        period_rtol : float
            ``rtol`` of :func:`peelapprox.periodicity` (1e-6: the hybrid solver at rtol 1e-10 reproduces a
            periodic orbit's jump forces to ~1e-12, chaotic returns do not come within 1e-6), > 0.
        max_period : int
            Largest period tried, >= 1.
        method : str, optional
            The ``method`` text (None: ``"trajectory: "`` and the trajectory's method, solver, rtol, window).

        Returns
        -------
        StickSlipObservables

        Raises
        ------
        ValueError
            A bad argument, named: jumps that are not finite, not in time order or do not alternate, or
            ``t_transient`` at or after the trajectory's end.
        peelapprox.validate.ArgumentTypeError
            ``tr`` without jumps.
        """
        tr = _trajectory("tr", tr)
        t_transient = duration("t_transient", t_transient, zero=True)
        period_rtol = positive("period_rtol", period_rtol)
        max_period = integer("max_period", max_period)
        if method is not None and not isinstance(method, str):
            raise TypeError(f"method must be a str or None, got {type(method).__name__}")
        J = tr.jumps
        t, F = np.asarray(J.t, dtype=float), np.asarray(J.F, dtype=float)
        fb = np.asarray(J.from_branch)
        if not (t.ndim == 1 and t.shape == F.shape == fb.shape):
            raise ValueError(f"tr.jumps: t, F and from_branch must be 1-D of one length, got shapes {t.shape}, "
                             f"{F.shape}, {fb.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(F))):
            raise ValueError("tr.jumps: the jump times and forces must be finite")
        if not np.all(np.isin(fb, (_AB, _CD))):
            raise ValueError(f"tr.jumps.from_branch must hold branch codes {_AB} (AB) and {_CD} (CD)")
        t0, t1 = getattr(tr, "t_transient", None), getattr(tr, "t_end", None)
        start = max(t_transient, float(t0)) if t0 is not None else t_transient
        end = float(t1) if t1 is not None else None
        if end is not None and not start < end:
            raise ValueError(f"t_transient must be below the trajectory's window end t_end = {end:g} s, got "
                             f"{t_transient:g} (the window is [max(t_transient, tr.t_transient), t_end])")
        if np.any(np.diff(t) < 0):
            raise ValueError("tr.jumps: the jumps must be in time order")
        keep = t >= start
        t, F, fb = t[keep], F[keep], fb[keep]
        if np.any(fb[1:] == fb[:-1]):
            raise ValueError("tr.jumps: the jumps must alternate AB→CD and CD→AB (an exact trajectory's do)")
        params = getattr(tr, "params", None)
        common: dict[str, Any] = dict(
            method=method if method is not None else _describe(tr, start, end, period_rtol),
            V=None if params is None else float(params.V), I=None if params is None else float(params.I),
            t_start=start, t_end=end)
        if t.size == 0:
            return cls._no_slip(status="steady", reason=_steady_reason(tr, start, end), **common)
        return cls._from_jumps(t, F, fb, end, period_rtol, max_period, common)

    @classmethod
    def _no_slip(cls, *, status: str, reason: str, **common: Any) -> StickSlipObservables:
        """The observables of a window without a slip: every mean, spread, extreme and the period None."""
        empty: dict[str, Any] = {f.name: None for f in dataclasses.fields(cls) if f.name not in common}
        empty.update(status=status, reason=reason, n_slips=0, period_label="no stick-slip")
        return cls(**empty, **common)

    @classmethod
    def _from_jumps(cls, t: np.ndarray, F: np.ndarray, fb: np.ndarray, end: float | None, period_rtol: float,
                    max_period: int, common: dict[str, Any]) -> StickSlipObservables:
        """The observables of a window's jumps ``t, F, fb`` (checked, alternating, at least one)."""
        stats, cycles = jump_statistics(t, F, fb, period_rtol=period_rtol, max_period=max_period)
        stays = np.diff(t)
        n, label = stats["n_slips"], stats["period_label"]
        if n < 2:
            status = "too few slips"
            reason = (f"{n} AB→CD jump{'' if n == 1 else 's'} among the {t.size} jumps of the window "
                      f"{_window_text(common['t_start'], end)}: no slip interval; lengthen the window")
        elif end is not None and end - t[-1] > QUIET_FACTOR * float(stays.max()):
            status = "transient"
            reason = (f"the jumps stop at t = {fmt_number(t[-1], 6)} s: the open {BRANCHES[1 - fb[-1]]} stay to "
                      f"the window's end, {fmt_number(end - t[-1], 3)} s, is over {QUIET_FACTOR:g} times the "
                      f"longest complete stay ({fmt_number(stays.max(), 3)} s); the means are the transient's")
        else:
            status = "stick-slip"
            reason = (f"{n} slips in the window {_window_text(common['t_start'], end)}, return map {label}"
                      + (f"; means over the last {cycles} whole cycles" if cycles is not None else ""))
        return cls(status=status, reason=reason, **stats, **common)

    # ------------------------------------------------------------------------------------------ output
    def as_dict(self) -> dict[str, Any]:
        """The fields as plain JSON data (:func:`peelapprox.io.jsonable`: None stays None), one flat row."""
        return {f.name: jsonable(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def to_dataframe(self):
        """One row, the columns of :meth:`as_dict`, as a :class:`pandas.DataFrame`; ``df.attrs["units"]``.

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        pd = optional_import("pandas", "StickSlipObservables.to_dataframe")
        row = self.as_dict()
        df = pd.DataFrame([row], columns=list(row))
        df.attrs["units"] = {name: self.UNITS.get(name, "") for name in row}
        return df

    @property
    def is_stick_slip(self) -> bool:
        """True if ``status == "stick-slip"``."""
        return self.status == "stick-slip"

    @classmethod
    def _means(cls) -> tuple[tuple[str, str], ...]:
        """The four means and their units, in the order of the repr and the summary."""
        return tuple((name, cls.UNITS[name]) for name in cls.MEANS)

    def _head(self) -> str:
        where = ", ".join(f"{n}={fmt_number(v, 4)}" for n, v in (("V", self.V), ("I", self.I)) if v is not None)
        per = f", {self.period_label}" if self.n_slips else ""
        return f"{self.status}{per}" + (f", {where}" if where else "")

    def __repr__(self) -> str:
        means = ", ".join(f"{name}={fmt_number(getattr(self, name), 4)} {unit}" for name, unit in self._means()
                          if getattr(self, name) is not None)
        if self.n_slips == 0 or not means:
            return f"StickSlipObservables({self._head()}: {'no slip' if self.n_slips == 0 else 'no complete stay'})"
        return (f"StickSlipObservables({self._head()}, {self.n_slips} slips: {means}, "
                f"F {fmt_number(self.F_min, 4)}…{fmt_number(self.F_max, 4)} N)")

    def summary(self) -> str:
        """A few lines for a person: the status and its reason, each mean ± its spread, the F range, the
        method."""
        lines = [f"{self._head()}: {self.reason}"]
        for name, unit in self._means():
            value = getattr(self, name)
            if value is not None:
                lines.append(f"  {name:<14} {fmt_number(value, 5)} ± {fmt_number(getattr(self, name + '_spread'), 2)}"
                             f" {unit}")
        if self.F_max is not None:
            lines.append(f"  {'F at jumps':<14} {fmt_number(self.F_min, 5)} … {fmt_number(self.F_max, 5)} N")
        lines.append(f"  {self.method}")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        items: Sequence[tuple[str, Any]] = [("status", self.status), ("reason", self.reason),
                                            ("method", self.method), ("V [m/s]", self.V), ("I [kg m²]", self.I),
                                            ("slips", self.n_slips), ("period", self.period_label)]
        items = [*items, *((f"{n} [{u}]", getattr(self, n)) for n, u in self._means()),
                 *((f"{n} spread [{u}]", getattr(self, f"{n}_spread")) for n, u in self._means()),
                 ("F_max [N]", self.F_max), ("F_min [N]", self.F_min)]
        return html_table("StickSlipObservables", items)


def _roles(*roles: str) -> tuple[str, ...]:
    return tuple(f.name for f in dataclasses.fields(StickSlipObservables) if f.metadata.get("role") in roles)


StickSlipObservables.OBSERVABLES = _roles("mean", "extreme")
StickSlipObservables.MEANS = _roles("mean")
StickSlipObservables.SPREADS = _roles("spread")
StickSlipObservables.UNITS = {f.name: f.metadata["unit"] for f in dataclasses.fields(StickSlipObservables)
                              if "unit" in f.metadata}
