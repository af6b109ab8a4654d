"""Adding a family as CONTRIBUTING.md says: in a copy of the package, from a clean state, generated and evaluated.

The copy gets exactly the code block of CONTRIBUTING.md's "Adding a family" appended to its
``peelapprox/law/_families.py``; the generator (``python -m peelapprox.law.codegen``) runs there in a
subprocess, and a second process imports the copy and evaluates the new family, by numpy and by its compiled
kernel.  The oracle is the formula written a third time, here, in numpy.  Tolerance: 1e-13 relative to the sum of
the magnitudes of the terms (a few ulp of the largest term: the generated code evaluates the same terms in
another order, and ``exp(-v/w)`` is the same call), while a wrong coefficient, exponent or derivative is an O(1)
error.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-13


def _contributing_block() -> str:
    """The python block of CONTRIBUTING.md's "Adding a family" section."""
    text = (ROOT / "CONTRIBUTING.md").read_text()
    section = text.split("\n## Adding a family\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def _run(code: str, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(cwd), NUMBA_CACHE_DIR=str(cwd / "numba-cache"))
    return subprocess.run([sys.executable, *code.split(" ", 1)] if code.startswith("-m ") else
                          [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


_EVALUATE = """
import json, numpy as np, peelapprox
from peelapprox import PeelForce
from peelapprox.kernels import LAW_FPP, family_kernel
from peelapprox.law._families import packed
assert peelapprox.__file__.startswith({root!r}), peelapprox.__file__
law = PeelForce.family("exp_dip", a=210.0, c=95.5, q=0.45)
v = np.logspace(-3, 1.5, 25)
fn, pack = family_kernel("exp_dip")
coef = packed("exp_dip", pack, 1.3, tuple(x for _, x in law.coefficients))
print(json.dumps(dict(repr=repr(law), depends_on_V=law.depends_on_V, v=v.tolist(),
                      numpy=[law.f(v, 1.3).tolist(), law.df(v, 1.3).tolist(), law.d2f(v, 1.3).tolist()],
                      kernel=[list(fn(float(x), coef, LAW_FPP)) for x in v])))
"""


def test_a_family_added_as_contributing_says_is_generated_and_evaluated(tmp_path):
    """Hypothesis: the section's block, appended to a copy of the package, is generated from a clean state (the
    new family is in FAMILIES but not yet in _generated.py) by ``python -m peelapprox.law.codegen``, and the law
    it gives equals the formula in numpy (f, f', f'' by numpy and by the compiled kernel, to TOL relative to the
    terms' magnitudes)."""
    pkg = tmp_path / "pkg"
    shutil.copytree(ROOT / "peelapprox", pkg / "peelapprox", ignore=shutil.ignore_patterns("__pycache__"))
    families = pkg / "peelapprox" / "law" / "_families.py"
    families.write_text(families.read_text() + "\n\n" + _contributing_block())
    gen = _run("-m peelapprox.law.codegen", pkg)
    assert gen.returncode == 0, gen.stderr[-3000:]
    assert "def law_exp_dip(x, coef, form):" in (pkg / "peelapprox" / "law" / "_generated.py").read_text()
    out = _run(_EVALUATE.format(root=str(pkg)), pkg)
    assert out.returncode == 0, out.stderr[-3000:]
    got = json.loads(out.stdout)
    assert got["repr"] == "PeelForce.exp_dip(a=210, b=30, c=95.5, w=0.5, q=0.45)"
    assert got["depends_on_V"] is True
    v, V, (a, b, c, w, q) = np.array(got["v"]), 1.3, (210.0, 30.0, 95.5, 0.5, 0.45)
    e, d = np.exp(-v / w), c * V**q
    terms = [[a + 0 * v, b * v, d + 0 * v, d * e], [b + 0 * v, d * e / w], [d * e / w**2]]
    exact = [terms[0][0] + terms[0][1] - terms[0][2] + terms[0][3], terms[1][0] - terms[1][1], terms[2][0]]
    kernel = np.array(got["kernel"]).T
    for k in range(3):
        scale = sum(np.abs(t) for t in terms[k])
        assert np.all(np.abs(np.array(got["numpy"][k]) - exact[k]) <= TOL * scale), k
        assert np.all(np.abs(kernel[k] - exact[k]) <= TOL * scale), k
