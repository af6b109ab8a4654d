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

from peelapprox.plotting import (  # noqa: E402
    TRAJECTORY_CYCLES,
    new_figure,
    plot_bifurcation,
    plot_segment,
    plot_trajectory,
    trajectory_window,
)


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


# ---- issue 29: plots that show the attractor, readable and reproducible ----------------------------------------

@pytest.fixture(scope="module")
def settled():
    """20 s at V = 1, I = 1e-2 from the default start: its last returns repeat with period 8 within ~1e-5 of
    max F (the paper's Fig. 4 orbit), well inside the 1e-3 that trajectory_window asks."""
    return exact.simulate(PeelParams(V=1.0, I=1e-2), 20.0)


def test_trajectory_plot_names_units_parameters_and_every_line(run):
    """Hypothesis: every axis label carries a unit in brackets, the title names V and I with their units and
    the method, and the phase panel's legend lists each of its three line styles (exact: string equality)."""
    fig = plot_trajectory(run)
    labels = [a.get_xlabel() for a in fig.axes] + [a.get_ylabel() for a in fig.axes]
    assert all(lab.endswith(("[s]", "[N]", "[rad]", "[m/s]")) for lab in labels), labels
    assert "V = 1 m/s" in fig.get_suptitle() and "I = 0.01 kg m²" in fig.get_suptitle()
    assert "hybrid" in fig.get_suptitle()
    legend = fig.axes[3].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == ["f(v, V)", "orbit (v, F)", "folds B, D"]
    other = plot_trajectory(exact.simulate(PeelParams(V=1.0, I=1e-2, k=500.0), 0.3), cycles=None)
    assert "k = 500 N/m" in other.get_suptitle()  # a parameter off its default is named


def test_trajectory_window_of_a_periodic_run_is_whole_periods(settled):
    """Hypothesis: at V = 1, I = 1e-2 after 20 s the default window (5 cycles) rounds up to one period of the
    period-8 return map, from one AB→CD jump to the last: its span equals the period T of the orbit closed by
    Newton (periodic_orbit, n = 8) within 1e-4 relative (the run's returns are within ~1e-5 of the orbit's,
    its period within ~1e-6), and 16 cycles are 2 T."""
    T = exact.periodic_orbit(PeelParams(V=1.0, I=1e-2), n=8).period
    w = trajectory_window(settled)
    assert (w.period, w.cycles) == (8, 8)
    assert w.end - w.start == pytest.approx(T, rel=1e-4)
    w2 = trajectory_window(settled, 16)
    assert (w2.period, w2.cycles) == (8, 16) and w2.end - w2.start == pytest.approx(2 * T, rel=1e-4)


def test_simulate_plot_of_a_periodic_run_spans_whole_periods_densely(tmp_path, monkeypatch):
    """Hypothesis: ``simulate --plot`` at V = 1, I = 1e-2 (20 s, period 8) draws an x span of k whole periods,
    k an integer: span / T within 1e-4 of round(span / T) >= 1 (T from Newton's orbit; the run's period
    agrees to ~1e-6), with the axis fitted to the window (x limits equal its ends to 1e-12 s), and draws the
    densely resampled run: at least PLOT_SAMPLES (4000) points in the F(t) line, where the ~1300 stored
    steps of one period would be a few hundred."""
    import peelapprox.plotting as plotting
    from peelapprox.cli import main
    from peelapprox.cli.simulate import PLOT_SAMPLES

    drawn = []
    real = plotting.plot_trajectory

    def spy(*args, **kwargs):
        drawn.append(real(*args, **kwargs))
        return drawn[-1]

    monkeypatch.setattr(plotting, "plot_trajectory", spy)
    png = tmp_path / "run.png"
    assert main(["simulate", "--V", "1", "--I", "1e-2", "--t-end", "20", "--plot", str(png), "--quiet"]) == 0
    assert png.stat().st_size > 10_000
    T = exact.periodic_orbit(PeelParams(V=1.0, I=1e-2), n=8).period
    ax = drawn[0].axes[0]
    x = ax.lines[0].get_xdata()
    span = x[-1] - x[0]
    k = round(span / T)
    assert k >= 1 and span / T == pytest.approx(k, rel=1e-4)
    assert ax.get_xlim() == pytest.approx((x[0], x[-1]), abs=1e-12)
    assert x.size >= PLOT_SAMPLES and "period-8" in drawn[0].get_suptitle()


