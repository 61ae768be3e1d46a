"""Error-free transformations of float64 arithmetic (double-double primitives), public within ``_kernels``.

Every compensated kernel builds on these: ``two_sum`` (Knuth's TwoSum: ``s + e == a + b``
exactly), ``fast_two_sum`` (Dekker's, when ``|a| >= |b|``), and ``fast_sum``, a plain sum that
numba may vectorize, for buffers whose rounding error a certificate bounds (``EPS`` is the unit
roundoff 2**-53 those bounds are written in).

References
----------
Knuth, *The Art of Computer Programming* vol. 2, 4.2.2; Dekker (1971), "A floating-point
technique for extending the available precision", Numer. Math. 18.
"""

from __future__ import annotations

from numba import njit

#: Unit roundoff of float64.
EPS = 2.0**-53


@njit(cache=True, inline="always")
def two_sum(a, b):
    """``(s, e)`` with ``s = fl(a + b)`` and ``s + e == a + b`` exactly (TwoSum)."""
    s = a + b
    bv = s - a
    e = (a - (s - bv)) + (b - bv)
    return s, e


@njit(cache=True, inline="always")
def fast_two_sum(a, b):
    """TwoSum for ``|a| >= |b|`` (three operations instead of six)."""
    s = a + b
    return s, b - (s - a)


@njit(cache=True, fastmath=True)
def fast_sum(buffer, count):
    """``sum(buffer[:count])`` in any order the compiler likes (vectorized)."""
    total = 0.0
    for j in range(count):
        total += buffer[j]
    return total
