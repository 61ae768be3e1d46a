"""Input checks shared by the public functions.

Every public function validates its input once, here, and raises
``TypeError`` (wrong kind of object) or ``ValueError`` (right kind, bad
value) with a message that says what was wrong and what is accepted.
"""

from __future__ import annotations

import numbers
import sys
from typing import Any

import numpy as np

MIN_SAMPLES = 4

#: Integers beyond this magnitude are not all exact in float64.
EXACT_INTEGER_LIMIT = 2**53

#: Smallest accepted sampling rate (Hz): below it averaging times m / freq can overflow float64.
MIN_FREQ = 1e-250

#: Values beyond this magnitude are shifted by their midrange before the Allan variance,
#: whose sums would otherwise overflow (the Allan variance does not depend on a shift).
SHIFT_LIMIT = 2.0**1000

#: Largest number of bootstrap replicates (8 bytes per replicate and process are kept).
MAX_REPLICATES = 10**7

#: Longest text of a value quoted in an error message.
MESSAGE_VALUE_LIMIT = 120


def cap_text(text: str, limit: int = 2000) -> str:
    """``text`` cut to ``limit`` characters, saying how long it was.

    >>> cap_text("abcdef", 3)
    'abc ... (6 characters)'
    """
    return text if len(text) <= limit else f"{text[:limit]} ... ({len(text)} characters)"


def short_repr(value: Any, limit: int = MESSAGE_VALUE_LIMIT) -> str:
    """``repr(value)`` cut to ``limit`` characters, so that no message grows with the input.

    A NumPy array is summarized by NumPy first (no full expansion of a huge array).

    >>> short_repr(list(range(1000)), 30)
    '[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, ... (1000 items)]'
    >>> short_repr("x" * 200, 10)
    "'xxxxxxxxx ... (202 characters)"
    """
    if isinstance(value, np.ndarray) and value.size > 64:
        with np.printoptions(threshold=16, edgeitems=3):
            text = repr(value)
    elif isinstance(value, (list, tuple)) and len(value) > 64:
        head = repr(type(value)(value[:16]))
        return f"{head[: min(limit, len(head) - 1)].rstrip(', ')}, ... ({len(value)} items){head[-1]}"
    else:
        try:
            text = repr(value)
        except ValueError:  # an int of more digits than Python converts to text
            text = f"<int of {value.bit_length()} bits>" if isinstance(value, int) else f"<{type(value).__name__}>"
    if len(text) <= limit:
        return text
    return f"{text[:limit].rstrip(', ')} ... ({len(text)} characters)"


def as_array(x: Any, what: str) -> np.ndarray:
    """``numpy.asarray(x)`` that refuses masked values and ragged nested lists by name.

    A masked array with no masked value is taken as its data; masked values
    (gaps) are not supported and are never silently used.
    """
    if isinstance(x, np.ma.MaskedArray):
        masked = int(np.ma.count_masked(x))
        if masked:
            first = int(np.flatnonzero(np.ma.getmaskarray(x).ravel())[0])
            raise ValueError(
                f"{what} is a masked array with {masked} masked value(s) (the first at flat index {first}); "
                "gaps are not supported: drop them (x.compressed()) or fill them (x.filled(value)) first"
            )
        return np.asarray(np.ma.getdata(x))
    try:
        return np.asarray(x)
    except ValueError as error:
        if "inhomogeneous" not in str(error) and "sequence" not in str(error):
            raise
        raise ValueError(
            f"{what} is a ragged sequence (its rows or items have different lengths or nesting); "
            "give a flat 1-D list or array of numbers (or a 2-D array with rows of one length)"
        ) from None


def integer_range(array: np.ndarray) -> tuple[int, int] | None:
    """(min, max) of an integer array as Python ints, or None for other dtypes."""
    return None if array.dtype.kind not in "iu" or array.size == 0 else (int(array.min()), int(array.max()))


