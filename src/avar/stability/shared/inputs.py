"""The inputs every deviation statistic shares: the data, its rate, and the options.

Validation happens here once, at the public boundary (:mod:`avar.stability.classic.deviations`,
:mod:`avar.stability.total.deviations`, :mod:`avar.stability.time_error.deviations`, ...); the kernels
below trust what they are given.
"""

from __future__ import annotations

import numbers
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar._kernels.classic.phase import Scanned, scan
from avar._time_steps import rate_from_index
from avar._validation import as_array, as_float64, check_freq, check_numeric_dtype, short_repr
from avar.stability.shared.confidence import DEFAULT_CONFIDENCE

__all__ = ["DATA_TYPES", "DEFAULT_CONFIDENCE", "NAN_POLICIES", "SCALE_LIMIT", "TINY_LIMIT", "check_data", "check_not_tiny",
           "check_options", "rate_of", "scaled"]

DATA_TYPES = ("freq", "phase")


#: One pass over the data (:func:`avar._kernels.classic.phase.scan`): ``n_missing``, ``total``, ``low``,
#: ``high``, ``moment``; the kernel's own record, under the name the stability layer uses.
Scan = Scanned


class CheckedData(NamedTuple):
    """Float64 values of the data and their :class:`Scan`."""

    values: np.ndarray
    scanned: Scan | None


class ScaledData(NamedTuple):
    """Data scaled by 2**-exponent to magnitude ~1 (exponent 0: unscaled), with their :class:`Scan`."""

    values: np.ndarray
    scanned: Scan
    exponent: int
NAN_POLICIES = ("raise", "omit")


def check_data(data: Any, data_type: str, nan_policy: str, weigh: bool = False,
               statistic: str = "the statistic") -> CheckedData:
    """Float64 values of ``data`` and their :func:`scan` (NaN count, sum, min, max, and with
    ``weigh`` the centred moment), or an error naming ``data`` (and ``statistic``)."""
    if isinstance(data, pd.DataFrame):
        raise TypeError("data is a DataFrame; give one column (a 1-D series) of phase or frequency data")
    if isinstance(data, pd.Series):
        data = data.to_numpy()
    if isinstance(data, (str, bytes)):
        raise TypeError("data must be a numeric 1-D array of phase or frequency data, got a string")
    array = as_array(data, "data")
    check_numeric_dtype(array, "data")
    if array.ndim != 1:
        raise ValueError(f"data must be 1-D, got an array of shape {array.shape}")
    values = np.ascontiguousarray(as_float64(array), dtype=np.float64)
    if not values.flags.writeable:  # one compiled signature of the kernels
        values = values.copy()
    scanned = scan(values, weigh=weigh) if values.size else Scan(0, 0.0, np.inf, -np.inf, np.nan)  # one pass
    if (np.isinf(scanned.low) or np.isinf(scanned.high)) and scanned.n_missing < values.size:
        infinite = np.flatnonzero(np.isinf(values))
        raise ValueError(f"data has {infinite.size} infinite value(s), the first at index {infinite[0]}; "
                         "infinite values are never accepted (NaN marks a gap, see nan_policy)")
    n_missing = int(scanned.n_missing)
    if n_missing and nan_policy == "raise":
        missing = np.flatnonzero(np.isnan(values))
        raise ValueError(f"data has {n_missing} NaN value(s), the first at index {missing[0]}; pass "
                         "nan_policy='omit' to skip the terms that touch them, or remove/fill them")
    if values.size == 0:
        raise ValueError(f"data holds no samples (an empty series); {statistic} needs {data_type} data")
    if n_missing == values.size:
        raise ValueError(f"data holds only NaN values ({values.size}); {statistic} needs {data_type} data")
    return CheckedData(values, scanned)


def rate_of(data: Any, rate: Any) -> float:
    """``rate``, else the rate of a pandas Series' time index, else 1 Hz."""
    if rate is not None:
        return check_freq(rate, "rate")
    if isinstance(data, pd.Series):
        index_rate = rate_from_index(data.index, "data")
        if index_rate is not None:
            return index_rate
    return 1.0


