"""One vocabulary (docs/conventions.md): parameter aliases, their deprecation, confidence levels.

``rate`` is the sampling rate (R's ``freq`` an alias in the R-compatible functions),
``confidence`` a probability (``alpha``, 1 - confidence, R's alias in :func:`avar.avlr` and a
deprecated one elsewhere). :func:`renamed` resolves a parameter given under either spelling and
warns for a deprecated one; :func:`resolve_confidence` does it for ``confidence``/``alpha`` and
keeps the significance 1 - confidence exact.
"""

from __future__ import annotations

import warnings
from decimal import Decimal
from typing import Any, NamedTuple

from avar._validation import check_freq, check_real

__all__ = ["CONFIDENCE_95", "REMOVED_IN", "Default", "check_confidence", "check_rate", "complement",
           "deprecated_significance", "renamed", "resolve_confidence"]

#: The release that removes the deprecated spellings (``alpha=`` for ``confidence=``, ``freq=`` for ``rate=``
#: outside the R-compatible functions, ``--alpha``, ``--units``); see docs/conventions.md.
REMOVED_IN = "0.3.0"


def check_rate(rate: Any, name: str = "rate") -> float:
    """A finite, positive sampling rate (Hz) as float; messages name ``name``, the spelling the caller used."""
    return check_freq(rate, name)


class Default(float):
    """A float default that knows it was not given: ``value is DEFAULT`` tells a default from an explicit equal value.

    Its repr is the number's, so signatures read ``confidence=0.95``.
    """

    __slots__ = ()


#: The default confidence of intervals of fits and reports (a probability).
CONFIDENCE_95 = Default(0.95)


def complement(probability: float) -> float:
    """``1 - probability``, from the shortest decimal spelling of ``probability``.

    ``complement(0.95)`` is the float 0.05 itself (``1 - 0.95`` is 0.05000000000000004), so
    ``confidence=0.95`` and the deprecated ``alpha=0.05`` give the very same numbers.

    >>> complement(0.95), complement(0.05), complement(0.6827)
    (0.05, 0.95, 0.3173)
    """
    return float(1 - Decimal(repr(float(probability))))


def _probability(value: Any, name: str, example: str) -> float:
    value = check_real(value, name)
    if not 0.0 < value < 1.0:
        raise ValueError(f"{name} must be in (0, 1) ({example}), got {value!r}")
    return value


def check_confidence(value: Any, name: str = "confidence") -> float:
    """A confidence level: a probability strictly between 0 and 1 (0.95 for 95 % intervals)."""
    return _probability(value, name, "e.g. 0.95 for 95% intervals")


class Renamed(NamedTuple):
    """A parameter's value and the spelling the caller gave it under."""

    value: Any
    spelling: str


class ConfidenceLevel(NamedTuple):
    """A confidence level and its significance, 1 - confidence (both exact to their decimal spelling)."""

    confidence: float
    significance: float


def renamed(new: str, new_value: Any, old: str, old_value: Any, *, deprecated: bool, default: Any = None,
            note: str = "", stacklevel: int = 3) -> Renamed:
    """The value of a parameter spelled ``new`` or, as an alias, ``old``; and the spelling the caller used.

    ``new_value is default`` means ``new`` was not given. Both given: a TypeError naming both.
    A ``deprecated`` alias warns (DeprecationWarning, at the caller's line with the default
    ``stacklevel``) naming the alias, its replacement (``note`` says how to convert) and the
    release that removes it.
    """
    if old_value is None:
        return Renamed(new_value, new)
    if new_value is not default:
        raise TypeError(f"give {new}= or {old}= (its {'deprecated ' if deprecated else ''}alias), not both")
    if deprecated:
        warnings.warn(f"{old}= is deprecated and will be removed in avar {REMOVED_IN}; use {new}= instead{note}",
                      DeprecationWarning, stacklevel=stacklevel)
    return Renamed(old_value, old)


def resolve_confidence(confidence: Any, alpha: Any, *, deprecated: bool = True, stacklevel: int = 4
                       ) -> ConfidenceLevel:
    """(confidence, significance = 1 - confidence) of ``confidence=`` or its alias ``alpha=`` (1 - confidence).

    The significance is kept as given when ``alpha`` is (``alpha=1e-300`` keeps its tail;
    its confidence rounds to 1); else it is :func:`complement` of the confidence. A
    ``deprecated`` alias warns (see :func:`renamed`).
    """
    value, used = renamed("confidence", confidence, "alpha", alpha, deprecated=deprecated,
                          default=CONFIDENCE_95, note=" (confidence = 1 - alpha, e.g. confidence=0.95 for alpha=0.05)",
                          stacklevel=stacklevel)
    if used == "alpha":
        significance = _probability(value, "alpha", "1 - the confidence level, e.g. 0.05 for 95% intervals")
        return ConfidenceLevel(complement(significance), significance)
    level = check_confidence(value)
    return ConfidenceLevel(level, complement(level))


def deprecated_significance(confidence: float | None) -> float | None:
    """A result's deprecated ``alpha`` attribute: 1 - its ``confidence`` (None stays None), with a DeprecationWarning."""
    warnings.warn(f"the attribute alpha (1 - confidence) is deprecated and will be removed in avar {REMOVED_IN}; "
                  "read confidence instead", DeprecationWarning, stacklevel=3)
    return None if confidence is None else complement(confidence)