def as_float64(array: np.ndarray) -> np.ndarray:
    """Contiguous float64 values of a real 1-D array, or the integers themselves.

    Integers beyond 2**53 are first shifted by an exact integer offset (the
    midrange): the Allan variance does not depend on a shift, and the shifted
    values convert exactly as long as the data span less than 2**53. Integers
    spanning 2**53 or more (up to the whole int64 range) cannot be converted
    without loss: they are returned unchanged, as integers, for the kernels.
    """
    bounds = integer_range(array)
    if bounds is None or max(abs(bounds[0]), abs(bounds[1])) <= EXACT_INTEGER_LIMIT:
        return np.ascontiguousarray(array, dtype=np.float64)
    if bounds[1] - bounds[0] >= EXACT_INTEGER_LIMIT:
        return np.ascontiguousarray(array)
    offset = (bounds[0] + bounds[1]) // 2
    if array.dtype.kind == "i":
        return (array - np.int64(offset)).astype(np.float64)
    above = array >= np.uint64(offset)
    return np.where(above, (array - np.uint64(offset)).astype(np.float64), -(np.uint64(offset) - array).astype(np.float64))


def shift_huge(values: np.ndarray) -> np.ndarray:
    """Values shifted by their midrange when they reach :data:`SHIFT_LIMIT` (else unchanged).

    The Allan variance does not depend on a shift; near the float64 limit the
    sums of the estimator overflow, while the shifted values (exact for a
    constant series, where the Allan variance is 0) do not. Non-finite values
    are left for :func:`check_finite` to report.

    >>> shift_huge(np.full(3, 1.7e308)).tolist()
    [0.0, 0.0, 0.0]
    """
    if values.size == 0 or values.dtype.kind != "f":
        return values
    with np.errstate(invalid="ignore"):
        low, high = float(np.min(values)), float(np.max(values))
    if not (np.isfinite(low) and np.isfinite(high)) or max(-low, high) < SHIFT_LIMIT:
        return values
    middle = low / 2 + high / 2
    with np.errstate(over="ignore"):
        return values - middle


def _as_float(value: Any, name: str) -> float:
    """``float(value)``, with an int too large for float64 reported by name."""
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"{name} = {short_repr(value)} is beyond the float64 range (about 1.8e308)") from None


def check_freq(freq: Any, name: str = "freq") -> float:
    """A finite, positive sampling frequency as float."""
    if isinstance(freq, (bool, np.bool_)) or not isinstance(freq, numbers.Real):
        raise TypeError(f"{name} must be a positive real number (Hz), got {type(freq).__name__}")
    value = _as_float(freq, name)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0 (Hz), got {freq!r}")
    if value < MIN_FREQ:
        raise ValueError(
            f"{name} = {freq!r} Hz is too small: averaging times m / {name} would overflow float64; "
            f"give a rate >= {MIN_FREQ:g} Hz (or express time in other units)"
        )
    return value


def check_numeric_dtype(array: np.ndarray, what: str) -> None:
    """Reject non-numeric and complex data."""
    kind = array.dtype.kind
    if kind == "c":
        raise TypeError(f"{what} is complex; the Allan variance needs real-valued data")
    if kind not in "biuf":
        raise TypeError(
            f"{what} must be numeric (int or float), got dtype {array.dtype}; "
            "convert it with numpy.asarray(x, dtype=float) if it holds numbers"
        )


def check_finite(values: np.ndarray, what: str) -> None:
    """Reject NaN and infinite values, saying how many and where the first is."""
    bad = ~np.isfinite(values)
    if bad.any():
        where = np.flatnonzero(bad)
        n_nan = int(np.isnan(values[where]).sum())
        raise ValueError(
            f"{what} has {where.size} non-finite value(s) ({n_nan} NaN, {where.size - n_nan} inf); "
            f"the first is at index {where[0]}. Remove or fill them before computing the Allan variance."
        )


def check_length(n: int, what: str) -> None:
    if n < MIN_SAMPLES:
        raise ValueError(f"{what} has {n} sample(s); the Allan variance needs at least {MIN_SAMPLES}")


#: A time step longer than this many median steps is a gap.
GAP_FACTOR = 1.5


