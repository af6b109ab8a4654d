"""The figure plumbing every plot shares: a pyplot-free figure, the axes a plot draws into, the one writer
(byte-reproducible files) and the parameters of a run in words, for titles."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["new_figure", "pyplot", "save_figure"]

#: The fixed metadata each format gets from :func:`save_figure`: no software version, no creation date (the
#: keys matplotlib would otherwise fill with the running version and the clock), so that the same figure
#: gives the same bytes on any machine and at any time.
_METADATA: dict[str, dict[str, str | None]] = {
    "png": {"Software": None},
    "pdf": {"Creator": None, "Producer": None, "CreationDate": None},
    "svg": {"Creator": None, "Date": None},
    "ps": {"Creator": "peelapprox"},  # PostScript prints None as "None"; its date comes from SOURCE_DATE_EPOCH
    "eps": {"Creator": "peelapprox"},
}

#: The SVG writer's id salt (its default is random per process: ids, hence bytes, would differ between runs).
_SVG_HASHSALT = "peelapprox"

#: The default value and unit of the parameters a title names when they differ from the default.
_DEFAULTS = {"k": (1000.0, "N/m"), "R": (0.1, "m"), "l": (1.0, "m")}

#: The unit of each parameter a plot can have on an axis (a law's coefficients have their own, not known here).
UNITS = {"V": "m/s", "I": "kg m²", "k": "N/m", "R": "m", "l": "m", "tape_mass": "kg", "load": "N",
         "load_mass": "kg"}


def pyplot():
    """``matplotlib.pyplot``, imported on first use.  It does not choose or change the backend (the session's,
    or matplotlib's automatic choice: Agg without a display); the package's own figures do not need it
    (:func:`new_figure`)."""
    import matplotlib.pyplot as plt

    return plt


def new_figure(*, figsize: tuple[float, float] | None = None, layout: Any = "constrained", **kwargs: Any):
    """A :class:`matplotlib.figure.Figure` made without pyplot: no backend, no global state, nothing to close.

    It is saved with :func:`save_figure` (or ``fig.savefig(path)``; the format from the extension), and shown
    in Jupyter as a cell's value.  The default constrained layout keeps titles, labels and legends of its
    panels apart.  ``kwargs`` go to ``Figure``.
    """
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout=layout, **kwargs)


def save_figure(fig: Any, path: str | os.PathLike, *, dpi: float = 120, **kwargs: Any) -> None:
    """Write ``fig`` to ``path`` (format from the extension), byte-reproducibly: the same figure gives the
    same bytes on every write, on any machine with the same matplotlib and fonts: saved twice, after a
    ``show()``, or drawn afresh as in each run of a script.  (The constrained layout refines the positions it
    finds on every draw; the save starts it from the grid cells, as a new figure's first draw does, and puts
    the axes back afterwards.  A colorbar's axes start where the last draw left them: a figure with a colorbar
    is byte-identical from save to save, and to a fresh figure's save when not drawn in between.)

    The file gets fixed metadata (no software version, no creation date: PNG ``Software``, PDF ``Creator``,
    ``Producer`` and ``CreationDate``, SVG ``Creator`` and ``Date``, PS ``Creator``; the PS ``CreationDate``
    from ``SOURCE_DATE_EPOCH``, 0 unless set) and SVG ids from a fixed salt (``svg.hashsalt``).  ``kwargs`` go
    to ``savefig`` (a ``metadata`` given there is added to the fixed one).  The figure stays open (whoever
    made it owns it: a :func:`new_figure` needs no closing).
    """
    import matplotlib

    fmt = kwargs.pop("format", None) or os.path.splitext(os.fspath(path))[1].lstrip(".").lower() or \
        matplotlib.rcParams["savefig.format"]
    metadata = {**_METADATA.get(fmt, {}), **(kwargs.pop("metadata", None) or {})}
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    positions = _positions(fig)
    try:
        if fmt in ("ps", "eps") and epoch is None:  # the one date the PostScript writer takes from outside
            os.environ["SOURCE_DATE_EPOCH"] = "0"
        _start_layout(fig)
        with matplotlib.rc_context({"svg.hashsalt": _SVG_HASHSALT}):
            fig.savefig(path, dpi=dpi, format=fmt, metadata=metadata or None, **kwargs)
    finally:
        if fmt in ("ps", "eps") and epoch is None:
            os.environ.pop("SOURCE_DATE_EPOCH", None)
        _restore(positions)


def _positions(fig: Any) -> list[tuple[Any, Any, Any, bool]]:
    """Every axes of ``fig`` (its subfigures' too) with its original and active positions and whether it is in
    the layout: what a draw under a layout engine changes, for :func:`_restore`."""
    return [(ax, ax.get_position(original=True).frozen(), ax.get_position(original=False).frozen(),
             ax.get_in_layout()) for ax in getattr(fig, "axes", ())]


def _restore(positions: list[tuple[Any, Any, Any, bool]]) -> None:
    """Put the axes back where :func:`_positions` found them: a save leaves the figure's layout as it was."""
    for ax, original, active, in_layout in positions:
        ax.set_position(original, which="original")
        ax.set_position(active, which="active")
        ax.set_in_layout(in_layout)


def _start_layout(fig: Any) -> None:
    """Under the constrained layout, every grid axes in the layout back at its grid cell (where a new figure
    has it), so that the layout the save runs starts where a fresh figure's first draw does.

    The constrained layout refines the positions it finds (two passes from the current positions, whose tick
    labels' sizes it measures): drawn again, a figure's axes move by ~1e-6 of the figure, and some figures
    cycle between a few layouts, so without this start a PDF or SVG saved twice (or after a ``show()``) was
    not byte-identical.  Axes placed by hand (out of the layout) and axes without a grid cell (a colorbar's)
    are left where they are; :func:`_restore` puts them all back after the save."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine  # matplotlib is loaded: fig is its figure

    engine = fig.get_layout_engine() if hasattr(fig, "get_layout_engine") else None
    if not isinstance(engine, ConstrainedLayoutEngine):
        return
    for ax in fig.axes:
        spec = ax.get_subplotspec() if hasattr(ax, "get_subplotspec") else None
        if spec is not None and ax.get_in_layout():
            ax.set_subplotspec(spec)


def _save(fig: Any, path: str | None, dpi: int = 120) -> None:
    """:func:`save_figure` when ``path`` is given (the plot functions' ``path=``)."""
    if path:
        save_figure(fig, path, dpi=dpi)


def _canvas(ax: Any, fig: Any, shape: tuple[int, int], figsize: tuple[float, float], **subplot_kw: Any):
    """``(figure, axes)``: ``axes`` an object array of ``shape``, from ``ax`` (that many axes; one Axes when
    ``shape`` is ``(1, 1)``), from ``fig`` (its new subplots) or from a :func:`new_figure`; a figure without a
    layout engine gets the constrained layout (:func:`_lay_out`).

    Raises
    ------
    ValueError
        ``ax`` and ``fig`` both given, or ``ax`` not ``shape[0] * shape[1]`` axes.
    TypeError
        ``ax`` not matplotlib axes, ``fig`` not a figure.
    """
    n = shape[0] * shape[1]
    if ax is not None and fig is not None:
        raise ValueError("ax and fig: give one of them (the figure of ax is where it is drawn)")
    if ax is not None:
        flat = list(np.ravel(np.asarray(ax, dtype=object))) if isinstance(ax, (Sequence, np.ndarray)) else [ax]
        if len(flat) != n:
            raise ValueError(f"ax must be {n} axes (this plot has {shape[0]} x {shape[1]} panels), got {len(flat)}")
        for a in flat:
            if not (hasattr(a, "plot") and hasattr(a, "figure")):
                raise TypeError(f"ax must be matplotlib axes, got {type(a).__name__}")
        _lay_out(flat[0].figure)
        return flat[0].figure, np.array(flat, dtype=object).reshape(shape)
    if fig is None:
        fig = new_figure(figsize=figsize)
    elif not hasattr(fig, "subplots"):
        raise TypeError(f"fig must be a matplotlib figure, got {type(fig).__name__}")
    _lay_out(fig)
    axs = fig.subplots(*shape, squeeze=False, **subplot_kw)
    return fig, axs


def _lay_out(fig: Any) -> None:
    """Give ``fig`` the constrained layout if it has no layout engine (``plt.subplots(2, 2)``'s default): the
    panels' titles would otherwise overlap the x labels of the panels above them."""
    get = getattr(fig, "get_layout_engine", None)
    if get is not None and get() is None:
        fig.set_layout_engine("constrained")


def axis_label(name: str) -> str:
    """``name`` with its unit for an axis: ``"V [m/s]"``; a law's coefficient (no unit known here) as
    ``"c (law coefficient)"``."""
    unit = UNITS.get(name)
    return f"{name} [{unit}]" if unit else f"{name} (law coefficient)"


def params_label(params: Any, *, skip: str | tuple[str, ...] = ()) -> str:
    """The parameters of a run for a title: ``"V = 1 m/s, I = 0.01 kg m²"``, then k, R, l where they differ
    from the defaults, the law when it is not the paper's and the model variant (:func:`model_label`);
    ``skip`` leaves out the ones a plot sweeps (its axes)."""
    if params is None:
        return ""
    skip = (skip,) if isinstance(skip, str) else tuple(skip)
    parts = [f"{name} = {getattr(params, name):g} {UNITS[name]}" for name in ("V", "I") if name not in skip]
    for name, (default, unit) in _DEFAULTS.items():
        value = getattr(params, name, default)
        if name not in skip and value != default:
            parts.append(f"{name} = {value:g} {unit}")
    law = law_label(getattr(params, "force", None))
    if law:
        parts.append(law)
    return ", ".join(parts) + model_label(params)


def law_label(force: Any) -> str:
    """``"law cubic(a=150, b=300, c=280, d=80)"`` for a family law, ``"law f = 21*v**2 - 110*v + 300"`` for an
    expression, ``"law tabulated (V=None: 30 points, ...)"`` for a table or a smoothed law (its display, cut at
    60 characters); ``""`` for the paper's fvV (the default)."""
    if force is None or getattr(force, "kind", "paper") == "paper":
        return ""
    name = getattr(force, "name", None)
    if name is not None:
        shown = ", ".join(f"{k}={v:g}" for k, v in dict(getattr(force, "coefficients", None) or ()).items())
        return f"law {name}" + (f"({shown})" if shown else "")
    text = str(getattr(force, "display", "") or "")
    text = text if len(text) <= 60 else text[:57] + "..."
    if force.kind == "expression":
        return f"law f = {text.strip(chr(39))}"
    return f"law {force.kind} ({text})" if text else f"law {force.kind}"


def model_label(params: Any) -> str:
    """A model variant of ``params`` in words, for a title, with a leading ``", "``: ``", tape mass m = 0.0001
    kg"``, ``", load F_L = 245 N on M = 25 kg"`` (both, for a massive tape under a load); ``""`` for the paper's
    model (its titles as before the variants existed)."""
    parts = []
    m = getattr(params, "tape_mass", None)
    if m:
        parts.append(f"tape mass m = {m:g} kg")
    if getattr(params, "loading", "velocity") == "load":
        if not m:
            parts.append("massless tape")
        load, mass = getattr(params, "load", None), getattr(params, "load_mass", None)
        parts.append((f"load F_L = {load:.4g} N" if load is not None else "load")
                     + (f" on M = {mass:g} kg" if mass is not None else ""))
    return "".join(", " + x for x in parts)
