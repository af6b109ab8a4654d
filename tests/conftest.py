import pytest

from peelapprox import PeelParams


@pytest.fixture(scope="session")
def p_low():
    """V=1, I=1e-5: the paper's low-inertia case (Fig. 3b,c)."""
    return PeelParams(V=1.0, I=1e-5)


@pytest.fixture(scope="session")
def p_high():
    """V=1, I=1e-2: the paper's high-inertia case (Fig. 4)."""
    return PeelParams(V=1.0, I=1e-2)
