"""The power-law noise exponent alpha, S_y(f) ~ f**alpha, that a caller may fix.

Stable32 and every statistic of the catalogue let the user fix the noise type
instead of identifying it per level: alpha = 2 white PM, 1 flicker PM, 0 white
FM, -1 flicker FM, -2 random-walk FM (NIST SP 1065, Table 3). The fixed alpha
sets the EDF, the bias corrections and the chi-squared bounds of every level.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from avar._validation import short_repr

#: The docstring entry of ``alpha=`` shared by the statistics.
ALPHA_PARAMETER = """    alpha : int, optional
        Fix the power-law noise exponent (2 white PM, 1 flicker PM, 0 white
        FM, -1 flicker FM, -2 random-walk FM) at every level, as Stable32
        allows: it sets the EDF, bias corrections and bounds where the
        statistic has them; None (default) identifies it per level
        (:mod:`avar.stability.uncertainty.noise_id`).
"""


def check_alpha(alpha: Any) -> int | None:
    """``alpha=``: None, or an integer noise exponent in -2 .. 2; otherwise an error naming ``alpha``.

    >>> check_alpha(None), check_alpha(-1)
    (None, -1)
    >>> check_alpha(3)
    Traceback (most recent call last):
    ...
    ValueError: alpha must be in -2 .. 2 (2 white PM, 1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM), got 3
    """
    if alpha is None:
        return None
    if isinstance(alpha, (bool, np.bool_)) or not isinstance(alpha, numbers.Integral):
        raise TypeError(f"alpha must be None or an integer noise exponent in -2 .. 2, got {short_repr(alpha)}")
    if not -2 <= int(alpha) <= 2:
        raise ValueError(f"alpha must be in -2 .. 2 (2 white PM, 1 flicker PM, 0 white FM, -1 flicker FM, "
                         f"-2 random-walk FM), got {int(alpha)}")
    return int(alpha)
