"""Simulation kernels (numba): recursions that NumPy cannot vectorize."""

from __future__ import annotations

from numba import njit

from avar._kernels.runtime.tasks import run_ranges


@njit(cache=True, nogil=True)
def _ar1_rows(out, phi, first, stop):
    for r in range(first, stop):
        previous = out[r, 0]
        for t in range(1, out.shape[1]):
            previous = phi * previous + out[r, t]
            out[r, t] = previous


def ar1_recursion(out, phi):
    """In place, row by row: ``out[r, t] = phi * out[r, t - 1] + out[r, t]``.

    ``out`` (replicates, n) holds the innovations (the first column already
    scaled to the stationary variance); afterwards it holds the AR(1) paths.
    Rows are independent, so they run on the threads; the order of operations
    within a row is fixed, so results do not depend on the thread count.
    """
    run_ranges(out.shape[0], lambda first, stop: _ar1_rows(out, float(phi), first, stop))
