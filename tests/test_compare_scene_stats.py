"""``compare --scene X`` computes the statistics of the chosen scenes' runs only (issue 36, item 8)."""

from __future__ import annotations

import comparisons
from peelapprox.cli import main


def test_scene_restricts_the_statistics_runs(monkeypatch, capsys):
    """The runs handed to run_compare's statistics are exactly the chosen scenes' (of STAT_RUNS); all four
    without --scene; none with --no-stats.  run_compare itself is replaced (it would integrate the runs): what is
    asserted is what the CLI asks it for."""
    asked = []

    class Stop(Exception):
        pass

    def fake(scenes, *, statistics_runs, **kw):
        asked.append((scenes, tuple(statistics_runs)))
        raise Stop

    def call(argv: list[str]) -> None:
        try:
            main(argv)
        except Stop:
            pass

    monkeypatch.setattr(comparisons, "run_compare", fake)
    scene = next(n for n, sc in comparisons.SCENES.items() if sc.run == "V1-I1e-2")
    monkeypatch.setenv("PEELAPPROX_TRACEBACK", "1")  # the stand-in's exception comes back as it is
    call(["compare", "--scene", scene])
    call(["compare"])
    call(["compare", "--scene", scene, "--no-stats"])
    assert asked[0] == ([scene], ("V1-I1e-2",))
    assert asked[1][1] == comparisons.STAT_RUNS
    assert asked[2][1] == ()