def test_saves_of_one_figure_are_byte_identical(run, tmp_path):
    """Hypothesis: save_figure (and so every ``path=``) writes the same bytes for the same figure: one figure
    object saved twice (PDF and SVG with a draw in between, what a ``show()`` does), and a fresh figure saved
    as PDF through ``path=``, with no software version or creation date in the file (exact: byte
    equality, and the keys absent from the bytes; a date would differ between two runs, so its absence is
    what makes the bytes reproducible, and it is read directly rather than waited for).  The F and v panels of
    ``run``: their constrained layout cycled among three layouts from draw to draw, and the PDF and SVG of
    three saves of one figure all differed before the save started the layout from the grid cells (the PDF
    and SVG checks below failed then).  Seven saves of a two-panel figure (the four-panel one's six and a 1 s
    sleep before): ~5 s of CPU."""
    from peelapprox.plotting import save_figure

    fig = plot_trajectory(run, panels=("F", "v"))
    for ext in ("png", "pdf", "svg"):
        a, b = tmp_path / f"a.{ext}", tmp_path / f"b.{ext}"
        save_figure(fig, a)
        if ext != "png":  # PNG's pixels hide the layout's ~1e-6 moves; its bytes only needed the fixed metadata
            fig.draw_without_rendering()  # the layout runs again, as on screen
        save_figure(fig, b)
        data = a.read_bytes()
        assert data == b.read_bytes(), ext
        assert b"Matplotlib v" not in data and b"CreationDate" not in data and b"<dc:date>" not in data, ext
    plot_trajectory(run, str(tmp_path / "fresh.pdf"), panels=("F", "v"))
    assert (tmp_path / "fresh.pdf").read_bytes() == (tmp_path / "a.pdf").read_bytes()


def test_plot_trajectory_draws_one_panel_on_one_axes(run):
    """Hypothesis: ``panels=("F",)`` takes one Axes (not a list), draws F(t) there and nothing else (exact:
    the drawn data are the window's stored F samples, one axes in the figure); on its own figure it makes one
    axes, and two panels make two, in the order given."""
    fig = new_figure()
    ax = fig.subplots()
    assert plot_trajectory(run, panels=("F",), ax=ax) is fig and len(fig.axes) == 1
    w = trajectory_window(run)
    t = np.asarray(run.t)
    m = (t >= w.start) & (t <= w.end)
    assert np.array_equal(ax.lines[0].get_ydata(), np.asarray(run.F)[m]) and ax.get_ylabel() == "F [N]"
    assert len(plot_trajectory(run, panels=("F",)).axes) == 1
    two = plot_trajectory(run, panels=("phase", "v"))
    assert [a.get_xlabel() for a in two.axes] == ["v [m/s]", "t [s]"]
    with pytest.raises(ValueError, match="panels"):
        plot_trajectory(run, panels=("F", "F"))


def test_titles_clear_the_x_labels_above_them_in_a_users_2x2(run):
    """Hypothesis: drawn into the user's own 2 x 2 (a figure without a layout engine, ``plt.subplots``'
    default), each lower panel's title box lies below the x label box of the panel above it (exact: a gap of
    at least 0 display pixels after layout); it overlapped before."""
    fig = new_figure(figsize=(11, 7.5), layout=None)
    axs = fig.subplots(2, 2)
    plot_trajectory(run, ax=axs)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    for col in (0, 1):
        label = axs[0, col].xaxis.label.get_window_extent(renderer)
        title = axs[1, col].title.get_window_extent(renderer)
        assert title.y1 <= label.y0, (col, title.y1, label.y0)


def _fake_branches(n_branches: int, n: int = 4):
    """Duck-typed exact.OrbitBranch objects (what plot_bifurcation reads): each with 5 points in V, a fold in
    the middle, a grazing end; branch k's returns are k + 1..n (+ V)."""
    from types import SimpleNamespace as NS

    params = PeelParams(V=1.0, I=1e-2)
    out = []
    for k in range(n_branches):
        start = NS(n=n, stable=True, return_map_values=np.arange(n) + 10.0 * k, params=params)
        points = [NS(value=1.0 + 0.1 * i, orbit=start if i == 0 else
                     NS(n=n, stable=i < 3, return_map_values=np.arange(n) + 10.0 * k + 0.1 * i, params=params))
                  for i in range(5)]
        fold = NS(kind="fold", value=1.25, orbit=points[2].orbit, marker=("s", "C3"))
        out.append(NS(parameter="V", points=points, bifurcations=(fold,), end_marker="x", end_value=1.45,
                      stopped="grazing"))
    return out


def test_bifurcation_plot_units_title_legend_and_one_marker_per_bifurcation():
    """Hypothesis: the x axis is "V [m/s]", the title names the fixed I (and not V), the legend lists the grey
    dots, the starting orbit, the fold, the end and both line styles; each bifurcation is one marker (one
    point drawn, not n = 4); lines are thin (0.9 pt) (exact: strings, counts)."""
    from types import SimpleNamespace as NS

    diagram = NS(parameter="V", values=np.array([1.0, 1.2, 1.4]),
                 returns=(np.array([1.0, 2.0]), np.array([1.5]), np.array([])))
    fig = plot_bifurcation(diagram, _fake_branches(1))
    ax = fig.axes[0]
    assert ax.get_xlabel() == "V [m/s]" and ax.get_ylabel().endswith("[N]")
    assert "I = 0.01 kg m²" in ax.get_title() and "V =" not in ax.get_title()
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts == ["brute-force runs: F at each AB→CD jump", "period-4 orbit from V = 1", "stable orbit",
                     "unstable orbit", "fold", "end: grazing"]
    folds = [ln for ln in ax.lines if ln.get_marker() == "s"]
    assert len(folds) == 1 and len(folds[0].get_xdata()) == 1
    assert {ln.get_linewidth() for ln in ax.lines if ln.get_linestyle() in ("-", "--")} == {0.9}