def analyze_steps(steps: np.ndarray) -> tuple[float, float, float, np.ndarray]:
    """Rate, median step, jitter and gaps of the time steps (s) of a recording.

    The median step locates the gaps: steps longer than ``GAP_FACTOR`` median steps. The
    step is then the least-squares slope of time against sample number, pooled over the
    stretches between gaps: the rounding of stamps (a 300 Hz log stamped to the
    millisecond steps 3, 3, 4 ms) biases the median step (333 Hz) and barely moves the
    slope. The rate is 1 / that step; the jitter is the root mean square of the
    deviations of the steps (outside gaps) from it (s).

    Returns
    -------
    rate : float
        Hz.
    median : float
        The median step (s).
    jitter : float
        s, rms.
    gaps : ndarray of int
        0-based positions ``i`` of the gap steps (between samples ``i`` and ``i + 1``).

    Raises
    ------
    ValueError
        A step that is not > 0 (the message gives its position), or no step at all.

    >>> rate, median, jitter, gaps = analyze_steps(np.diff(np.round(np.arange(3000) / 0.3)) / 1000)
    >>> round(rate, 2), median, round(jitter * 1e3, 3), gaps.size
    (300.0, 0.003, 0.471, 0)
    """
    steps = np.asarray(steps, dtype=np.float64)
    if steps.size == 0:
        raise ValueError("a time axis needs at least two samples")
    bad = ~(steps > 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"time does not increase strictly: sample {i + 2} is at {steps[i]:+.6g} s from sample {i + 1}"
            f"{f' ({int(bad.sum())} such steps)' if bad.sum() > 1 else ''}; sort the samples or drop duplicate times"
        )
    median = float(np.median(steps))
    is_gap = steps > GAP_FACTOR * median
    times = np.concatenate([[0.0], np.cumsum(steps)])
    segment = np.concatenate([[0], np.cumsum(is_gap)])
    counts = np.bincount(segment).astype(np.float64)
    number = np.arange(times.size, dtype=np.float64)
    d_number = number - (np.bincount(segment, number) / counts)[segment]
    d_time = times - (np.bincount(segment, times) / counts)[segment]
    spread = float(d_number @ d_number)
    step = float(d_number @ d_time) / spread if spread > 0 else float(steps[~is_gap].mean())
    regular = steps[~is_gap]
    jitter = float(np.sqrt(np.mean((regular - step) ** 2)))
    return 1.0 / step, median, jitter, np.flatnonzero(is_gap)


def describe_gaps(gaps: np.ndarray, steps: np.ndarray, median: float, seconds_at) -> str:
    """'3 gap(s) (steps > 1.5 x the median step 5 ms); the first after sample 1200 (t = 6 s), 0.5 s long'.

    ``seconds_at(i)`` gives the time (s from the first sample) of 0-based sample ``i``.
    """
    first = int(gaps[0])
    return (
        f"{gaps.size} gap(s) (time steps > {GAP_FACTOR:g} x the median step {median:.6g} s); the first is between "
        f"samples {first + 1} and {first + 2} (row {first + 2} at t = {seconds_at(first + 1):.6g} s), "
        f"a step of {float(steps[first]):.6g} s"
    )


def _rate_from_seconds(seconds: np.ndarray, what: str) -> float:
    steps = np.diff(seconds)
    try:
        rate, median, _, gaps = analyze_steps(steps)
    except ValueError as error:
        raise ValueError(f"{what} has a time index where {error}") from None
    if gaps.size:
        origin = seconds[0]
        message = describe_gaps(gaps, steps, median, lambda i: seconds[i] - origin)
        raise ValueError(f"{what} has a time index with {message}; fill or cut them, or pass the sampling rate explicitly")
    return rate


