"""Results of the outlier-resistant estimators: :class:`Outliers`, :class:`RobustAllanVariance`.

They hold numbers and never compute estimates; :mod:`avar.stability.robust.estimator`
builds them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from avar._frozen import frozen_array
from avar.stability.allan.results import AllanVariance


@dataclass(frozen=True, eq=False)
class Outliers:
    """Samples of a series that lie far from the line through their neighbours.

    Built by :func:`avar.count_outliers`; read-only.

    Attributes
    ----------
    count : int
        How many samples were flagged.
    indices : ndarray of int64
        Their positions (0-based, increasing).
    n : int
        Length of the series (also ``n_samples``).
    threshold : float
        The flagging threshold, in robust standard deviations.
    scale : float
        The robust standard deviation of the residuals from that line
        (1.4826 MAD), in data units.
    """

    count: int
    indices: np.ndarray
    n: int
    threshold: float
    scale: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "indices", frozen_array(self.indices, np.int64))

    @property
    def n_samples(self) -> int:
        """Length of the series (the same as ``n``)."""
        return self.n

    @property
    def fraction(self) -> float:
        """count / n: the share of flagged samples."""
        return self.count / self.n

    def __int__(self) -> int:
        return self.count

    def __repr__(self) -> str:
        return (f"<Outliers {self.count} of {self.n} samples ({100 * self.fraction:.3g} %) beyond "
                f"{self.threshold:g} robust SD ({self.scale:.6g})>")


@dataclass(frozen=True, eq=False)
class RobustAllanVariance(AllanVariance):
    """An :class:`AllanVariance` ("mo") estimated after setting flagged samples aside.

    Built by :func:`avar.robust_avar`. Besides the fields of
    :class:`AllanVariance` (``n_differences`` counts the differences each
    level averaged):

    Attributes
    ----------
    outliers : Outliers
        The samples set aside (see :func:`avar.count_outliers`).
    intact : ndarray of bool
        Per level: True where the level averages only the differences whose
        2m samples hold no flagged sample (unbiased for the clean process),
        False where it is the ordinary estimator of the series with the
        flagged samples replaced by linear interpolation, less white
        noise's interpolation excess (see :func:`avar.robust_avar`).
    contaminated : ndarray
        Per level, the fraction of the N - 2m + 1 differences that touch a
        flagged sample, about 1 - (1 - p)**(2m) ~= 2 m p for a flagged
        fraction p: where it exceeds about 1/4 a robust scale of the
        differences themselves could no longer resist, which is why the
        estimator sets the samples aside instead.
    """

    outliers: Outliers | None = None
    intact: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    contaminated: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "intact", frozen_array(self.intact, np.bool_))
        object.__setattr__(self, "contaminated", frozen_array(self.contaminated))
        if len(self.intact) != len(self.levels) or len(self.contaminated) != len(self.levels):
            raise ValueError("intact and contaminated must have one value per level")
        if not isinstance(self.outliers, Outliers):
            raise TypeError("outliers must be an avar.stability.robust.results.Outliers")

    def describe(self) -> str:
        """The :class:`AllanVariance` line, plus the flagged samples."""
        return (super().describe() + f", robust: {self.outliers.count} outlying samples set aside "
                f"({100 * self.outliers.fraction:.3g} %)")