def test_bifurcation_plot_draws_a_chosen_subset_of_many_branches():
    """Hypothesis: of 30 branches the default draws MAX_BRANCHES (12) and says so in the title; ``select``
    draws exactly the branches named (numbered from 1) and ``max_branches=None`` all (exact: the count of
    fold markers, one per drawn branch)."""
    from peelapprox.plotting import MAX_BRANCHES

    many = _fake_branches(30)

    def folds(fig):
        return sum(1 for ln in fig.axes[0].lines if ln.get_marker() == "s")

    fig = plot_bifurcation(None, many)
    assert folds(fig) == MAX_BRANCHES == 12 and "12 of 30 branches" in fig.axes[0].get_title()
    assert folds(plot_bifurcation(None, many, select=[3, 7])) == 2
    assert folds(plot_bifurcation(None, many, max_branches=None)) == 30
    with pytest.raises(ValueError, match="select"):
        plot_bifurcation(None, many, select=[31])


def test_phase_diagram_title_names_the_fixed_parameters_and_axes_their_units():
    """Hypothesis: a sweep at k = 500 N/m has k in the phase diagram's title (V and I are its axes, not
    repeated), and both axes carry units (exact: strings)."""
    from types import SimpleNamespace as NS

    from peelapprox.plotting import plot_phase_diagram

    result = NS(values=lambda key: np.array([[1.0, 2.0], [3.0, 4.0]]), I_values=[1e-5, 1e-2], V_values=[1.0, 2.0],
                records=[{}] * 4, options={"k": 500.0}, force=None)
    ax = plot_phase_diagram(result, "jumps_mean_period").axes[0]
    assert "k = 500 N/m" in ax.get_title() and "V =" not in ax.get_title() and "4/4 points" in ax.get_title()
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("V [m/s]", "I [kg m²]")


def test_bifurcation_plot_select_refuses_a_non_number_before_any_run(capsys):
    """Hypothesis: ``bifurcation --plot-select 0`` (branches are numbered from 1) is a usage error, exit status
    2, before the diagram's runs start (exact: the status and the option named)."""
    from peelapprox.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["bifurcation", "--V", "1", "--I", "1e-2", "--param", "V", "--range", "0.9:1.1:3", "--plot-select", "0,2"])
    assert exc.value.code == 2 and "--plot-select" in capsys.readouterr().err


def test_bad_plot_arguments_are_named(run):
    """Hypothesis: every malformed argument of the trajectory and bifurcation plots is a TypeError or ValueError
    naming it (cycles 0, -1, "5", NaN, 2.5; panels None, 5, a nested list; dense not a run; select an int, empty
    or out of range), never an unrelated exception from numpy or matplotlib."""
    from peelapprox.plotting import plot_bifurcation, plot_trajectory, trajectory_window

    for bad in (0, -1, "5", float("nan"), 2.5, True):
        with pytest.raises((TypeError, ValueError), match="cycles"):
            trajectory_window(run, bad)
    for kw in (dict(panels=None), dict(panels=5), dict(panels=("F", ["v"])), dict(panels=()), dict(dense=5)):
        with pytest.raises((TypeError, ValueError), match=next(iter(kw))):
            plot_trajectory(run, **kw)
    for select in (1, [], [1]):
        with pytest.raises((TypeError, ValueError), match="select"):
            plot_bifurcation(None, [], select=select)


def test_law_label_names_every_kind_but_the_default():
    """Hypothesis: a title names the law unless it is the paper's fvV: a family by name and coefficients, an
    expression by its formula, a table or a smoothed law by kind and display (cut at 60 characters)."""
    import numpy as np

    from peelapprox import PeelForce
    from peelapprox.plotting._figure import law_label

    v = np.logspace(-1, 1, 30)
    f = PeelForce.cubic().f(v, 1.0)
    assert law_label(PeelForce.paper()) == ""
    assert law_label(PeelForce.cubic()) == "law cubic(a=150, b=300, c=300, d=80)"
    assert law_label(PeelForce.expression("300 - 110*v + 21*v**2")) == "law f = 21*v**2 - 110*v + 300"
    assert law_label(PeelForce.tabulated(v, f)).startswith("law tabulated (V=None: 30 points")
    assert law_label(PeelForce.smoothed(v, f)).startswith("law smoothed (V=None: C4 spline")
