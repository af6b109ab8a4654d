"""The escape return of a weakly unstable orbit of the reduced map (``ApproximateAttractor.escape_returns``).

Oracles: the exact model's own escape and multiplier at seeded random points, computed by
``python -m comparisons.benchmark.approx_targets --points 100 --seed 1 --escapes 10`` and stored below as data (the
exact run from the solver's default start, :func:`exact.simulate` at rtol 1e-10 with ``save="jumps"``; the escape
return is the first AB→CD jump after the run's closest approach to the period-1 orbit of
:func:`exact.periodic_orbit` whose force deviates from the orbit's by more than the reduced orbit's force drop;
``|μ|`` is that exact orbit's largest multiplier).  The last test recomputes the exact multiplier (~1 s).
"""

from __future__ import annotations

import warnings

import pytest

import exact
from peelapprox import PeelParams, approximate_attractor

#: ``(V, I, exact escape return, exact orbit's largest |μ|)`` at two of the ten escape points of the seed-1
#: benchmark (``comparisons.benchmark.approx_targets.points(100, 1)``; the benchmark command in the module
#: docstring): the two where the default chain's own |μ| - 1 (5.57e-4 against 2.13e-3, 1.46e-4 against 1.95e-4)
#: put the escape furthest off (826 against 222, 24127 against 17556, before the full chain's rate was used).
EXACT_ESCAPES = (
    (2.4833593849423576, 0.004408645032101619, 222, 1.0021348931194314),
    (4.427839671559062, 0.006240640779560414, 17556, 1.0001950417433036),
)
FULL = dict(alpha_model="genalpha", v_equation="fullvdot", cd_alpha_model="genalpha", cd_v_equation="fullvdot")
#: Airy1 + approxvdot on both branches: a chain whose escape rate comes from the full chain where its own |μ| is
#: near 1 (``escape_multiplier``; the default at high inertia until the full chain became the default everywhere).
AIRY = dict(alpha_model="airy1", v_equation="approxvdot", cd_alpha_model="airy1", cd_v_equation="approxvdot")


def _rate(a) -> float:
    """The |μ| that set the escape law's rate: ``escape_multiplier``'s where there is one, else the map's own."""
    return abs(a.escape_multiplier) if a.escape_multiplier is not None else max(abs(m) for m in a.multipliers)