def check_options(estimator: str, data: Any, rate: Any, data_type: Any, confidence: Any, nan_policy: Any) -> float:
    """The sampling rate (:func:`rate_of`: ``rate``, else ``data``'s time index, else 1 Hz) once
    ``rate``, ``data_type``, ``confidence`` and ``nan_policy`` hold, or an error naming the argument."""
    rate = rate_of(data, rate)
    if not isinstance(data_type, str) or data_type not in DATA_TYPES:
        raise ValueError(f"data_type must be 'freq' (fractional frequency) or 'phase' (time error, s), "
                         f"got {short_repr(data_type)}")
    if not isinstance(nan_policy, str) or nan_policy not in NAN_POLICIES:
        raise ValueError(f"nan_policy must be 'raise' or 'omit', got {short_repr(nan_policy)}")
    if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, numbers.Real):
        raise TypeError(f"confidence must be a number in (0, 1), e.g. 0.683 or 0.95, got {short_repr(confidence)}")
    if not 0.0 < float(confidence) < 1.0:
        raise ValueError(f"confidence must be in (0, 1), e.g. 0.683 or 0.95, got {short_repr(confidence)}")
    return rate


#: Data beyond 2**+-SCALE_LIMIT are scaled by a power of two (exact) before any square is formed.
SCALE_LIMIT = 400


def scaled(values: np.ndarray, scanned: Scan, weigh: bool) -> ScaledData:
    """``values`` scaled by 2**-e to magnitude ~1 when near the float64 limits (squares of data near
    1e-300 underflow to 0, of data near 1e300 overflow), with their scan and e (0: unscaled).

    The deviation is then exact; the variance is its square correctly rounded (0 or subnormal for
    data near 1e-300), and a variance beyond the float64 maximum is an error."""
    big = max(abs(float(scanned.low)), abs(float(scanned.high)))
    if not np.isfinite(big) or big == 0 or 2.0 ** -SCALE_LIMIT < big < 2.0 ** SCALE_LIMIT:
        return ScaledData(values, scanned, 0)
    exponent = int(np.frexp(big)[1])
    values = np.ldexp(values, -exponent)
    return ScaledData(values, scan(values, weigh=weigh), exponent)


#: Data below 2**-TINY_LIMIT in magnitude have variances at the bottom of float64 (about 1e-302 and less).
TINY_LIMIT = 500


def check_not_tiny(statistic: str, scanned: Scan) -> None:
    """An error for data below 2**-TINY_LIMIT in magnitude (but not all zero), for the statistics
    that do not rescale them (their variance would underflow to 0: a zero deviation, silently).

    >>> check_not_tiny("mtotdev", Scan(0, 0.0, -1e-300, 1e-300, np.nan))
    Traceback (most recent call last):
    ...
    ValueError: data of magnitude 1e-300 is below the float64 range of mtotdev's variance; rescale the data, e.g. to other units
    """
    big = max(abs(float(scanned.low)), abs(float(scanned.high)))
    if np.isfinite(big) and 0 < big < 2.0 ** -TINY_LIMIT:
        raise ValueError(f"data of magnitude {big:.3g} is below the float64 range of {statistic}'s variance; "
                         "rescale the data, e.g. to other units")


def finite_vector(data: Any, name: str, minimum: int) -> np.ndarray:
    """``data`` (array_like or Series) as a 1-D finite float64 array of at least ``minimum`` values,
    or ``TypeError``/``ValueError`` naming ``name``."""
    array = as_array(data.to_numpy() if hasattr(data, "to_numpy") else data, name)
    check_numeric_dtype(array, name)
    if array.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got an array of shape {array.shape}")
    values = np.asarray(as_float64(array), dtype=np.float64)
    if values.size < minimum:
        raise ValueError(f"{name} must hold at least {minimum} values, got {values.size}")
    bad = ~np.isfinite(values)
    if bad.any():
        raise ValueError(f"{name} has {int(bad.sum())} NaN or infinite value(s), the first at index "
                         f"{int(np.flatnonzero(bad)[0])}; fill or remove them first")
    return values
