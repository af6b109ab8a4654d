"""Approximate-vs-exact comparison harness (segments, seeding, error tables, benchmarks)."""
