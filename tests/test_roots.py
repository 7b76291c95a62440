"""wgcad.roots.brentq against scipy.optimize.brentq: the same root to the requested tolerance.

The audit uses its own Brent root (importing scipy.optimize cost more than
the audit's work); both implement Brent's 1973 algorithm, so on every
function they must land within the tolerance of each other and of the
true root where it is known in closed form.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq as scipy_brentq

from wgcad.roots import brentq

CASES = [
    # (function, a, b, true root or None)
    (lambda x: x * x - 2.0, 0.0, 2.0, math.sqrt(2.0)),
    (lambda x: math.cos(x) - x, 0.0, 1.0, None),
    (lambda x: (x - 1e-3) ** 3, -1.0, 1.0, 1e-3),  # flat: a triple root
    (lambda x: math.exp(50 * x) - 1e10, 0.0, 1.0, math.log(1e10) / 50),  # steep
    (lambda x: 2.0 * (x - 0.2) if x < 0.2 else 0.5 * (x - 0.2), 0.0, 1.0, 0.2),  # kinked at the root
    (lambda x: math.tan(x) - 1.0, 0.0, 1.2, math.pi / 4),
    (lambda x: x - 1e-9, 0.0, 1e-6, 1e-9),  # a root near zero, at backlash scales
    (lambda x: math.atan(1e6 * (x - 0.7)), 0.0, 1.0, 0.7),  # a step
]


@pytest.mark.parametrize("k", range(len(CASES)))
@pytest.mark.parametrize("xtol", [2e-12, 1e-13, 1e-6])
def test_same_root_as_scipy(k, xtol):
    f, a, b, true = CASES[k]
    ours = brentq(f, a, b, xtol=xtol)
    theirs = scipy_brentq(f, a, b, xtol=xtol, maxiter=500)
    tol = xtol + 8.9e-16 * abs(theirs)
    assert abs(ours - theirs) <= 2 * tol  # each within its tolerance of the root
    if true is not None:
        assert abs(ours - true) <= tol * 1.0001 + 1e-15
    # the reversed bracket finds the same root
    assert abs(brentq(f, b, a, xtol=xtol) - ours) <= 2 * tol


def test_random_polynomials_against_scipy():
    rng = np.random.default_rng(7)
    for _ in range(300):
        roots = np.sort(rng.uniform(-2, 2, 3))
        poly = np.poly(roots)
        lo = rng.uniform(roots[0] - 1, roots[0] - 1e-3)
        hi = rng.uniform(roots[0] + 1e-3, roots[1] - 1e-6)

        def f(x):
            return float(np.polyval(poly, x))

        if f(lo) * f(hi) >= 0:
            continue
        assert abs(brentq(f, lo, hi, xtol=1e-13) - roots[0]) <= 1e-12


def test_no_bracket_and_exact_ends():
    with pytest.raises(ValueError):
        brentq(lambda x: x * x + 1.0, -1.0, 1.0)
    assert brentq(lambda x: x, 0.0, 1.0) == 0.0
    assert brentq(lambda x: x - 1.0, 0.0, 1.0) == 1.0


def test_gives_up_past_maxiter():
    with pytest.raises(RuntimeError):
        brentq(lambda x: x**3 - 0.3, 0.0, 1.0, xtol=1e-15, maxiter=3)
