"""The sweep's phase diagram labels its colour bar and explains its blank cells (issue 36, item 10)."""

from __future__ import annotations

from pathlib import Path

DOCS_SWEEP = Path(__file__).resolve().parent.parent / "docs" / "sweep"


def test_colorbar_label_and_blank_cell_explained():
    """The stored sweep of docs/sweep: the Lyapunov figure's colour bar reads "largest Lyapunov exponent
    [bit/s]" (not the record key), and the one blank cell (V = 0.5, I = 1e-4, a breakdown) carries an "x" with
    its status in the legend (exact strings)."""
    from comparisons.sweep import load_sweep
    from peelapprox.plotting import plot_phase_diagram

    r = load_sweep(str(DOCS_SWEEP))
    fig = plot_phase_diagram(r, "lyapunov_bits_per_s")
    ax, cax = fig.axes[0], fig.axes[1]
    assert cax.get_ylabel() == "largest Lyapunov exponent [bit/s]"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["no value: breakdown:no_root"]
    offsets = ax.collections[-1].get_offsets()
    assert offsets.shape == (1, 2) and tuple(offsets[0]) == (0.5, 1e-4)
