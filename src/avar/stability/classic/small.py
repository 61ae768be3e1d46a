"""The deviation family's short records in NumPy: nothing to compile, as exact as the kernels.

The compiled path (:mod:`avar._kernels.classic.levels`) holds the phase as a compensated
running sum ``hi + lo``. Here the same double-double is built with vectorized NumPy, exactly
split rather than compensated:

1. every increment is an exact pair ``h + l`` (Knuth's TwoSum, the kernels' arithmetic:
   :func:`increments`);
2. ``h`` is split into a high part on a coarse binary grid ``g`` (``H = rint(h / g) g``) and
   the rest ``L = h - H`` (both exact). ``g`` is chosen (and checked) so that every running
   sum of the high parts is at most ``2**HIGH_BITS g`` in magnitude: :func:`numpy.cumsum` of
   them is then exact in float64 (integers times ``g`` below 2**53 g);
3. the low parts ``L + l`` (at most ``g / 2 + |l|`` each) are summed by a plain cumsum, whose
   rounding is bounded a posteriori: each step errs by at most ``u = eps (max |lo| + max |L +
   l|)`` (:class:`SplitSum`);
4. a term (a second, third or fourth difference of the phase, or of its running sum for
   MDEV and MHDEV; TOTDEV's of the reflected phase) is its difference of the high parts,
   exact (every value and difference a multiple of ``g`` below 2**53 g), plus that of the
   low parts. A difference over a span of ``s`` steps sees only the rounding of those
   ``s`` steps, ``s u`` at most, so a term of a level m errs by at most
   ``delta = (2**(d - 1) m + d 2**d) u`` (d-th difference; :func:`term_error`);
5. the level's sum of ``count`` squares errs by at most ``2 delta sqrt(count S) + count
   delta**2 + (27 + log2 count) eps S`` (Cauchy-Schwarz, the final roundings and NumPy's
   pairwise sum). :func:`level_sums` returns ``None`` unless every level's bound is within
   :data:`TOL` of its sum ``S``: the caller then runs the compiled kernels.

Noise-like data pass at every level with bounds near 1e-15; a large excursion of the
running sums relative to the terms (a frequency drift far above the noise in MDEV) makes the
bound fail and the compensated kernels decide. Nothing here validates input or handles
gaps: :mod:`avar.stability.classic.core` calls it on clean, gap-free data.

References
----------
D. E. Knuth, *The Art of Computer Programming* vol. 2, 4.2.2 (TwoSum). N. J. Higham,
*Accuracy and Stability of Numerical Algorithms*, 2002, ch. 4 (summation error bounds).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from avar._kernels.classic.sums import CUMSUM_BLOCK

#: Unit roundoff of float64.
EPS = 2.0**-53
#: Running sums of the high parts stay within 2**HIGH_BITS grid units: differences up to the
#: fourth (coefficients summing to 16), and TOTDEV's reflections, stay below 2**53 units, exact.
HIGH_BITS = 48
#: Relative bound on a level's error (its sum of squares) the NumPy path must certify.
TOL = 1e-13
#: Grids outside 2**+-GRID_LIMIT (data near the float64 limits) take the compiled path.
GRID_LIMIT = 900
#: Kernel code -> (order of the difference, whether it is taken of the phase's running sum).
CODES = {0: (2, False), 1: (3, False), 2: (3, True), 3: (2, False), 4: (4, True)}


class Pairs(NamedTuple):
    """Values held exactly as ``high + low`` (float64 arrays of one length)."""

    high: np.ndarray
    low: np.ndarray


class SplitSum(NamedTuple):
    """A running sum (from 0) held as ``hi + lo``.

    ``hi``: the running sum of the high parts, exact, multiples of ``grid``; ``lo``: that of
    the low parts, rounded; ``step``: a bound on the rounding error each step adds to ``lo``.
    """

    hi: np.ndarray
    lo: np.ndarray
    grid: float
    step: float


class Levels(NamedTuple):
    """Sums of squared terms and term counts of every level, the detrended phase (float64), and
    the line its increments lost, ``centre + slope i`` (in the data's units)."""

    sums: np.ndarray
    counts: np.ndarray
    phase: np.ndarray
    centre: float
    slope: float


class ExactPhase(NamedTuple):
    """The detrended phase as a :class:`SplitSum`, and the line its increments lost (:func:`exact_phase`)."""

    phase: SplitSum
    centre: float
    slope: float


def two_sum(a: np.ndarray, b: np.ndarray | float) -> Pairs:
    """``(s, e)`` with ``s = fl(a + b)`` and ``s + e == a + b`` exactly, elementwise (TwoSum)."""
    s = a + b
    bv = s - a
    return Pairs(s, (a - (s - bv)) + (b - bv))


def increments(data: np.ndarray, kind: int, centre: float, slope: float, scale: float) -> Pairs:
    """The phase's increments less ``centre + slope i``, times ``scale``, as exact pairs.

    ``kind`` 0: ``data`` is the frequency (the increments); 1: the phase (increments
    ``data[i + 1] - data[i]``). The arithmetic of
    :func:`avar._kernels.classic.phase.phase_increment`: ``slope i`` must be exact and
    ``scale`` a power of two.
    """
    if kind == 1:
        high, low = two_sum(data[1:], -data[:-1])
    else:
        high, low = data, np.zeros(data.shape[0])
    high, error = two_sum(high, -centre)
    low = low + error
    if slope != 0.0:
        high, error = two_sum(high, -(slope * np.arange(high.shape[0], dtype=np.float64)))
        low = low + error
    return Pairs(high * scale, low * scale)


def grid_of(high: np.ndarray) -> float | None:
    """The power of two ``g`` of step 2 of the module notes for these high parts: ``count
    max |high| < 2**(HIGH_BITS - 1) g``; None when it would leave the float64 range."""
    count = high.shape[0]
    big = float(np.max(np.abs(high))) if count else 0.0
    if big == 0.0:
        return 1.0
    _, exponent = np.frexp(big * count)  # big * count < 2**exponent
    grid = float(np.ldexp(1.0, int(exponent) - (HIGH_BITS - 1)))
    return grid if 2.0**-GRID_LIMIT < grid < 2.0**GRID_LIMIT else None


def split_running_sum(values: Pairs, grid: float | None = None) -> SplitSum | None:
    """The running sum ``S[0] = 0, S[k] = sum_{i < k} (high_i + low_i)`` (steps 2 and 3 of the
    module notes) on the grid ``grid`` (default :func:`grid_of`); None when the grid would
    leave the float64 range or a running sum of the high parts exceeds 2**HIGH_BITS of it."""
    count = values.high.shape[0]
    grid = grid_of(values.high) if grid is None else grid
    if grid is None:
        return None
    high = np.rint(values.high / grid) * grid
    rest = (values.high - high) + values.low
    hi = np.zeros(count + 1)
    lo = np.zeros(count + 1)
    np.cumsum(high, out=hi[1:])
    if count and not float(np.max(np.abs(hi))) <= 2.0**HIGH_BITS * grid:
        return None  # (every sum checked within 2**HIGH_BITS g: none reached 2**53 g, so all were exact)
    np.cumsum(rest, out=lo[1:])
    largest = float(np.max(np.abs(lo))) + (float(np.max(np.abs(rest))) if count else 0.0)
    return SplitSum(hi, lo, grid, EPS * largest * (1.0 + 2.0**-20))


def exact_phase(data: np.ndarray, kind: int, centre: float, slope: float, scale: float) -> ExactPhase | None:
    """The phase of :func:`increments` as a :class:`SplitSum`, its line rounded to the grid.

    The statistics do not see the line (a constant frequency, and for the Hadamard family a
    linear drift), so it is moved to a multiple of ``g / scale`` (the slope only where the
    products ``slope i`` stay exact): data on a coarser grid than ``g`` (integers, values
    with a large offset) then leave no low parts at all, and their sums are exact.
    """
    grid = grid_of(increments(data, kind, centre, slope, scale).high)
    if grid is None:
        return None
    unit = grid / scale
    rounded = float(np.rint(centre / unit)) * unit
    steep = float(np.rint(slope / unit)) * unit
    if not abs(steep) / unit * data.shape[0] < 2.0**52:
        steep = slope  # keep the slope exact: its products with the indices are
    return ExactPhase(split_running_sum(increments(data, kind, rounded, steep, scale), grid), rounded, steep)


def running_phase_sum(phase: SplitSum) -> SplitSum | None:
    """The running sum of the phase less a multiple of its grid near its mean (MDEV's ``C``,
    N + 1 points from N): its high parts are the phase's, less that multiple, exactly."""
    centre = float(np.rint(np.mean(phase.hi) / phase.grid)) * phase.grid
    return split_running_sum(Pairs(phase.hi - centre, phase.lo))


def _differences(values: np.ndarray, m: int, order: int, stride: int, count: int) -> np.ndarray:
    """The ``order``-th differences at lag ``m`` of ``values`` at points ``j stride``, j < ``count``."""
    if stride > 1:  # stride m: the differences of the decimated points
        w = values[: (count + order - 1) * stride + 1 : stride]
        for _ in range(order):
            w = w[1:] - w[:-1]
        return w
    w = values[: count + order * m]
    for _ in range(order):
        w = w[m:] - w[:-m]
    return w


def _reflected(values: np.ndarray, m: int) -> np.ndarray:
    """TOTDEV's phase ``P*[j]``, j = 1 - m .. N - 2 + m, reflected at both ends (``P[0] = 0``):
    ``P*[-j] = -P[j]``, ``P*[last + j] = 2 P[last] - P[last - j]``."""
    last = values.shape[0] - 1
    return np.concatenate((-values[m - 1 : 0 : -1], values, 2.0 * values[last] - values[last - 1 : last - m : -1]))


def term_error(code: int, m: int, phase_step: float, running_step: float) -> float:
    """Bound on the error of one term of level ``m`` (step 4 of the module notes).

    The d-th difference of a rounded running sum over spans of m steps errs by at most
    ``2**(d - 1) m`` steps' rounding, its evaluation by ``d 2**d`` more; TOTDEV's reflected
    terms span at most 4 m steps, and their reflection rounds once more. Of the running
    sum ``C`` of the phase (MDEV, MHDEV), the phase's own errors add ``2**(d - 2) m**2``
    of its steps (a window sum of m phase values per term).
    """
    order, running = CODES[code]
    if code == 3:
        return (4.0 * m + 40.0) * phase_step
    own = (2.0 ** (order - 1) * m + order * 2.0**order)
    if not running:
        return own * phase_step
    return own * running_step + 2.0 ** (order - 2) * m * m * phase_step


def certified(total: float, delta: float, count: int) -> bool:
    """Whether ``count`` terms whose squares sum to ``total`` (computed) are within :data:`TOL`
    of the exact sum when each term errs by at most ``delta`` (step 5 of the module notes)."""
    if count == 0:
        return True
    bound = 2.0 * delta * np.sqrt(count * total) + count * delta * delta
    bound = (bound + (27.0 + np.log2(count)) * EPS * total) * (1.0 + 2.0**-20)
    if not np.isfinite(total) or not np.isfinite(bound):
        return False
    return bound == 0.0 or bound <= TOL * total


def level_sums(data: np.ndarray, kind: int, centre: float, slope: float, scale: float, code: int,
               factors: np.ndarray, strides: np.ndarray, counts: np.ndarray) -> Levels | None:
    """Sums of squared terms of every level of gap-free data, certified, or None.

    Parameters
    ----------
    data : float64 ndarray
        Frequency (``kind`` 0, M values) or phase (``kind`` 1, M + 1 values) data, finite.
    kind, centre, slope, scale
        As :func:`increments`: the line the phase's increments lose and the power of two
        they are scaled by.
    code : int
        The kernel code of the estimator (:data:`CODES`: 0 second differences, 1 third,
        2 MDEV, 3 TOTDEV, 4 MHDEV; see :mod:`avar._kernels.classic.levels`).
    factors, strides, counts : int64 ndarrays
        Averaging factor, stride between terms and number of terms of every level
        (TOTDEV's term k is centred on phase point k = 1 .. N - 2).

    Returns
    -------
    Levels or None
        ``sums`` (float64; of the scaled phase), ``counts``, ``phase``, the detrended
        scaled phase (M + 1 points; before the running sum of MDEV and MHDEV), and the
        ``centre`` and ``slope`` its increments lost (:func:`exact_phase`). None where a
        level's error bound exceeds :data:`TOL` of its sum: the compiled kernels decide.

    Examples
    --------
    >>> y = np.array([0.0, 1.0, 0.0, 1.0, 0.0])
    >>> out = level_sums(y, 0, 0.4, 0.0, 1.0, 0, np.array([1, 2]), np.array([1, 1]), np.array([4, 2]))
    >>> out.sums.tolist(), out.counts.tolist()
    ([4.0, 0.0], [4, 2])
    """
    exact = exact_phase(data, kind, centre, slope, scale)
    if exact is None or exact.phase is None:
        return None
    phase = exact.phase
    order, running = CODES[code]
    source = running_phase_sum(phase) if running else phase
    if source is None:
        return None
    sums = np.zeros(factors.shape[0])
    for i, (m, stride, count) in enumerate(zip(factors.tolist(), strides.tolist(), counts.tolist())):
        if count <= 0:
            continue
        if code == 3:
            high = _differences(_reflected(source.hi, m), m, 2, 1, count)
            low = _differences(_reflected(source.lo, m), m, 2, 1, count)
        else:
            high = _differences(source.hi, m, order, stride, count)
            low = _differences(source.lo, m, order, stride, count)
        terms = high + low
        np.square(terms, out=terms)
        sums[i] = float(np.sum(terms))
        if not certified(sums[i], term_error(code, m, phase.step, source.step), count):
            return None
    return Levels(sums, np.asarray(counts, dtype=np.int64), phase.hi + phase.lo, exact.centre, exact.slope)


class TwinPhase(NamedTuple):
    """The compensated phase ``hi + lo`` (``lo`` float32) of :func:`detrended_phase`."""

    hi: np.ndarray
    lo: np.ndarray


def _block(high: np.ndarray, low: np.ndarray | None, start_hi: float, start_lo: float) -> tuple[np.ndarray, np.ndarray | None]:
    """The kernel's running ``total`` and ``comp`` over one block from ``start_hi + start_lo``:
    total_k = fl(total_{k-1} + h_k), comp_k = fl(comp_{k-1} + fl(e_k + l_k)), e_k the TwoSum
    error of the addition; ``low`` None: ``total`` alone (``comp`` None)."""
    total = np.cumsum(np.concatenate(([start_hi], high)))
    if low is None:
        return total[1:], None
    error = two_sum(total[:-1], high).low
    comp = np.cumsum(np.concatenate(([start_lo], error + low)))
    return total[1:], comp[1:]


def detrended_phase(data: np.ndarray, data_lo: np.ndarray | None, kind: int, centre: float, slope: float,
                    scale: float, block: int = CUMSUM_BLOCK, low: bool = True) -> TwinPhase:
    """:func:`avar._kernels.classic.phase.detrended_phase` in NumPy, bit for bit: ``hi``, ``lo``
    (M + 1 values, 0 first) of the compensated running sum of the increments less ``centre +
    slope i``, times ``scale``, by blocks of ``block`` increments (each block's own sum from 0,
    the blocks' offsets in double-double, then each block from its offset). ``kind`` 0:
    ``data`` is the frequency, 1: the phase, 2: the increments are ``data + data_lo`` (the
    running sum of a phase; ``slope`` 0), written as renormalized pairs. ``low`` False (kinds 0
    and 1): ``hi`` alone, ``lo`` left 0 (the kernel's ``hi`` never reads its compensation).

    >>> detrended_phase(np.array([1.0, 3.0, 2.0]), None, 0, 2.0, 0.0, 1.0).hi.tolist()
    [0.0, -1.0, 0.0, 0.0]
    """
    if kind == 2:
        high, error = two_sum(data, -centre)
        pairs = (high * scale, (data_lo.astype(np.float64) + error) * scale)
    else:
        pairs = increments(data, kind, centre, slope, scale)
    high, low_parts = pairs[0], (pairs[1] if low else None)
    n = high.shape[0]
    hi = np.zeros(n + 1)
    lo = np.zeros(n + 1, dtype=np.float32)
    starts = range(0, n, block)

    def part(b: int) -> np.ndarray | None:
        return None if low_parts is None else low_parts[b : b + block]

    own = [_block(high[b : b + block], part(b), 0.0, 0.0) for b in starts]  # each block's own sum from 0
    sums = [(float(t[-1]), 0.0 if c is None else float(c[-1])) for t, c in own]
    total, comp = 0.0, 0.0
    for b, (block_hi, block_lo) in zip(starts, sums):  # each block from the earlier blocks' sum (double-double)
        run_hi, run_lo = _block(high[b : b + block], part(b), total, comp)
        if kind == 2:
            run_hi, run_lo = two_sum(run_hi, run_lo)
        hi[b + 1 : b + 1 + run_hi.shape[0]] = run_hi
        if run_lo is not None:
            lo[b + 1 : b + 1 + run_hi.shape[0]] = run_lo
        s = total + block_hi
        bv = s - total
        comp += ((total - (s - bv)) + (block_hi - bv)) + block_lo
        total = s
    return TwinPhase(hi, lo)
