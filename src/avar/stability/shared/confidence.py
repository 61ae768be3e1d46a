"""Confidence levels: one sigma, the catalogue's default, and how a level is printed."""

from __future__ import annotations

import math

#: One standard deviation, erf(1 / sqrt(2)) = 0.682689...: the default confidence. Stable32 prints
#: it as "Confidence Factor = 0.683" and computes with the exact value: its printed bounds are
#: reproduced with this, not with 0.683, whose intervals are as wide as one sigma's with 0.15 %
#: fewer degrees of freedom (``tests/stability/uncertainty/test_chi2.py``).
ONE_SIGMA = math.erf(1.0 / math.sqrt(2.0))
DEFAULT_CONFIDENCE = ONE_SIGMA


def format_confidence(confidence: float) -> str:
    """A confidence level as printed: one sigma as Stable32 prints it (0.683), any other as given.

    >>> format_confidence(ONE_SIGMA), format_confidence(0.95), format_confidence(0.9973)
    ('0.683', '0.95', '0.9973')
    """
    return "0.683" if confidence == ONE_SIGMA else f"{confidence:g}"
