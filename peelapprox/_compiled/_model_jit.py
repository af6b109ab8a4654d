"""The model's compiled pieces, inlined into every field that uses them: the ``cos θ`` closures (with the
geometry switch and the second derivative), the slow rates (FLOW1, FLOW2, flow3), the constraint rate (Eq. vdot)
and the regularised system XDAE with its Jacobian, each compiled from :mod:`peelapprox._compiled._generated`.

One place for them: :mod:`peelapprox.kernels` offers them to ``exact``, and the model variants' fields
(:mod:`peelapprox.kernels._variant_fields`) inline the same kernels.
"""

from __future__ import annotations

from . import _generated as _g
from ._jit import kernel

__all__ = ["closure_paper", "closure_exact", "closure", "closure_paper_d2", "closure_exact_d2", "closure_d2",
           "slow_rates", "constraint_rate", "regularized_rhs", "regularized_jacobian"]

#: ``(c, dc/dα)`` of the paper's closure ``cos θ = -sin α`` at ``(alpha, R, l)``.
closure_paper = kernel(inline="always")(_g.closure_paper)
#: ``(c, dc/dα)`` of the full geometry ``cos θ = -l sin α / L``.
closure_exact = kernel(inline="always")(_g.closure_exact)
#: FLOW1, FLOW2, flow3: ``(α̇, ω̇, Ḟ)``.
slow_rates = kernel(inline="always")(_g.slow_rates)
#: Eq. (vdot)'s numerator ``Ġ`` for ``G = F (1 + c)``.
constraint_rate = kernel(inline="always")(_g.constraint_rate)
#: XDAE with ``M = diag(1, 1, 1, ε)``, last row divided by ε.
regularized_rhs = kernel(inline="always")(_g.regularized_rhs)
#: Its Jacobian, a row-major 16-tuple.
regularized_jacobian = kernel(inline="always")(_g.regularized_jacobian)


#: ``(c, dc/dα, d²c/dα²)`` of the paper's closure.
closure_paper_d2 = kernel(inline="always")(_g.closure_paper_d2)
#: ``(c, dc/dα, d²c/dα²)`` of the full geometry.
closure_exact_d2 = kernel(inline="always")(_g.closure_exact_d2)


@kernel(inline="always")
def closure_d2(alpha, exact_geometry, R, l):
    """``(c, dc/dα, d²c/dα²)`` of the paper's closure (``exact_geometry == 0``) or of the full geometry (else): the
    Jacobian of the hybrid field needs the second derivative."""
    if exact_geometry == 0.0:
        return closure_paper_d2(alpha, R, l)
    return closure_exact_d2(alpha, R, l)


@kernel(inline="always")
def closure(alpha, exact_geometry, R, l):
    """``(c, dc/dα)`` of the paper's closure (``exact_geometry == 0``) or of the full geometry (else)."""
    if exact_geometry == 0.0:
        return closure_paper(alpha, R, l)
    return closure_exact(alpha, R, l)
