"""Approximate-vs-exact comparison harness (segments, seeding, error tables, benchmarks)."""

from ._segments import Segment, segments

__all__ = ["Segment", "segments"]
