"""Confidence intervals of the Allan deviation."""

from __future__ import annotations

import numpy as np


def relative_errors(n: int, factors: np.ndarray) -> np.ndarray:
    """The R package's relative error of the Allan deviation, 1 / sqrt(2 (N / m - 1))."""
    return 1.0 / np.sqrt(2.0 * (n / np.asarray(factors, dtype=np.float64) - 1.0))
