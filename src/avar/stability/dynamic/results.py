"""The result of a dynamic deviation (:func:`avar.dynamic`, :func:`avar.dadev`, :func:`avar.dhdev`).

Results hold numbers; they never compute estimates (the bands of :meth:`DynamicDeviation.unstable`
are chi-squared quantiles of the EDFs held).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import check_freq, short_repr
from avar.stability.shared.confidence import format_confidence
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.registry import CLASSIC, LONG_NAMES
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES, chi2_bounds

#: Columns of :meth:`DynamicDeviation.summary`.
SUMMARY_COLUMNS = ["Time", "Window", "Tau", "m", "N terms", "Alpha", "Min sigma", "Sigma", "Max sigma", "EDF"]
#: Columns of :meth:`DynamicDeviation.unstable`.
UNSTABLE_COLUMNS = ["First window", "Last window", "Windows", "Start", "End", "Change from", "Change to", "Change",
                    "Worst tau", "Ratio"]
#: The default confidence of :meth:`DynamicDeviation.unstable`: a stationary window is flagged
#: with probability at most 1 - this.
UNSTABLE_CONFIDENCE = 0.99


def _frozen(values: Any, dtype: type, shape: tuple[int, ...]) -> np.ndarray:
    array = np.array(values, dtype=dtype, copy=True)
    if array.shape != shape:
        raise ValueError(f"expected an array of shape {shape}, got {array.shape}")
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class DynamicDeviation:
    """A classic deviation in every window of a sliding window (Stable32's dynamic stability).

    Build it with :func:`avar.dynamic`, :func:`avar.dadev` or :func:`avar.dhdev`; read-only.
    Row ``w`` of the 2-D fields is window ``w``: samples ``starts[w] .. starts[w] + window - 1``,
    whose every level is what ``avar.<estimator>`` gives for those samples alone.

    Attributes
    ----------
    times : ndarray
        Each window's centre (s, from the first sample at 0; frequency samples span
        tau0 each, so a window of frequency data spans window / rate s).
    starts : ndarray of int64
        Each window's first sample.
    taus : ndarray
        Averaging times tau = m / rate (s), up to a quarter of the window.
    averaging_factors : ndarray of int64
        Averaging factors m.
    deviation, variance : ndarray, windows x taus
        The deviation (dimensionless; TDEV, HTDEV in s) and its square; NaN where gaps left no term.
    n_terms, alpha : ndarray of int64, windows x taus
        Terms averaged; the identified power-law noise exponent (2 white PM .. -2 random-walk FM).
    edf, lci, uci : ndarray, windows x taus
        Equivalent degrees of freedom and the chi-squared bounds of the deviation.
    band_edf : ndarray, windows x taus
        The EDF each window would have if the record were stationary: the statistic's EDF for
        a window of this length under the noise the whole record shows at each tau (a window's
        own identification, from few averages at long taus, errs more often); the bands of
        :meth:`unstable` take it.
    record : Deviation
        The statistic of the whole record at the same taus: the reference of :meth:`unstable`.
    estimator : str
        The statistic (``"oadev"`` for DADEV, ``"ohdev"`` for DHDEV, ...).
    data_type : {"phase", "freq"}
    rate : float
        Sampling rate (Hz).
    window, step : int
        Samples per window and from one window's start to the next.
    n_samples : int
        Length of the record.
    confidence : float
        Two-sided confidence level of ``lci`` and ``uci``.
    """

    times: np.ndarray
    starts: np.ndarray
    taus: np.ndarray
    averaging_factors: np.ndarray
    deviation: np.ndarray
    variance: np.ndarray
    n_terms: np.ndarray
    alpha: np.ndarray
    edf: np.ndarray
    lci: np.ndarray
    uci: np.ndarray
    band_edf: np.ndarray
    record: Deviation
    estimator: str
    data_type: str
    rate: float
    window: int
    step: int
    n_samples: int
    confidence: float

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        n_windows, n_taus = len(np.asarray(self.times)), len(np.asarray(self.taus))
        set_field(self, "times", _frozen(self.times, np.float64, (n_windows,)))
        set_field(self, "starts", _frozen(self.starts, np.int64, (n_windows,)))
        set_field(self, "taus", _frozen(self.taus, np.float64, (n_taus,)))
        set_field(self, "averaging_factors", _frozen(self.averaging_factors, np.int64, (n_taus,)))
        for name in ("deviation", "variance", "edf", "lci", "uci", "band_edf"):
            set_field(self, name, _frozen(getattr(self, name), np.float64, (n_windows, n_taus)))
        for name in ("n_terms", "alpha"):
            set_field(self, name, _frozen(getattr(self, name), np.int64, (n_windows, n_taus)))
        if not isinstance(self.record, Deviation) or len(self.record) != n_taus:
            raise ValueError(f"record must be the Deviation of the whole record at the {n_taus} taus")
        if self.estimator not in CLASSIC:
            raise ValueError(f"estimator must be one of {list(CLASSIC)}, got {short_repr(self.estimator)}")
        if self.data_type not in ("phase", "freq"):
            raise ValueError(f"data_type must be 'phase' or 'freq', got {short_repr(self.data_type)}")
        set_field(self, "rate", check_freq(self.rate, "rate"))
        for name in ("window", "step", "n_samples"):
            set_field(self, name, int(getattr(self, name)))
        set_field(self, "confidence", float(self.confidence))

    @property
    def n_windows(self) -> int:
        """Number of windows (rows)."""
        return len(self.times)

    @property
    def name(self) -> str:
        """``"D"`` and the statistic's upper-case name, e.g. ``"DOADEV"`` (Stable32's DAVAR)."""
        return "D" + self.estimator.upper()

    @property
    def long_name(self) -> str:
        """E.g. ``"dynamic overlapping Allan deviation"``."""
        return "dynamic " + LONG_NAMES.get(self.estimator, self.estimator)

    def __len__(self) -> int:
        return self.n_windows

    def window_span(self) -> tuple[np.ndarray, np.ndarray]:
        """Each window's first and last instant (s): frequency samples span 1 / rate each, phase
        points are instants."""
        last = self.starts + (self.window if self.data_type == "freq" else self.window - 1)
        return self.starts / self.rate, last / self.rate

    def summary(self) -> pd.DataFrame:
        """One row per window and level (long format): ``Time`` (the window's centre, s), ``Window``
        (its number), ``Tau`` (s), ``m``, ``N terms``, ``Alpha``, ``Min sigma``, ``Sigma``, ``Max
        sigma``, ``EDF``."""
        n_windows, n_taus = self.deviation.shape
        return pd.DataFrame({
            "Time": np.repeat(self.times, n_taus), "Window": np.repeat(np.arange(n_windows), n_taus),
            "Tau": np.tile(self.taus, n_windows), "m": np.tile(self.averaging_factors, n_windows),
            "N terms": self.n_terms.ravel(), "Alpha": self.alpha.ravel(), "Min sigma": self.lci.ravel(),
            "Sigma": self.deviation.ravel(), "Max sigma": self.uci.ravel(), "EDF": self.edf.ravel(),
        }, columns=SUMMARY_COLUMNS)

    def reference(self, kind: str = "record") -> np.ndarray:
        """The deviation a stationary record's windows scatter about, per tau: the whole record's
        (``"record"``, :attr:`record`), or the median of the windows' (``"median"``: not pulled
        by a local event, such as a frequency step, that raises the whole record's at long taus)."""
        if kind == "record":
            return np.asarray(self.record.deviation)
        if kind == "median":
            with warnings.catch_warnings():  # a tau without any value (gaps) has a NaN median
                warnings.simplefilter("ignore", RuntimeWarning)
                return np.nanmedian(self.deviation, axis=0)
        raise ValueError(f"reference must be 'record' or 'median', got {short_repr(kind)}")

    def band(self, confidence: float = UNSTABLE_CONFIDENCE, reference: str = "record") -> tuple[np.ndarray, np.ndarray]:
        """Where each window's deviation lies, with probability ``confidence`` at each level, if
        the record were stationary: the reference deviation s (:meth:`reference`; by default the
        whole record's) times sqrt(chi2_q(edf) / edf) and sqrt(chi2_{1-q}(edf) / edf), edf the
        window's :attr:`band_edf` (windows x taus; NaN without EDF)."""
        confidence = _check_confidence(confidence)
        lower = np.full(self.deviation.shape, np.nan)
        upper = np.full(self.deviation.shape, np.nan)
        reference = np.broadcast_to(self.reference(reference), self.deviation.shape)
        known = np.isfinite(self.band_edf) & np.isfinite(reference) & (reference > 0)
        if known.any():
            low, high = chi2_bounds(reference[known], self.band_edf[known], confidence, quantiles=CATALOGUE_QUANTILES)
            lower[known] = reference[known] ** 2 / high
            upper[known] = reference[known] ** 2 / low
        return lower, upper

    def outside(self, confidence: float = UNSTABLE_CONFIDENCE, reference: str = "record") -> np.ndarray:
        """Which windows (rows) leave the band of a stationary record (:meth:`band`) at which taus (columns).

        Each level's band is taken at 1 - (1 - confidence) / (number of taus) (Bonferroni), so
        that a stationary window leaves it at some tau with probability at most 1 - confidence.
        """
        confidence = _check_confidence(confidence)
        lower, upper = self.band(1.0 - (1.0 - confidence) / max(1, len(self.taus)), reference)
        with np.errstate(invalid="ignore"):
            return (self.deviation < lower) | (self.deviation > upper)

    def unstable(self, confidence: float = UNSTABLE_CONFIDENCE, reference: str = "record") -> pd.DataFrame:
        """The non-stationarity summary: each run of consecutive windows that leave the band of a
        stationary record (:meth:`outside`) at some tau, one row per run. The band is about the
        whole record's deviation by default; ``reference="median"`` takes the windows' median,
        which a local event does not pull (fewer stationary windows flagged around it).

        Columns: ``First window``, ``Last window``, ``Windows`` (how many), ``Start`` and ``End``
        (s: the run's first and last instant), ``Change from`` and ``Change to`` (s: the stretch
        that every window of the run holds: where a single change, such as a frequency step or a
        jump of the noise level, that only these windows see, lies; NaN when the windows share
        none), ``Change`` (its middle), ``Worst tau`` (s) and ``Ratio`` (the run's deviation over
        the reference where they differ most). No row: no window leaves its band.

        Examples
        --------
        >>> import numpy as np
        >>> import avar
        >>> y = np.random.default_rng(3).standard_normal(20_000)
        >>> y[12_000:] += 1.0                     # a frequency step of one sigma at t = 12,000 s
        >>> runs = avar.dadev(y, window=1000, step=100).unstable()
        >>> worst = runs.loc[runs.Ratio.idxmax()]
        >>> bool(abs(worst.Change - 12_000) <= 100)
        True
        """
        flags = self.outside(confidence, reference)
        reference_deviation = self.reference(reference)
        windows = np.flatnonzero(flags.any(axis=1))
        first_time, last_time = self.window_span()
        rows = []
        if windows.size:
            breaks = np.flatnonzero(np.diff(windows) > 1)
            for run in np.split(windows, breaks + 1):
                a, b = int(run[0]), int(run[-1])
                cells = flags[a:b + 1]
                ratio = self.deviation[a:b + 1] / reference_deviation[None, :]
                with np.errstate(divide="ignore", invalid="ignore"):
                    distance = np.where(cells, np.abs(np.log(ratio)), -np.inf)
                row, column = np.unravel_index(int(np.argmax(distance)), distance.shape)
                shared = first_time[b] <= last_time[a]
                low, high = (first_time[b], last_time[a]) if shared else (np.nan, np.nan)
                rows.append([a, b, b - a + 1, first_time[a], last_time[b], low, high, (low + high) / 2,
                             self.taus[column], ratio[row, column]])
        frame = pd.DataFrame(rows, columns=UNSTABLE_COLUMNS)
        frame.index.name = "Run"
        return frame.astype({"First window": np.int64, "Last window": np.int64, "Windows": np.int64})

    def describe(self) -> str:
        """One line: statistic, input, windows and confidence."""
        return (f"{self.name} ({self.long_name}) of {self.n_samples} {self.data_type} samples at {self.rate:g} Hz, "
                f"{self.n_windows} windows of {self.window} samples every {self.step}, {len(self.taus)} taus, "
                f"{format_confidence(self.confidence)} confidence")

    def __repr__(self) -> str:
        return f"<DynamicDeviation {self.describe()}>"

    def plot(self, kind: str = "heatmap", **kwargs: Any):
        """The deviation over time and tau: a heat map with a log colour scale (``kind="heatmap"``)
        or Stable32's 3-D view (``kind="surface"``); see :func:`avar.plotting.dynamic.plot_dynamic`."""
        from avar.plotting import plot_dynamic

        return plot_dynamic(self, kind=kind, **kwargs)


def _check_confidence(confidence: Any) -> float:
    if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, (int, float, np.integer, np.floating)) \
            or not 0.0 < float(confidence) < 1.0:
        raise ValueError(f"confidence must be a number in (0, 1), e.g. 0.99, got {short_repr(confidence)}")
    return float(confidence)