def _left(p: PeelParams, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = approximate_attractor(p, start="solver", warn=False, **kw)
    left = [a for a in o.alternatives if a.escape_returns is not None and a.period == 1]
    assert left, f"the map left no period-1 orbit at V = {p.V}, I = {p.I}"
    return left[0]


@pytest.mark.parametrize("V, I, k_exact, mu_exact", EXACT_ESCAPES)
def test_escape_return_within_the_target_of_the_exact_run(V, I, k_exact, mu_exact):
    """Stored exact oracle (module docstring).  From the solver's start the default chain (the full branch dynamics
    linearised in α at every inertia) leaves the weakly unstable small mode; its escape return is within 20 % of
    the exact run's (the target's tolerance: the escape return is ``k0 + ln(threshold/A)/ln|μ|``, and the amplitude
    ``A`` is the map's own; measured -6.3 % and -0.2 %), and the rate it used, its own ``|μ| - 1``, within 2 % of the
    exact orbit's (measured 0.3 % and 0.03 %; 0.4 % at worst over the benchmark's ten points, the rest of the full
    chain's error being O(α²) with α ≈ 0.01-0.06 at the jumps).  With Airy1 + approxvdot's own rate the first
    point's escape was 826 (+272 %), the second's 24127 (+37 %): the test fails if a chain that drops the O(α)
    terms sets the rate."""
    a = _left(PeelParams(V=V, I=I))
    assert abs((_rate(a) - 1.0) / (mu_exact - 1.0) - 1.0) < 0.02
    assert abs(a.escape_returns / k_exact - 1.0) < 0.2


#: ``(V, I, exact escape return, exact orbit's largest |μ|)`` at a seed-1 point (the same benchmark and command, with
#: ``--escapes 20``) where the default map's period-1 orbit from the solver's start is weakly stable (|μ| 0.99974)
#: and the exact one weakly unstable.
EXACT_STAYS = (3.058514854738682, 0.008747337560936048, 2008, 1.000516535901718)


def test_an_orbit_the_map_stays_on_gets_the_exact_runs_escape():
    """Stored exact oracle (module docstring).  With Airy1 + approxvdot the map settles on a period-1 orbit it finds
    weakly stable, its prediction from the solver's start; the full chain's orbit is unstable as the exact one is
    (the default chain leaves it: its escape 1991 against the exact 2008), so the prediction
    carries an escape return: within 20 % of the exact run's (the target's tolerance; measured +1.5 %), its rate
    within 2 % of the exact orbit's |μ| - 1 (measured 0.05 %; 7 % at worst at the 14 such orbits measured, so the
    bound is the one of this point, not of the class).  Before, a stable orbit had no escape return at all."""
    V, I, k_exact, mu_exact = EXACT_STAYS
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = approximate_attractor(PeelParams(V=V, I=I), start="solver", warn=False, **AIRY)
    assert o.period == 1 and o.stable and o.escape_multiplier is not None and o.escape_returns is not None
    assert abs((abs(o.escape_multiplier) - 1.0) / (mu_exact - 1.0) - 1.0) < 0.02
    assert abs(o.escape_returns / k_exact - 1.0) < 0.2


def test_no_escape_return_where_the_map_settles_from_a_deviation_as_large_as_the_orbit():
    """Stored exact oracle (the same benchmark): at this seed-1 point the map of Airy1 + approxvdot settles on a
    period-1 orbit it finds weakly stable, from a deviation that, at the full chain's rate, is already as large as
    the orbit's force drop;
    the exact run leaves the orbit at return 172 (the exact |μ| 1.00307).  The linear law has no e-fold to run
    there (it would say 40, the map's settling return: -77 %; 3 of 3 such escapes were 73-77 % off), so the
    prediction carries the full chain's multiplier, within 2 % of the exact one in |μ| - 1 (measured 1.5 %), and no
    escape return rather than a wrong one."""
    p = PeelParams(V=1.7032415340471847, I=0.010714235142583683)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = approximate_attractor(p, start="solver", warn=False, **AIRY)
    assert o.period == 1 and o.stable and o.escape_returns is None and o.escape_multiplier is not None
    assert abs((abs(o.escape_multiplier) - 1.0) / (1.003074497139905 - 1.0) - 1.0) < 0.02


#: ``(V, I, exact escape return, exact orbit's largest |μ|)`` at the three points of the escape benchmark (the same
#: command, ``--escapes 20``; seed 1's two, seed 2's one) where the map's deviation at its Newton on the period-1 orbit
#: is already one force drop: stayed on with Airy1 + approxvdot (the test above), left with the default chain.
EXACT_ALREADY_GONE = (
    (1.7032415340471847, 0.010714235142583683, 172, 1.003074497139905),
    (1.5618394109371796, 0.014632175964579521, 31, 1.0029857734584966),
    (1.2085835138825265, 0.06104553039523779, 147, 1.0016410797377928),
)


@pytest.mark.parametrize("V, I, k_exact, mu_exact", EXACT_ALREADY_GONE)
def test_no_escape_return_where_the_map_leaves_an_orbit_from_a_deviation_as_large_as_it(V, I, k_exact, mu_exact):
    """Stored exact oracle (module docstring).  From the solver's start the default chain (genalpha + fullvdot) finds
    this period-1 orbit unstable, as the exact model does, and leaves it, but its deviation at its Newton (return 40)
    is already the orbit's force drop: the linear law has no e-fold to run and would say 40, the map's own return,
    against the exact run's ``k_exact`` (172, 31, 147: 73-77 % off both ways).  So the orbit left is reported
    unstable (its own multipliers, ``escape_multiplier`` None: the rate would be the map's own) with no escape
    return rather than a wrong one.  Its |μ| - 1 within 10 % of the exact orbit's (measured -1.5 %, -2.1 %, -8.6 %:
    the 2 % of the small modes above does not hold at these low-V orbits, so the bound is these three's, not the
    class's).  Fails if the law answers (any number) for such an orbit (it answered 40 before)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = approximate_attractor(PeelParams(V=V, I=I), start="solver", warn=False)
    left = [a for a in o.alternatives if a.period == 1 and a.stable is False]
    assert len(left) == 1, f"the map left no period-1 orbit at V = {V}, I = {I}"
    a = left[0]
    assert a.escape_returns is None and a.escape_multiplier is None
    assert abs((max(abs(m) for m in a.multipliers) - 1.0) / (mu_exact - 1.0) - 1.0) < 0.1


def test_the_full_chain_keeps_its_own_rate():
    """Stored exact oracle.  Run with the full chain itself (genalpha + fullvdot on both branches), the map's own
    multiplier sets the rate (``escape_multiplier`` None, nothing to refine), and its |μ| - 1 is the exact orbit's
    within 2 % (the same bound as above: it is the same Newton on the same chain) at the first point of
    :data:`EXACT_ESCAPES`."""
    V, I, _, mu_exact = EXACT_ESCAPES[0]
    a = _left(PeelParams(V=V, I=I), **FULL)
    assert a.escape_multiplier is None and a.multipliers is not None
    assert abs((max(abs(m) for m in a.multipliers) - 1.0) / (mu_exact - 1.0) - 1.0) < 0.02


def test_escape_rate_against_the_exact_periodic_orbit():
    """Independent oracle computed here: :func:`exact.periodic_orbit` (Newton on the full DAE's section, seeded by
    a 3 s exact run from the solver's start, which sits on the small mode: the exact escape is at return 222, about
    5 s) at the first point of :data:`EXACT_ESCAPES`.  The escape law's |μ| - 1 within 2 % of the exact orbit's (as
    above)."""
    V, I, _, _ = EXACT_ESCAPES[0]
    p = PeelParams(V=V, I=I)
    orbit = exact.periodic_orbit(p, start=exact.simulate(p, 3.0, rtol=1e-10, save="jumps"), n=1, max_wall=120.0)
    mu_exact = max(abs(m) for m in orbit.multipliers)
    a = _left(p)
    assert abs((_rate(a) - 1.0) / (mu_exact - 1.0) - 1.0) < 0.02
