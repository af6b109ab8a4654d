"""The peel-force law ``f(v, V)``: what a law is, how it is evaluated, its folds, and its compiled form.

The modules, one concern each (private: the public names are offered by :mod:`peelapprox`):

* ``_force`` — :class:`PeelForce`, a law as plain data, and the checks of which laws a consumer runs;
* ``_kinds`` — what each kind of law (paper, family, expression, tabulated) does: one object per kind;
* ``_paper`` — the paper's law fvV, bitwise; ``_families`` — the families, each formula next to its defaults;
  ``_expression`` and ``_grammar`` — expression laws, parsed, never evaluated; ``_table`` — tabulated laws;
  ``_spline`` — smoothed laws (a C⁴ spline in ln v); ``_fit`` — fits to measured points (``PeelForce.fit``);
  ``_tablefile`` — a law from a CSV file (``PeelForce.from_csv``);
* ``_folds`` — the one fold record (:class:`BranchStructure`, also named ``Folds``) and the fold search;
  ``_structure`` — :func:`branch_structure` and :func:`fixed_point` of any law;
* ``_abi`` — the calling convention of a compiled law; ``_compiled`` — a law at one V as the drivers take it;
  ``_table_jit`` — the compiled tabulated law; ``codegen`` — the generator of the compiled laws (run
  ``python -m peelapprox.law.codegen`` after changing a family), writing ``_generated``; ``_cache`` — the
  verified on-disk cache of the compiled expression laws; ``_symbolic`` — any closed-form law as sympy.
"""

from __future__ import annotations

from ._fit import FitResult, FoldEstimate
from ._folds import BRANCHES, BREAKDOWN_LEVEL, BranchStructure, Folds
from ._force import ALL_LAWS, KINDS, PeelForce, law_label, require_law
from ._paper import branch_inverse, peel_force, peel_force_derivative
from ._structure import FixedPoint, branch_structure, fixed_point

__all__ = ["ALL_LAWS", "BRANCHES", "BREAKDOWN_LEVEL", "KINDS", "BranchStructure", "FitResult", "FixedPoint",
           "FoldEstimate", "Folds", "PeelForce",
           "branch_inverse", "branch_structure", "fixed_point", "law_label", "peel_force", "peel_force_derivative",
           "require_law"]
