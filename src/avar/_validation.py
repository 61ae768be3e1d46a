"""Input checks shared by the public functions.

Every public function validates its input once, here, and raises
``TypeError`` (wrong kind of object) or ``ValueError`` (right kind, bad
value) with a message that says what was wrong and what is accepted.
"""

from __future__ import annotations

import numbers
import sys
from typing import Any, NamedTuple

import numpy as np

from avar._time_steps import rate_from_index

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


class IntegerRange(NamedTuple):
    """The smallest and largest value of an integer array, as Python ints (exact beyond 2**53)."""

    minimum: int
    maximum: int


def integer_range(array: np.ndarray) -> IntegerRange | None:
    """:class:`IntegerRange` of an integer array, or None for other dtypes and empty arrays.

    >>> integer_range(np.array([3, -2**62, 7]))
    IntegerRange(minimum=-4611686018427387904, maximum=7)
    """
    if array.dtype.kind not in "iu" or array.size == 0:
        return None
    return IntegerRange(int(array.min()), int(array.max()))


def as_float64(array: np.ndarray) -> np.ndarray:
    """Contiguous float64 values of a real 1-D array, or the integers themselves.

    Integers beyond 2**53 are first shifted by an exact integer offset (the
    midrange): the Allan variance does not depend on a shift, and the shifted
    values convert exactly as long as the data span less than 2**53. Integers
    spanning 2**53 or more (up to the whole int64 range) cannot be converted
    without loss: they are returned unchanged, as integers, for the kernels.
    """
    bounds = integer_range(array)
    if bounds is None or max(abs(bounds.minimum), abs(bounds.maximum)) <= EXACT_INTEGER_LIMIT:
        return np.ascontiguousarray(array, dtype=np.float64)
    if bounds.maximum - bounds.minimum >= EXACT_INTEGER_LIMIT:
        return np.ascontiguousarray(array)
    offset = (bounds.minimum + bounds.maximum) // 2
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


def native_values(array: np.ndarray) -> np.ndarray | None:
    """``array`` itself when the kernels read it as it is, else None: integers, booleans, float32/64
    (magnitudes near the float64 limit are the kernels' to rescale). A non-finite value is not looked
    for here: it makes the kernels' centre, hence every level, non-finite, and
    :func:`avar.stability.allan.columns.allan_variance_columns` then reports it (:func:`check_finite`),
    so valid data is read once less."""
    if array.dtype.kind in "biu" or (array.dtype.kind == "f" and array.itemsize >= 4):
        return array
    return None


class ValidSeries(NamedTuple):
    """A validated 1-D series (:func:`as_series`)."""

    #: The samples: float64, or the caller's integers, booleans or float32 with ``native=True``.
    values: np.ndarray
    #: Sampling rate (Hz).
    rate: float


def as_series(x: Any, freq: Any, native: bool = False, rate_name: str = "freq") -> ValidSeries:
    """Validate a 1-D series and its rate; return the :class:`ValidSeries` of values and rate (Hz).

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
    return ValidSeries(values, rate)


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
