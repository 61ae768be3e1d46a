"""The result of the deviation family (:func:`avar.adev` ... :func:`avar.totdev`): :class:`Deviation`.

Results hold numbers; they never compute estimates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._escape import html_text
from avar._frozen import frozen_array
from avar._validation import check_freq, short_repr
from avar.stability.shared.confidence import format_confidence
from avar.stability.shared.registry import LONG_NAMES, STATISTICS

#: Columns of :meth:`Deviation.summary`, in the order of Stable32's run table.
SUMMARY_COLUMNS = ["Tau", "m", "N terms", "Alpha", "Min sigma", "Sigma", "Max sigma", "EDF"]


@dataclass(frozen=True, eq=False)
class Deviation:
    """One time-and-frequency stability deviation, level by level.

    Build it with :func:`avar.adev`, :func:`avar.oadev`, :func:`avar.mdev`,
    :func:`avar.tdev`, :func:`avar.hdev`, :func:`avar.ohdev`,
    :func:`avar.totdev`, :func:`avar.mhdev`, :func:`avar.htdev`, the total and Theo
    statistics :func:`avar.mtotdev`, :func:`avar.ttotdev`, :func:`avar.htotdev`,
    :func:`avar.mhtotdev`, :func:`avar.theo1` and :func:`avar.theoh`, or :func:`avar.pdev`, :func:`avar.mtie`,
    :func:`avar.tierms`, :func:`avar.gcodev`, :func:`avar.three_cornered_hat`
    or :class:`avar.Stream`; the fields are read-only. MTIE, TIE rms and
    GCODEV carry no bounds (``edf``, ``lci``, ``uci`` NaN).

    Attributes
    ----------
    taus : ndarray
        Averaging times tau = m / rate (s).
    averaging_factors : ndarray of int64
        Averaging factors m.
    deviation : ndarray
        The deviation (dimensionless; TDEV, HTDEV and TTOTDEV in seconds).
    variance : ndarray
        Its square.
    n_terms : ndarray of int64
        (property) Number of terms averaged at each level (Stable32's ``#``).
    n : ndarray of int64
        The same term counts (``n_terms``'s older name).
    alpha : ndarray of int64
        Identified power-law noise exponent, S_y(f) ~ f**alpha (2 white PM,
        1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM).
    edf : ndarray
        Equivalent degrees of freedom (Greenhall and Riley 2003; TOTDEV: NIST SP 1065).
    lci, uci : ndarray
        Lower and upper chi-squared confidence bounds of the deviation.
    estimator : str
        The statistic's name: ``"adev"`` ... ``"totdev"``, or one of the registry
        :data:`avar.stability.shared.registry.DEVIATION_STATISTICS` (and ``"gcodev"``).
    data_type : {"phase", "freq"}
        What the input held: phase (time error, s) or fractional frequency.
    rate : float
        Sampling rate (Hz).
    n_samples : int
        Length of the input.
    confidence : float
        Two-sided confidence level of ``lci`` and ``uci``.
    """

    taus: np.ndarray
    averaging_factors: np.ndarray
    deviation: np.ndarray
    variance: np.ndarray
    n: np.ndarray
    alpha: np.ndarray
    edf: np.ndarray
    lci: np.ndarray
    uci: np.ndarray
    estimator: str
    data_type: str
    rate: float
    n_samples: int
    confidence: float

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        for name in ("taus", "deviation", "variance", "edf", "lci", "uci"):
            set_field(self, name, frozen_array(getattr(self, name)))
        for name in ("averaging_factors", "n", "alpha"):
            set_field(self, name, frozen_array(getattr(self, name), np.int64))
        names = ("taus", "averaging_factors", "deviation", "variance", "n", "alpha", "edf", "lci", "uci")
        if len({len(getattr(self, name)) for name in names}) != 1:
            raise ValueError(f"{', '.join(names)} must have one length")
        known = tuple(STATISTICS)
        if self.estimator not in known:
            raise ValueError(f"estimator must be one of {sorted(set(known))}, got {short_repr(self.estimator)}")
        if self.data_type not in ("phase", "freq"):
            raise ValueError(f"data_type must be 'phase' or 'freq', got {short_repr(self.data_type)}")
        set_field(self, "rate", check_freq(self.rate, "rate"))
        set_field(self, "n_samples", int(self.n_samples))
        set_field(self, "confidence", float(self.confidence))

    @property
    def n_terms(self) -> np.ndarray:
        """Number of terms averaged at each level (Stable32's ``#``; also ``n``)."""
        return self.n

    @property
    def name(self) -> str:
        """The estimator's upper-case name, e.g. ``"OADEV"``."""
        return self.estimator.upper()

    @property
    def long_name(self) -> str:
        """The statistic's long name, e.g. ``"overlapping Allan deviation"``."""
        return LONG_NAMES.get(self.estimator, self.estimator)

    def __len__(self) -> int:
        return len(self.taus)

    def summary(self) -> pd.DataFrame:
        """One row per level, as Stable32's run table.

        Columns: ``Tau`` (s), ``m`` (averaging factor), ``N terms`` (terms
        averaged), ``Alpha`` (noise exponent), ``Min sigma`` (lci), ``Sigma``
        (the deviation; TDEV in s), ``Max sigma`` (uci), ``EDF``. The index
        ``Level`` numbers the levels from 1.
        """
        return pd.DataFrame(
            {
                "Tau": self.taus,
                "m": self.averaging_factors,
                "N terms": self.n,
                "Alpha": self.alpha,
                "Min sigma": self.lci,
                "Sigma": self.deviation,
                "Max sigma": self.uci,
                "EDF": self.edf,
            },
            columns=SUMMARY_COLUMNS,
            index=pd.RangeIndex(1, len(self) + 1, name="Level"),
        )

    def describe(self) -> str:
        """One line: estimator, input, rate, levels and confidence."""
        return (
            f"{self.name} ({self.long_name}) of {self.n_samples} {self.data_type} samples "
            f"at {self.rate:g} Hz, {len(self)} levels, {format_confidence(self.confidence)} confidence"
        )

    def __str__(self) -> str:
        table = self.summary().to_string(index=False, float_format=lambda v: f"{v:.6g}")
        return self.describe() + "\n" + table

    def __repr__(self) -> str:
        return f"<Deviation {self.describe()}>"

    def _repr_html_(self) -> str:
        return f"<p>{html_text(self.describe())}</p>" + self.summary().to_html(index=False)

    def plot(self, **kwargs: Any):
        """Log-log plot of the deviation with its error bars; see :func:`avar.plotting.plot_deviation`."""
        from avar.plotting import plot_deviation

        return plot_deviation(self, **kwargs)
