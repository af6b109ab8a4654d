"""Plots.  Every plot function draws into ``ax=`` (its axes) or ``fig=`` (an empty figure) when given, else into a
new :class:`matplotlib.figure.Figure` made without pyplot (:func:`new_figure`), and returns the figure.  A
figure drawn into that has no layout engine gets the constrained layout: titles clear the labels above them.

The package never calls ``matplotlib.use`` and never changes the backend of the session it runs in.  A figure it
makes itself is not registered with pyplot: it needs no backend, nothing has to close it, and in Jupyter it is
displayed once, as the value of the cell (``display(fig)`` shows it elsewhere).  To draw into a pyplot window,
pass your own: ``plot_trajectory(traj, fig=plt.figure())`` then ``plt.show()``.  Files are written by
:func:`save_figure` (the plot functions' ``path=`` too): fixed metadata, so the same figure gives the same
bytes.  matplotlib is imported on first use only (``import peelapprox`` loads none); the CLI's output-path
check (``peelapprox.cli._checks``) only asks it, lazily too, which image formats it can write.

The modules: ``_figure`` (figures, axes, the writer, titles), ``_trajectory`` (a run in time and in the v–F
plane), ``_segment`` (a reduced branch solution), ``_phase_diagram`` (a sweep over (V, I)) and
``_bifurcation`` (orbit diagrams and branches), ``_front`` (the peel front in space and time), ``_bursts`` (a
burst-size distribution with its fits).
"""

from ._bifurcation import MAX_BRANCHES, plot_bifurcation
from ._bursts import plot_burst_distribution
from ._figure import new_figure, pyplot, save_figure
from ._front import plot_front
from ._phase_diagram import cell_edges, plot_phase_diagram
from ._segment import plot_segment
from ._trajectory import TRAJECTORY_CYCLES, TRAJECTORY_PANELS, TrajectoryWindow, plot_trajectory, trajectory_window

__all__ = ["MAX_BRANCHES", "TRAJECTORY_CYCLES", "TRAJECTORY_PANELS", "TrajectoryWindow", "cell_edges", "new_figure",
           "plot_bifurcation", "plot_burst_distribution", "plot_front", "plot_phase_diagram", "plot_segment",
           "plot_trajectory", "pyplot", "save_figure", "trajectory_window"]
