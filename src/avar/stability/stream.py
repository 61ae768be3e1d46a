"""Deviations updated as data arrive: :class:`Stream`.

For long-running monitoring of a clock or a sensor: feed chunks of any size
with :meth:`Stream.update`, read the current deviations with
:meth:`Stream.result` at any time. O(levels) work per sample, memory bounded
by the largest tau (the last 2m or 3m phase points, as double-double numbers,
and for MDEV/TDEV the last m second differences of each level; an update
works on a copy of that history followed by the chunk), never by the length
of the stream. The numbers equal the batch function's on the
concatenated data (to rounding, ~1e-12 relative).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from avar._kernels.stream import stream_update
from avar._validation import check_freq, short_repr
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.grids import grid_factors
from avar.stability.shared.inputs import DATA_TYPES, DEFAULT_CONFIDENCE, check_data
from avar.stability.shared.noise_types import check_alpha
from avar.stability.shared.term_counts import term_counts
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES
from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf

#: Statistic -> (kernel kind, points spanned per m, divisor K of the variance).
STREAM_STATISTICS = {"oadev": (0, 2, 2.0), "adev": (1, 2, 2.0), "ohdev": (2, 3, 6.0), "hdev": (3, 3, 6.0),
                     "mdev": (4, 3, 2.0), "tdev": (4, 3, 2.0)}


class Stream:
    """A deviation accumulated chunk by chunk (``allantools.realtime``'s job, for six statistics).

    Parameters
    ----------
    statistic : {"oadev", "adev", "mdev", "tdev", "hdev", "ohdev"}
        The deviation, as the batch function of that name.
    taus : array_like of float
        Averaging times in seconds (rounded to whole m = tau rate); the
        memory is about 3 max(m) + sum(m) floats.
    rate : float
        Sampling rate in Hz.
    data_type : {"freq", "phase"}
        What the chunks hold, as the batch functions.
    confidence : float
        Two-sided confidence level of the bounds.
    alpha : int
        Power-law noise exponent (2 white PM .. -2 random-walk FM) used for
        the EDF and bounds: a stream keeps no data to identify the noise, so
        give the clock's (default 0, white FM).

    Examples
    --------
    >>> import numpy as np, avar
    >>> y = np.random.default_rng(0).standard_normal(10000)
    >>> stream = avar.Stream("oadev", taus=[1, 10, 100])
    >>> for chunk in np.array_split(y, 7):
    ...     _ = stream.update(chunk)
    >>> batch = avar.oadev(y, taus=[1, 10, 100])
    >>> bool(np.allclose(stream.result().deviation, batch.deviation, rtol=1e-12, atol=0))
    True
    >>> stream.n_samples
    10000
    """

    def __init__(self, statistic: str, taus: Any, rate: float = 1.0, data_type: str = "freq",
                 confidence: float = DEFAULT_CONFIDENCE, alpha: int = 0) -> None:
        if not isinstance(statistic, str) or statistic not in STREAM_STATISTICS:
            raise ValueError(f"statistic must be one of {tuple(STREAM_STATISTICS)}, got {short_repr(statistic)}")
        if not isinstance(data_type, str) or data_type not in DATA_TYPES:
            raise ValueError(f"data_type must be 'freq' or 'phase', got {short_repr(data_type)}")
        if isinstance(taus, str):
            raise TypeError("taus must be an array of averaging times in seconds (a stream has no length "
                            f"to build a named grid from), got {taus!r}")
        self.rate = check_freq(rate, "rate")
        if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, (int, float)) \
                or not 0 < confidence < 1:
            raise ValueError(f"confidence must be a number in (0, 1), got {short_repr(confidence)}")
        fixed = check_alpha(alpha)
        if fixed is None:
            raise TypeError("alpha must be an integer noise exponent in -2 .. 2 (a stream cannot identify it)")
        self.statistic, self.data_type, self.confidence, self.alpha = statistic, data_type, float(confidence), fixed
        self.factors = grid_factors(taus, self.rate, 2**40, first_octave=0, context="of a stream")
        self._kind, span, self._k = STREAM_STATISTICS[statistic]
        self._ring_hi = np.zeros(span * int(self.factors[-1]) + 1)  # the last span max(m) + 1 phase points
        self._ring_lo = np.zeros_like(self._ring_hi)
        self._state = np.array([1.0 if data_type == "freq" else 0.0, 0.0, 0.0])
        levels = self.factors.size
        self._sums, self._comps = np.zeros(levels), np.zeros(levels)
        self._counts = np.zeros(levels, dtype=np.int64)
        modified = self._kind == 4
        self._doffsets = np.concatenate(([0], np.cumsum(self.factors)[:-1])).astype(np.int64)
        self._dring = np.zeros(int(self.factors.sum()) if modified else 1)
        self._dsum, self._dcount = np.zeros(levels), np.zeros(levels, dtype=np.int64)
        self.n_samples = 0

    def update(self, chunk: Any) -> Stream:
        """Add the samples of ``chunk`` (1-D, finite) and return the stream."""
        values, scanned = check_data(chunk, self.data_type, "raise") if np.size(chunk) else (np.zeros(0), None)
        stream_update(values, self.data_type == "freq", self._kind, self._state, self._ring_hi, self._ring_lo,
                      self.factors, self._sums, self._comps, self._counts, self._dring, self._doffsets,
                      self._dsum, self._dcount)
        self.n_samples += values.size
        return self

    @property
    def n_phase(self) -> int:
        """Phase points so far (frequency samples + 1 once data arrived)."""
        return int(self._state[0]) if self.n_samples else 0

    def result(self) -> Deviation:
        """The current deviations of the levels with at least one term, as a :class:`avar.Deviation`."""
        keep = self._counts > 0
        if not keep.any():
            raise ValueError(f"no level has a term yet ({self.n_samples} samples); feed more data with update()")
        m = self.factors[keep]
        n = self._counts[keep]
        tau = m / self.rate
        scale = m.astype(np.float64) ** 2 if self.data_type == "freq" else tau**2
        if self._kind == 4:
            scale = scale * m.astype(np.float64) ** 2
        variance = self._sums[keep] / (self._k * n * scale)
        if self.statistic == "tdev":
            variance = variance * tau**2 / 3.0
        deviation = np.sqrt(variance)
        alpha = np.full(m.size, self.alpha, dtype=np.int64)
        edf = estimator_edf(self.statistic, alpha, m, self.n_phase)
        lci, uci = chi2_bounds(deviation, edf, self.confidence, quantiles=CATALOGUE_QUANTILES)
        return Deviation(taus=tau, averaging_factors=m, deviation=deviation, variance=variance, n=n, alpha=alpha,
                         edf=edf, lci=lci, uci=uci, estimator=self.statistic, data_type=self.data_type,
                         rate=self.rate, n_samples=self.n_samples, confidence=self.confidence)

    def expected_terms(self) -> np.ndarray:
        """Terms the batch function would average at every level now (NIST SP 1065's counts)."""
        return term_counts(self.statistic, self.n_phase, self.factors)

    def __repr__(self) -> str:
        return (f"<Stream {self.statistic} of {self.n_samples} {self.data_type} samples at {self.rate:g} Hz, "
                f"{self.factors.size} levels>")