def rate_from_index(index: Any, what: str) -> float | None:
    """Sampling rate (Hz) of a time index: regular Datetime/Timedelta, Period, or float seconds.

    A float index holds times in seconds: its rate is 1 / the mean step (see
    :func:`analyze_steps`; timestamp rounding and jitter are accepted, gaps are not).
    A PeriodIndex gives the rate of its periods. Returns None for other indexes (a
    RangeIndex or integer index numbers samples, it does not time them); raises
    ValueError for an irregular Datetime/Timedelta index or a float index with gaps.
    """
    import pandas as pd  # an index is a pandas object: pandas is loaded already
    if isinstance(index, pd.PeriodIndex) and len(index) >= 2:
        index = index.to_timestamp()
    if index.dtype.kind == "f" and len(index) >= 2:
        return _rate_from_seconds(index.to_numpy(dtype=np.float64), what)
    if not isinstance(index, (pd.DatetimeIndex, pd.TimedeltaIndex)) or len(index) < 2:
        return None
    steps = np.diff((index.tz_convert(None) if getattr(index, "tz", None) else index).to_numpy())  # own unit
    unit, count = np.datetime_data(steps.dtype)
    steps = steps.astype(np.int64)
    if np.any(steps <= 0):
        raise ValueError(f"{what} has a time index that does not increase strictly; sort it or drop duplicate times")
    if np.any(steps != steps[0]):
        raise ValueError(f"{what} has an irregular time index (steps from {steps.min() * count} to "
                         f"{steps.max() * count} {unit}); resample it to a regular grid or pass the sampling rate explicitly")
    return 1.0 / (float(steps[0]) * (np.timedelta64(count, unit) / np.timedelta64(1, "s")))


def native_values(array: np.ndarray) -> np.ndarray | None:
    """``array`` itself when the kernels read it as it is, else None: integers, booleans, float32/64
    (magnitudes near the float64 limit are the kernels' to rescale). A non-finite value is not looked
    for here: it makes the kernels' centre, hence every level, non-finite, and
    :func:`avar.stability.allan.columns.allan_variance_columns` then reports it (:func:`check_finite`),
    so valid data is read once less."""
    if array.dtype.kind in "biu" or (array.dtype.kind == "f" and array.itemsize >= 4):
        return array
    return None


def as_series(x: Any, freq: Any, native: bool = False, rate_name: str = "freq") -> tuple[np.ndarray, float]:
    """Validate a 1-D series and its rate; return float64 values and the rate (Hz).

    Integers spanning 2**53 or more are returned as integers (see :func:`as_float64`).
    ``native=True`` (for kernels that read any real dtype in place) returns integer, boolean and
    float32 arrays as they are, never copied to float64 (see :func:`native_values`).

    ``freq=None`` means the rate of a pandas time index when there is one,
    otherwise 1 Hz. ``rate_name``: the parameter's name in messages (``"rate"`` or ``"freq"``).
    """
    what, index_rate = "x", None
    pd = sys.modules.get("pandas")  # not loaded: x cannot be a pandas object, and stays light
    if pd is not None and isinstance(x, pd.DataFrame):
        raise TypeError("x is a DataFrame; give a 1-D series or an avar.IMU (see avar.IMU.from_dataframe)")
    if pd is not None and isinstance(x, pd.Series):
        index_rate = rate_from_index(x.index, what) if freq is None else None
        x = x.to_numpy()
    if isinstance(x, (str, bytes)):
        raise TypeError("x must be a numeric 1-D series, got a string")
    array = as_array(x, what)
    check_numeric_dtype(array, what)
    if array.ndim != 1:
        raise ValueError(f"x must be 1-D, got an array of shape {array.shape}; give a 1-D series or an avar.IMU")
    check_length(array.shape[0], what)
    values = native_values(array) if native else None
    if values is None:
        values = shift_huge(as_float64(array))
        check_finite(values, what)
    if freq is None:
        rate = index_rate if index_rate is not None else 1.0
    else:
        rate = check_freq(freq, rate_name)
    return values, rate


