"""Burst catalogues: :func:`burst_catalogue` (bursts of a power time series) and :class:`BurstCatalogue` (its
table, or a measured catalogue read by :meth:`BurstCatalogue.from_csv`).

A burst is a maximal interval where the power exceeds ``threshold``, on the piecewise-linear interpolant of the
samples: it starts and ends at the interpolated crossings of the threshold, so its duration and energy do not
jump with the sampling grid's phase.  Per burst:

* ``start``, ``end``, ``duration`` [s] — the up- and down-crossings and their difference;
* ``energy`` — ∫ power dt over the burst (the threshold's share included): the energy the burst released, the
  usual acoustic-emission "hit energy" when the power is the AE power [J if power is in W];
* ``excess`` — ∫ (power - threshold) dt over the burst: the energy above the threshold (→ ``energy`` as the
  threshold → 0; the excess is the size that does not grow with the burst's duration times the threshold);
* ``peak``, ``t_peak`` — the largest sample and its time;
* ``waiting`` — from the previous burst's end to this one's start (one fewer entry; the first burst has none).

Integrals are exact for the interpolant (trapezoids, a triangle at each crossing).  With ``min_gap``, bursts
separated by less than it are merged into one (an acoustic-emission "hit definition time").  A burst already
under way at the first sample or still under way at the last is cut by the record: it is dropped and counted
(``n_dropped``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import choice, finite, nonnegative, reals, shown, times
from ..io import fmt_number, optional_import, write_rows

__all__ = ["BURST_COLUMNS", "BurstCatalogue", "burst_catalogue"]

#: Each column of a catalogue and its unit ("power" and "energy": the units of the series given).
BURST_COLUMNS = {"start": "s", "end": "s", "duration": "s", "energy": "power*s", "excess": "power*s",
                 "peak": "power", "t_peak": "s", "size": ""}
_TIME_COLUMNS = ("start", "end", "duration", "t_peak")
_SIZE_COLUMNS = ("energy", "excess", "peak", "duration", "size")


@dataclass(frozen=True, eq=False)
class BurstCatalogue:
    """Bursts, one entry per burst in time order (:func:`burst_catalogue`, :meth:`from_csv`).

    Attributes
    ----------
    start, end, duration, energy, excess, peak, t_peak, size : ndarray or None
        The columns (module docstring of ``peelapprox/bursts/_catalogue.py``); a measured catalogue has the
        columns its file has (None for the others); ``size`` is a measured catalogue's own size column (a force
        drop, an amplitude), None for a computed one.
    threshold : float or None
        The power threshold (None: not known, a measured catalogue).
    n_dropped : int
        Bursts cut by the ends of the record and left out.
    source : str
        Where the catalogue comes from.
    """

    start: np.ndarray | None = None
    end: np.ndarray | None = None
    duration: np.ndarray | None = None
    energy: np.ndarray | None = None
    excess: np.ndarray | None = None
    peak: np.ndarray | None = None
    t_peak: np.ndarray | None = None
    size: np.ndarray | None = None
    threshold: float | None = None
    n_dropped: int = 0
    source: str = ""

    def __len__(self) -> int:
        return next((c.size for c in self._columns().values()), 0)

    def _columns(self) -> dict[str, np.ndarray]:
        return {k: getattr(self, k) for k in BURST_COLUMNS if getattr(self, k) is not None}

    @property
    def waiting(self) -> np.ndarray | None:
        """``start[k+1] - end[k]`` [s] (one fewer entry than bursts; None without start and end)."""
        if self.start is None or self.end is None:
            return None
        return self.start[1:] - self.end[:-1]

    def sizes(self, column: str = "energy") -> np.ndarray:
        """The sizes to fit (:func:`peelapprox.fit_power_law`): one of ``energy``, ``excess``, ``peak``,
        ``duration``, ``size``, the entries > 0.

        Raises
        ------
        ValueError
            An unknown column, or one this catalogue does not have.
        """
        column = choice("column", column, _SIZE_COLUMNS)
        values = getattr(self, column)
        if values is None:
            have = [c for c in _SIZE_COLUMNS if getattr(self, c) is not None]
            raise ValueError(f"column {column!r}: this catalogue has no such column (it has {have})")
        return values[values > 0]

    def as_rows(self) -> list[dict[str, Any]]:
        """One row per burst: its columns, and ``waiting`` (None for the first burst) where start and end are
        known."""
        cols = self._columns()
        wait = self.waiting
        rows = []
        for k in range(len(self)):
            row: dict[str, Any] = {name: float(v[k]) for name, v in cols.items()}
            if wait is not None:
                row["waiting"] = None if k == 0 else float(wait[k - 1])
            rows.append(row)
        return rows

    def write(self, path: str) -> str:
        """Write :meth:`as_rows` as CSV or JSON by the extension (:func:`peelapprox.io.write_rows`); a CSV reads
        back with :meth:`from_csv`."""
        fields = list(self._columns()) + (["waiting"] if self.waiting is not None else [])
        return write_rows(path, self.as_rows(), fields=fields)

    def to_dataframe(self):
        """:meth:`as_rows` as a :class:`pandas.DataFrame` (``pip install 'peelapprox[data]'``);
        ``df.attrs`` holds the threshold and the source."""
        pd = optional_import("pandas", "BurstCatalogue.to_dataframe")
        fields = list(self._columns()) + (["waiting"] if self.waiting is not None else [])
        df = pd.DataFrame(self.as_rows(), columns=fields)
        df.attrs.update({"threshold": self.threshold, "source": self.source, "n_dropped": self.n_dropped})
        return df

    @classmethod
    def from_csv(cls, path: str, *, size: str | None = None, delimiter: str | None = None,
                 units: dict[str, str] | None = None) -> BurstCatalogue:
        """A measured catalogue (acoustic-emission hits, force drops) from a CSV file: a header naming any of
        the columns ``start, end, duration, energy, excess, peak, t_peak, size`` (others are ignored), one burst
        per row.

        Times may state their unit in the header (``start [ms]``; s, ms, us, min) or in ``units``; the other
        columns are read as they are (their header cells must not state a unit).  ``size`` names one more column
        to read as the catalogue's ``size`` (``size="drop"`` for a force-drop table).  Read by the package's one
        CSV reader (a regular UTF-8 file of at most 16 MiB, ``#`` comments), which never executes anything.

        Raises
        ------
        ValueError
            Naming the file (and line, column): no known column, a cell that is not a number, a size <= 0 or not
            finite, an unknown unit.
        """
        from .._csvread import read_columns

        where = f"BurstCatalogue.from_csv({shown(str(path))})"
        wanted = {c: ("s" if c in _TIME_COLUMNS else "") for c in BURST_COLUMNS}
        if size is not None:
            if not isinstance(size, str) or not size:
                raise TypeError(f"size must be a column name, got {size!r}")
            wanted[size] = ""
        data = read_columns(str(path), wanted, where=where, delimiter=delimiter, optional=tuple(wanted),
                            stated=units)
        cols = {("size" if c == size else c): v for c, v in data.items() if c != "line"}
        if not cols:
            raise ValueError(f"{where}: none of the columns {', '.join(BURST_COLUMNS)}"
                             + (f" or {size}" if size else "") + " in the header")
        for name, v in cols.items():
            bad = ~np.isfinite(v) | ((v <= 0) if name in _SIZE_COLUMNS else np.zeros(v.shape, bool))
            if np.any(bad):
                k = int(np.flatnonzero(bad)[0])
                raise ValueError(f"{where} line {int(data['line'][k])}: {name} must be finite"
                                 + (" and > 0" if name in _SIZE_COLUMNS else "") + f", got {float(v[k])!r}")
        kw: dict[str, Any] = dict(cols)
        return cls(**kw, source=f"measured: {path}")

    def __repr__(self) -> str:
        th = "" if self.threshold is None else f", threshold {fmt_number(self.threshold, 3)}"
        return f"BurstCatalogue({len(self)} bursts, columns {list(self._columns())}{th}, dropped {self.n_dropped})"


def _crossing(t0: np.ndarray, t1: np.ndarray, p0: np.ndarray, p1: np.ndarray, h: float) -> np.ndarray:
    """Where the segments from (t0, p0) to (t1, p1) cross the level h."""
    return t0 + (h - p0) / (p1 - p0) * (t1 - t0)


def _integral(t: np.ndarray, p: np.ndarray, at: np.ndarray) -> np.ndarray:
    """∫_{t[0]}^{at} of the piecewise-linear interpolant of p, at each time of ``at`` (within [t[0], t[-1]])."""
    cum = np.r_[0.0, np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))]
    i = np.clip(np.searchsorted(t, at, side="right") - 1, 0, t.size - 2)
    frac = (at - t[i]) / (t[i + 1] - t[i])
    p_at = p[i] + frac * (p[i + 1] - p[i])
    return cum[i] + 0.5 * (p[i] + p_at) * (at - t[i])


def _excess_cumulative(t: np.ndarray, p: np.ndarray, h: float) -> np.ndarray:
    """``C[k]`` = ∫ max(p - h, 0) dt over the first k segments of the interpolant (a triangle at a crossing)."""
    e0, e1 = p[:-1] - h, p[1:] - h
    dt = np.diff(t)
    both = (e0 >= 0) & (e1 >= 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        part = np.where(e0 > 0, e0, e1) ** 2 / (2.0 * np.abs(e1 - e0)) * dt  # the triangle above h at a crossing
    seg = np.where(both, 0.5 * (e0 + e1) * dt, np.where((e0 > 0) | (e1 > 0), part, 0.0))
    return np.r_[0.0, np.cumsum(seg)]


def burst_catalogue(t: Any, power: Any, *, threshold: float, min_gap: float = 0.0) -> BurstCatalogue:
    """The bursts of a sampled power (module docstring of ``peelapprox/bursts/_catalogue.py``).

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing, at least 2.
    power : array_like
        The power at each time (an acoustic-emission power, a dissipation rate, any finite signal).
    threshold : float
        The level a burst exceeds (finite).
    min_gap : float
        Bursts separated by less than this [s] are one burst (an acoustic-emission "hit definition time"): its
        energy is the integral of the power over the whole of it, gaps included; its excess the sum of its
        parts' (the gaps are below the threshold); 0 (the default): every crossing pair is a burst.

    Returns
    -------
    BurstCatalogue
        Columns ``start, end, duration, energy, excess, peak, t_peak`` (and ``waiting``).

    Raises
    ------
    ValueError
        Times not strictly increasing or not finite, power not finite or of another length, fewer than 2
        samples, a threshold that is not finite, a negative min_gap.
    """
    t = times("t", t, lo=-math.inf)
    p = reals("power", power)
    if p.ndim != 1 or p.size != t.size:
        raise ValueError(f"power must be a 1-D array as long as t ({t.size}), got shape {p.shape}")
    if t.size < 2:
        raise ValueError(f"t and power must have at least 2 samples, got {t.size}")
    h = finite("threshold", threshold)
    min_gap = nonnegative("min_gap", min_gap)
    above = p > h
    edges = np.diff(above.astype(np.int8))
    ups = np.flatnonzero(edges == 1) + 1  # first sample above
    downs = np.flatnonzero(edges == -1) + 1  # first sample below again
    dropped = int(above[0]) + int(above[-1]) - int(bool(above.all()))
    if above[0]:
        downs = downs[1:]
    ups = ups[: downs.size]
    start = _crossing(t[ups - 1], t[ups], p[ups - 1], p[ups], h)
    end = _crossing(t[downs - 1], t[downs], p[downs - 1], p[downs], h)
    if min_gap > 0 and ups.size > 1:
        keep = np.r_[True, start[1:] - end[:-1] >= min_gap]  # a burst that starts a merged one
        last = np.r_[keep[1:], True]  # a burst that ends one
        ups, start = ups[keep], start[keep]
        downs, end = downs[last], end[last]
    cum_ex = _excess_cumulative(t, p, h)
    n = ups.size
    peak, tpk = np.empty(n), np.empty(n)
    for k in range(n):
        i, j = int(ups[k]), int(downs[k])  # samples i..j-1 above (and any gaps between merged parts)
        m = i + int(np.argmax(p[i:j]))
        peak[k], tpk[k] = p[m], t[m]
    excess = cum_ex[downs] - cum_ex[ups - 1]
    energy = _integral(t, p, end) - _integral(t, p, start)
    gap = f", bursts closer than {fmt_number(min_gap, 3)} s merged" if min_gap > 0 else ""
    return BurstCatalogue(start=start, end=end, duration=end - start, energy=energy, excess=excess,
                          peak=peak, t_peak=tpk, threshold=h, n_dropped=dropped,
                          source=f"burst_catalogue: threshold {fmt_number(h, 6)}, {t.size} samples{gap}")
