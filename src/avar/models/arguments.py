"""Checks of the arguments of the closed-form theory and the covariance builders.

Each returns a float64 (or int64) array, or raises ``TypeError``/``ValueError`` naming the
argument, what was wrong and what is accepted.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def as_float_array(x: Any, name: str) -> np.ndarray:
    """Convert ``x`` to a finite float64 array or raise TypeError/ValueError."""
    if x is None or isinstance(x, (str, bytes)):
        raise TypeError(f"{name} must be a real number or an array of real numbers, "
                        f"got {type(x).__name__}")
    try:
        arr = np.asarray(x)
    except Exception as exc:  # pragma: no cover - exotic objects
        raise TypeError(f"{name} must be a real number or an array of real numbers, "
                        f"got {type(x).__name__}") from exc
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be a real number or an array of real numbers "
                        f"(int or float), got dtype {arr.dtype}")
    arr = arr.astype(np.float64)
    if arr.size == 0:
        raise ValueError(f"{name} must not be empty")
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(f"{name} must be finite (no NaN or inf), got {float(arr[bad].flat[0]):g}")
    return arr


def as_whole(x: Any, name: str, minimum: int = 1) -> np.ndarray:
    """Validate whole numbers >= ``minimum`` (1.0 accepted, 1.5 rejected); int64 array."""
    arr = as_float_array(x, name)
    frac = arr != np.floor(arr)
    if frac.any():
        raise ValueError(f"{name} must be whole numbers (integers such as 1, 2, 8.0), "
                         f"got {float(arr[frac].flat[0])!r}")
    low = arr < minimum
    if low.any():
        raise ValueError(f"{name} must be >= {minimum}, got {arr[low].flat[0]:g}")
    if (arr > 2.0**62).any():
        raise ValueError(f"{name} is too large (must be < 2**62)")
    return arr.astype(np.int64)


def as_nonnegative(x: Any, name: str) -> np.ndarray:
    arr = as_float_array(x, name)
    neg = arr < 0
    if neg.any():
        raise ValueError(f"{name} must be >= 0 (a variance), got {arr[neg].flat[0]:g}")
    return arr


def as_phi(x: Any, name: str = "phi") -> np.ndarray:
    arr = as_float_array(x, name)
    bad = np.abs(arr) >= 1
    if bad.any():
        raise ValueError(f"{name} must satisfy |{name}| < 1 (stationary AR(1)), "
                         f"got {arr[bad].flat[0]:g}")
    return arr
