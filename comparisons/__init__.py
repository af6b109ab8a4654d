"""Approximate-vs-exact comparison harness (segments, seeding, error tables, benchmarks)."""

from ._compare import DEFAULT_MODELS, ComparisonRow, compare
from ._segments import Segment, segments

__all__ = ["Segment", "segments", "compare", "ComparisonRow", "DEFAULT_MODELS"]
