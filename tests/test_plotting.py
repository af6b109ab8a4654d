"""The plot functions' conventions: they leave the session's matplotlib backend alone, draw into
``ax=``/``fig=`` when given and return the figure, and show a readable window of a long stick-slip run."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import exact
from peelapprox import PeelParams, reduced_segment, return_map

pytest.importorskip("matplotlib")

from peelapprox.plotting import TRAJECTORY_CYCLES, new_figure, plot_bifurcation, plot_segment, plot_trajectory  # noqa: E402


@pytest.fixture(scope="module")
def run():
    """2 s of stick-slip at V = 1, I = 1e-2 (about 70 AB→CD returns per second)."""
    return exact.simulate(PeelParams(V=1.0, I=1e-2), 2.0)


@pytest.fixture(scope="module")
def seg():
    return reduced_segment(PeelParams(V=1.0, I=1e-2), "CD", F_in=295.6, alpha_in=-0.0304, alphadot_in=-160.0,
                           v_in=15.54, v_f=8.7, t_eval=np.linspace(0.0, 1e-3, 50))


def test_plot_functions_leave_an_interactive_backend_alone(tmp_path):
    """Hypothesis: a session on an interactive-looking backend (a GUI-style ``module://`` backend, chosen before
    the package is imported, as Qt/Tk/ipympl sessions do) keeps it after every plot function ran, with and
    without ``path``, and pyplot holds none of the package's figures (exact: string and list equality).  The
    earlier ``pyplot()`` switched any such backend to Agg, breaking ``plt.show()``."""
    (tmp_path / "fake_gui_backend.py").write_text(textwrap.dedent("""
        from matplotlib.backend_bases import FigureManagerBase, _Backend
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        class FigureCanvasFakeGui(FigureCanvasAgg):
            manager_class = FigureManagerBase

        @_Backend.export
        class _BackendFakeGui(_Backend):
            FigureCanvas = FigureCanvasFakeGui
            FigureManager = FigureManagerBase
            mainloop = None
    """))
    code = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {str(tmp_path)!r})
        import matplotlib
        matplotlib.use("module://fake_gui_backend")
        import matplotlib.pyplot as plt
        import numpy as np
        import exact
        from peelapprox import PeelParams, reduced_segment
        from peelapprox.plotting import plot_bifurcation, plot_segment, plot_trajectory, pyplot
        tr = exact.simulate(PeelParams(V=1.0, I=1e-2), 0.3)
        seg = reduced_segment(PeelParams(V=1.0, I=1e-2), "CD", F_in=295.6, alpha_in=-0.0304, alphadot_in=-160.0,
                              v_in=15.54, v_f=8.7)
        plot_trajectory(tr)
        plot_trajectory(tr, {str(tmp_path / "t.png")!r})
        plot_segment(seg, {str(tmp_path / "s.png")!r})
        plot_bifurcation(None, ())
        pyplot()
        print(matplotlib.get_backend())
        print(plt.get_fignums())
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[-3:-1] == ["module://fake_gui_backend", "[]"]
    assert (tmp_path / "t.png").stat().st_size > 10_000 and (tmp_path / "s.png").stat().st_size > 10_000


def test_plot_functions_draw_into_ax_or_fig_and_return_the_figure(run, seg):
    """Hypothesis: with ``ax=`` the panels are drawn on those axes (in the documented order) and their figure is
    returned; with ``fig=`` that figure gets the panels and is returned; neither: a new figure not managed by
    pyplot (exact: identity and counts)."""
    fig = new_figure()
    axs = fig.subplots(2, 2)
    assert plot_trajectory(run, ax=axs) is fig
    assert axs[0, 0].get_ylabel() == "F [N]" and axs[1, 1].get_xlabel() == "v [m/s]"
    fig2 = new_figure()
    assert plot_segment(seg, fig=fig2) is fig2 and len(fig2.axes) == 3
    fig3 = new_figure()
    ax = fig3.subplots()
    assert plot_bifurcation(None, (), ax=ax) is fig3 and len(fig3.axes) == 1
    own = plot_trajectory(run)
    assert own is not fig and len(own.axes) == 4
    import matplotlib.pyplot as plt

    assert all(plt.figure(n) is not own for n in plt.get_fignums())


def test_plot_functions_refuse_ax_and_fig_together_and_a_wrong_number_of_axes(run):
    """Hypothesis: the errors name the argument (ValueError for a wrong count or both given, TypeError for
    something that is not axes)."""
    fig = new_figure()
    axs = fig.subplots(2, 2)
    with pytest.raises(ValueError, match="ax and fig"):
        plot_trajectory(run, ax=axs, fig=fig)
    with pytest.raises(ValueError, match="ax must be 4 axes"):
        plot_trajectory(run, ax=axs[0])
    with pytest.raises(TypeError, match="ax must be matplotlib axes"):
        plot_trajectory(run, ax=[1, 2, 3, 4])
    with pytest.raises(ValueError, match="cycles"):
        plot_trajectory(run, cycles=0)


def test_plot_trajectory_shows_the_last_cycles_by_default(run):
    """Hypothesis: by default the time panels start at the AB→CD jump TRAJECTORY_CYCLES returns before the last
    one and end at the run's end (exact: the stored samples of that span); ``cycles=None`` draws every stored
    sample."""
    t_k, _ = return_map(run, with_times=True)
    assert t_k.size > TRAJECTORY_CYCLES + 1
    t = np.asarray(run.t)
    drawn = plot_trajectory(run).axes[0].lines[0].get_xdata()
    assert np.array_equal(drawn, t[(t >= t_k[-TRAJECTORY_CYCLES - 1]) & (t <= t[-1])])
    assert np.array_equal(plot_trajectory(run, cycles=None).axes[0].lines[0].get_xdata(), t)
    assert f"the last {TRAJECTORY_CYCLES} of {t_k.size - 1} cycles" in plot_trajectory(run).get_suptitle()
