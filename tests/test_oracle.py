"""The refactor oracle's comparison (``comparisons.oracle.compare``) on synthetic outputs.

Running the oracle itself takes ~20 s and is what a refactor's author does before and after; these tests
check that its comparison is exact in the ways that matter: one flipped bit, the sign of zero, a dtype, a
missing array, a changed JSON value are differences; timing fields are not.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from comparisons.oracle import compare


def _write(d, arrays, sweep=None, cmp=None):
    d.mkdir()
    np.savez(d / "arrays.npz", **arrays)
    (d / "sweep.json").write_text(json.dumps(sweep if sweep is not None else [{"I": 1e-4, "wall": 1.0}]))
    (d / "compare.json").write_text(json.dumps(cmp if cmp is not None else {"rows": [{"x": 1.5, "wall_s": 2.0}]}))


BASE = {"a": np.array([1.0, 0.0, 3.0]), "n": np.array([5])}


def test_identical_outputs_compare_equal(tmp_path):
    """Hypothesis: two directories written from the same data compare identical (empty difference list),
    even when their timing fields differ."""
    _write(tmp_path / "x", BASE, [{"I": 1e-4, "wall": 1.0}], {"rows": [{"x": 1.5, "wall_s": 2.0}]})
    _write(tmp_path / "y", BASE, [{"I": 1e-4, "wall": 9.0}], {"rows": [{"x": 1.5, "wall_s": 7.0}]})
    assert compare(tmp_path / "x", tmp_path / "y") == []


@pytest.mark.parametrize("other, what", [
    ({"a": np.array([1.0, 0.0, np.nextafter(3.0, 4.0)]), "n": BASE["n"]}, "array a"),  # one ulp
    ({"a": np.array([1.0, -0.0, 3.0]), "n": BASE["n"]}, "array a"),  # the sign of zero
    ({"a": BASE["a"].astype(np.float32), "n": BASE["n"]}, "array a"),  # a dtype
    ({"a": BASE["a"]}, "array names differ"),  # a missing array
])
def test_one_bit_of_an_array_is_a_difference(tmp_path, other, what):
    """Hypothesis: the array comparison is bytewise (one ulp, -0.0 vs 0.0, float32 vs float64 and a missing
    array are all reported, by name)."""
    _write(tmp_path / "x", BASE)
    _write(tmp_path / "y", other)
    diffs = compare(tmp_path / "x", tmp_path / "y")
    assert len(diffs) == 1 and diffs[0].startswith(what), diffs


def test_a_changed_json_value_is_a_difference(tmp_path):
    """Hypothesis: a non-timing JSON value that differs in its last digit is reported, naming the file."""
    _write(tmp_path / "x", BASE, cmp={"rows": [{"x": 1.5}]})
    _write(tmp_path / "y", BASE, cmp={"rows": [{"x": 1.5000000000000002}]})
    assert compare(tmp_path / "x", tmp_path / "y") == ["compare.json"]