def check_whole_numbers(values: Any, name: str) -> np.ndarray:
    """An int64 array of whole numbers (1.0 accepted, 1.5 rejected).

    A ``range`` is checked by its ends before it is expanded; sets, generators
    and numbers beyond int64 are refused by name.
    """
    if isinstance(values, (set, frozenset, dict)):
        raise TypeError(f"{name} must be whole numbers as an int, a range, a list or an array, got a "
                        f"{type(values).__name__} (unordered); give sorted({name}) instead")
    if isinstance(values, range):
        if len(values) and max(abs(values[0]), abs(values[-1])) >= 2**62:
            raise ValueError(f"{name} holds numbers too large to be scales or sizes (|value| < 2**62): "
                             f"{short_repr(values)}")
        return np.arange(values.start, values.stop, values.step, dtype=np.int64)
    if not isinstance(values, (numbers.Number, np.ndarray, list, tuple)) and (
        hasattr(values, "__next__") or not hasattr(values, "__len__")
    ):
        raise TypeError(f"{name} must be whole numbers as an int, a range, a list or an array, got "
                        f"{type(values).__name__}; convert it with list(...) first")
    array = np.atleast_1d(as_array(values, name))
    if array.dtype == object:
        items = array.ravel().tolist()
        if all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in items):
            big = next(v for v in items if abs(v) >= 2**62)
            raise ValueError(f"{name} holds {big}, too large to be a scale or size (|value| < 2**62)")
    if array.dtype.kind == "b" or array.dtype.kind not in "iuf":
        raise TypeError(f"{name} must hold whole numbers, got {short_repr(values)} (dtype {array.dtype})")
    if array.dtype.kind == "f":
        if not np.all(np.isfinite(array)) or np.any(array != np.round(array)):
            raise ValueError(f"{name} must hold whole numbers, got {short_repr(values)}")
        if np.any(np.abs(array) >= 2.0**62):
            raise ValueError(f"{name} holds numbers too large to be scales or sizes: {short_repr(values)}")
    if array.dtype.kind == "u" and array.size and int(array.max()) >= 2**62:
        raise ValueError(f"{name} holds numbers too large to be scales or sizes: {short_repr(values)}")
    return array.astype(np.int64)


def check_seed(seed: Any, name: str = "seed") -> Any:
    """A seed for :func:`numpy.random.default_rng`, refused by name when it is not one.

    Accepted: None, a non-negative int, a sequence of them, a
    ``numpy.random.SeedSequence``, ``BitGenerator`` or ``Generator``.

    >>> check_seed(3)
    3
    """
    accepted = ("None, a non-negative int, a list of non-negative ints, a numpy.random.SeedSequence, "
                "BitGenerator or Generator")
    if seed is None or isinstance(seed, (np.random.Generator, np.random.BitGenerator, np.random.SeedSequence)):
        return seed
    if isinstance(seed, (bool, np.bool_)):
        raise TypeError(f"{name} must be {accepted}; got {seed!r}")
    if isinstance(seed, numbers.Integral):
        if int(seed) < 0:
            raise ValueError(f"{name} must be >= 0 (a non-negative int); got {seed!r}")
        return int(seed)
    if isinstance(seed, (str, bytes, float, numbers.Number)) or not isinstance(seed, (list, tuple, np.ndarray)):
        raise TypeError(f"{name} must be {accepted}; got {short_repr(seed)} ({type(seed).__name__})")
    items = np.asarray(seed)
    if items.ndim != 1 or items.dtype.kind not in "iu" or (items.size and int(items.min()) < 0):
        raise ValueError(f"{name} must be {accepted}; got {short_repr(seed)}")
    return seed


def check_replicates(value: Any, name: str = "B", minimum: int = 2) -> int:
    """A count of replicates between ``minimum`` and :data:`MAX_REPLICATES`."""
    count = check_count(value, name, minimum)
    if count > MAX_REPLICATES:
        raise ValueError(f"{name} = {count} replicates is too many (their estimates alone would take "
                         f"{8 * count / 2**30:.3g} GiB per process); give at most {MAX_REPLICATES:,}")
    return count


def check_real(value: Any, name: str, minimum: float | None = None, bound: float | None = None) -> float:
    """A finite real parameter as float; ``minimum`` is inclusive, ``|value| < bound``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    number = _as_float(value, name)
    if not np.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if minimum is not None and number < minimum:
        raise ValueError(f"{name} must be >= {minimum:g}, got {value!r}")
    if bound is not None and abs(number) >= bound:
        raise ValueError(f"{name} must satisfy |{name}| < {bound:g}, got {value!r}")
    return number


def check_count(value: Any, name: str, minimum: int = 1) -> int:
    """A whole number >= ``minimum`` as int (``10.0`` accepted, ``True`` and ``1.5`` not)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a whole number >= {minimum}, got {type(value).__name__}")
    if not isinstance(value, numbers.Integral) and (not np.isfinite(float(value)) or float(value) != int(value)):
        raise ValueError(f"{name} must be a whole number >= {minimum}, got {short_repr(value)}")
    if int(value) < minimum:
        raise ValueError(f"{name} must be a whole number >= {minimum}, got {short_repr(value)}")
    return int(value)
