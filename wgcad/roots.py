"""A bracketed scalar root: Brent's method (inverse quadratic interpolation, secant and bisection).

The double-arc and cycloidal profiles, the tooth measurements and the
backlash need one root of a scalar function on a bracket. This is
``scipy.optimize.brentq``'s algorithm (R. P. Brent, *Algorithms for
Minimization without Derivatives*, 1973, ch. 4) in plain Python, a copy kept
by docs/architecture.md's rule: scipy's, imported where the root is taken,
costs 12-28 % of the CPU of ``wgcad audit`` / ``generate`` on
d1_double_arc and d1_cycloidal (benchmarks/copies.py, ``roots``), all of it
the import of scipy.optimize, which no narrower scipy import avoids (every
submodule runs the package's ``__init__``). tests/test_roots.py checks it
against scipy's to the requested tolerance on smooth, flat, steep and kinked
functions.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["brentq"]

_EPS = 2.220446049250313e-16


def brentq(f: Callable[[float], float], a: float, b: float, xtol: float = 2e-12, maxiter: int = 200) -> float:
    """A root of ``f`` in ``[a, b]`` (``f(a)`` and ``f(b)`` of opposite signs), to within ``xtol + 4 eps |x|``.

    Raises ValueError when the ends do not bracket a sign change and
    RuntimeError when ``maxiter`` evaluations do not reach the tolerance
    (Brent's method needs at most about the square of bisection's count).
    """
    a, b = float(a), float(b)
    fa, fb = float(f(a)), float(f(b))
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0) == (fb > 0):
        raise ValueError(f"f({a}) and f({b}) have the same sign: no bracketed root")
    c, fc = a, fa
    d = e = b - a
    for _ in range(maxiter):
        if (fb > 0) == (fc > 0):  # keep the root between b and c
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):  # b is the best estimate so far
            a, fa = b, fb
            b, fb = c, fc
            c, fc = a, fa
        tol = 2.0 * _EPS * abs(b) + 0.5 * xtol
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:  # secant
                p, q = 2.0 * m * s, 1.0 - s
            else:  # inverse quadratic interpolation
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q  # interpolation accepted
            else:
                d = e = m  # bisection
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0 else -tol)
        fb = float(f(b))
    raise RuntimeError(f"no root to {xtol} in {maxiter} evaluations")
