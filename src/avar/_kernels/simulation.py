"""Simulation kernels (numba): recursions that NumPy cannot vectorize."""

from __future__ import annotations

from numba import njit, prange


@njit(cache=True, parallel=True)
def ar1_recursion(out, phi):
    """In place, row by row: ``out[r, t] = phi * out[r, t - 1] + out[r, t]``.

    ``out`` (replicates, n) holds the innovations (the first column already
    scaled to the stationary variance); afterwards it holds the AR(1) paths.
    Rows are independent, so they run in parallel; the order of operations
    within a row is fixed, so results do not depend on the thread count.
    """
    rows, n = out.shape
    for r in prange(rows):
        previous = out[r, 0]
        for t in range(1, n):
            previous = phi * previous + out[r, t]
            out[r, t] = previous
