"""ITU-T wander masks of MTIE and TDEV, and the check of a measured curve against one.

Telecom clocks are judged by their wander: the MTIE and TDEV of their time error must stay
below the limit a Recommendation sets for the clock's class, at every observation interval
tau it covers. A mask here is data: pieces on tau intervals, each a sum of power laws
``sum_i c_i tau**p_i`` (tau in seconds, the limit in seconds), transcribed from the
Recommendation's table that is named in :attr:`Mask.source`. :func:`mask_check` evaluates a
mask at the taus of an :func:`avar.mtie` or :func:`avar.tdev` result and reports, per tau,
the limit, the margin (limit / measured: above 1 passes) and whether it passes.

The masks included are those of the clocks' wander generation under constant temperature
(the conditions a laboratory measurement meets):

* G.811 (PRC, primary reference clock): MTIE and TDEV (Tables 1 and 2 of G.811 (1997)).
* G.8272 PRTC-A and PRTC-B (primary reference time clock): MTIE and TDEV (Tables 1 to 4).
* G.8262 EEC option 1 and option 2 (synchronous Ethernet equipment clock): MTIE and TDEV
  (Tables 1, 3, 4, 5 of G.8262 (07/2010)); G.813 SEC option 1 and option 2 have the same
  limits (G.8262 took them over) and are listed under their own names too.

and the network limits: the wander an interface may show (measured against an ideal
reference, whatever the clocks before it), names ending in "network":

* G.823 (03/2000) synchronization interfaces of the 2048 kbit/s hierarchy: PRC, SSU, SEC and
  PDH (2048 kbit/s, 2048 kHz) outputs; G.824 (03/2000) DS1 (1544 kbit/s) synchronization
  interface. The Recommendations' tables themselves were not found: the pieces here are
  those that reproduce, to the printed digits, every value Semtech's ToPTrace utility tabulates
  for each mask (from 1 s up; so these masks start at 1 s, not 0.1 s). Cross-checks: the PRC
  pieces are G.811's (Tables 1 and 2) up to 10^4 s, and the SEC pieces are those of G.8261.
* G.8261 (08/2013) SyncE option 1 network: Tables 4 and 5, as transcribed in the timetools
  package; the same values as the G.823 SEC limit.

Not included: G.812 (SSU and node clock types I to VI) wander generation: no printed copy of
its tables was found, and a mask is only added from printed values. A user may build any mask
with :class:`Mask` and :class:`MaskPiece`.

References
----------
ITU-T G.811 (1997), G.813 (2003), G.8262/Y.1362 (2010), G.8272/Y.1367 (2018): timing
characteristics of PRC, SEC, EEC and PRTC clocks. ITU-T G.8261/Y.1361 (08/2013): timing and
synchronization aspects in packet networks (clause 9.2.1.1, network limits). ITU-T G.823 and
G.824 (03/2000): the control of jitter and wander within digital networks based on the 2048 and
1544 kbit/s hierarchies (clauses 6.2, network limits for wander at synchronization interfaces).
R. Smiley, timetools 0.6.0 (2017), ``timetools/synchronization/compliance/ituTG8261/eecOption1/
networkWander.py``. Semtech, ToPSync ToPTrace utility, ``Interface/Masks.cpp`` (2015).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from avar._frozen import frozen_array
from avar._validation import short_repr

__all__ = ["MASKS", "Mask", "MaskCheck", "MaskPiece", "find_mask", "mask_check"]

_NS = 1e-9
_US = 1e-6


@dataclass(frozen=True)
class MaskPiece:
    """One piece of a mask: on ``low < tau <= high`` (s) the limit is ``sum_i c_i tau**p_i`` (s)."""

    low: float
    high: float
    coefficients: tuple[float, ...]
    powers: tuple[float, ...]

    def limit(self, taus: np.ndarray) -> np.ndarray:
        """The limit (s) at ``taus`` (s), whatever the interval."""
        taus = np.asarray(taus, dtype=np.float64)
        return sum(c * taus**p for c, p in zip(self.coefficients, self.powers))


@dataclass(frozen=True)
class Mask:
    """A limit of MTIE or TDEV over observation intervals: pieces in increasing tau.

    Attributes
    ----------
    name : str
        How :data:`MASKS` and :func:`mask_check` know it, e.g. ``"G.8262 EEC option 1 MTIE"``.
    statistic : {"mtie", "tdev"}
        The statistic the limit applies to.
    pieces : tuple of MaskPiece
        Contiguous pieces from the smallest tau covered to the largest (inf: no end).
    source : str
        The Recommendation and table the values were transcribed from.
    """

    name: str
    statistic: str
    pieces: tuple[MaskPiece, ...]
    source: str

    @property
    def taus(self) -> tuple[float, float]:
        """The observation intervals covered (s): (smallest, largest), open below."""
        return self.pieces[0].low, self.pieces[-1].high

    def limit(self, taus: Any) -> np.ndarray:
        """The limit (s) at each tau (s); NaN outside the intervals the mask covers.

        >>> MASKS["G.811 PRC MTIE"].limit([1.0, 1000.0, 1e4]) / 1e-6   # microseconds
        array([0.025275, 0.3     , 0.39    ])
        """
        taus = np.atleast_1d(np.asarray(taus, dtype=np.float64))
        out = np.full(taus.shape, np.nan)
        for piece in self.pieces:
            inside = (taus > piece.low) & (taus <= piece.high)
            out[inside] = piece.limit(taus[inside])
        return out

    def breakpoints(self) -> np.ndarray:
        """The taus (s) where one piece ends and the next begins, with both ends of the range."""
        return np.array([self.pieces[0].low, *(piece.high for piece in self.pieces)])


def _mask(name: str, statistic: str, source: str, unit: float, *pieces: tuple) -> Mask:
    """A :class:`Mask` from ``(low, high, {power: coefficient})`` pieces in ``unit`` (ns or us)."""
    made = tuple(MaskPiece(float(low), float(high), tuple(unit * c for c in terms.values()),
                           tuple(float(p) for p in terms)) for low, high, terms in pieces)
    return Mask(name, statistic, made, source)


_G811_TDEV = ((0.1, 100, {0: 3.0}), (100, 1000, {1: 0.03}), (1000, 1e4, {0: 30.0}))
_EEC1_MTIE = ((0.1, 1, {0: 40.0}), (1, 100, {0.1: 40.0}), (100, 1000, {0.2: 25.25}))
_EEC1_TDEV = ((0.1, 25, {0: 3.2}), (25, 100, {0.5: 0.64}), (100, 1000, {0: 6.4}))
_EEC2_MTIE = ((0.1, 1, {0: 20.0}), (1, 10, {0.48: 20.0}), (10, 1000, {0: 60.0}))
_EEC2_TDEV = ((0.1, 2.5, {-0.5: 3.2}), (2.5, 40, {0: 2.0}), (40, 1000, {0.5: 0.32}), (1000, 1e4, {0: 10.0}))

_G8261 = "ITU-T G.8261/Y.1361 (08/2013), clause 9.2.1.1, "
_VIA_TIMETOOLS = " (network limit; as transcribed in timetools 0.6.0; the same values as the G.823 SEC limit)"
_VIA_SEMTECH = (" (network limit at the interface; from the values Semtech's ToPTrace utility tabulates for it, "
                "Masks.cpp 2015, at every sampled tau from 1 s; the Recommendation's own table was not found)")
_NETWORK_MTIE_TAIL = (2000, np.inf, {0.2: 433.0, 1: 0.01})        # ns, the same for PDH, SSU and SEC
_NETWORK_TDEV_TAIL = (100, 1e6, {0: 58.0, 0.5: 1.2, 1: 3e-4})     # ns

_ALL = (
    _mask("G.811 PRC MTIE", "mtie", "ITU-T G.811 (1997), Table 1", _US,
          (0.1, 1000, {1: 0.275e-3, 0: 0.025}), (1000, np.inf, {1: 1e-5, 0: 0.29})),
    _mask("G.811 PRC TDEV", "tdev", "ITU-T G.811 (1997), Table 2", _NS, *_G811_TDEV),
    _mask("G.8272 PRTC-A MTIE", "mtie", "ITU-T G.8272 (2018), Table 1", _US,
          (0.1, 273, {1: 0.275e-3, 0: 0.025}), (273, np.inf, {0: 0.1})),
    _mask("G.8272 PRTC-A TDEV", "tdev", "ITU-T G.8272 (2018), Table 2", _NS, *_G811_TDEV),
    _mask("G.8272 PRTC-B MTIE", "mtie", "ITU-T G.8272 (2018), Table 3", _US,
          (0.1, 54.5, {1: 0.275e-3, 0: 0.025}), (54.5, np.inf, {0: 0.04})),
    _mask("G.8272 PRTC-B TDEV", "tdev", "ITU-T G.8272 (2018), Table 4", _NS,
          (0.1, 100, {0: 1.0}), (100, 500, {1: 0.01}), (500, 1e5, {0: 5.0})),
    _mask("G.8262 EEC option 1 MTIE", "mtie", "ITU-T G.8262 (07/2010), Table 1", _NS, *_EEC1_MTIE),
    _mask("G.8262 EEC option 1 TDEV", "tdev", "ITU-T G.8262 (07/2010), Table 3", _NS, *_EEC1_TDEV),
    _mask("G.8262 EEC option 2 MTIE", "mtie", "ITU-T G.8262 (07/2010), Table 4", _NS, *_EEC2_MTIE),
    _mask("G.8262 EEC option 2 TDEV", "tdev", "ITU-T G.8262 (07/2010), Table 5", _NS, *_EEC2_TDEV),
    _mask("G.813 SEC option 1 MTIE", "mtie", "ITU-T G.813 (2003), option 1 (as G.8262 Table 1)", _NS, *_EEC1_MTIE),
    _mask("G.813 SEC option 1 TDEV", "tdev", "ITU-T G.813 (2003), option 1 (as G.8262 Table 3)", _NS, *_EEC1_TDEV),
    _mask("G.813 SEC option 2 MTIE", "mtie", "ITU-T G.813 (2003), option 2 (as G.8262 Table 4)", _NS, *_EEC2_MTIE),
    _mask("G.813 SEC option 2 TDEV", "tdev", "ITU-T G.813 (2003), option 2 (as G.8262 Table 5)", _NS, *_EEC2_TDEV),
    _mask("G.8261 SyncE option 1 network MTIE", "mtie", _G8261 + "Table 4" + _VIA_TIMETOOLS, _NS,
          (0.1, 2.5, {0: 250.0}), (2.5, 20, {1: 100.0}), (20, 2000, {0: 2000.0}), _NETWORK_MTIE_TAIL),
    _mask("G.8261 SyncE option 1 network TDEV", "tdev", _G8261 + "Table 5" + _VIA_TIMETOOLS, _NS,
          (0.1, 17.14, {0: 12.0}), (17.14, 100, {1: 0.7}), _NETWORK_TDEV_TAIL),
    _mask("G.823 PRC network MTIE", "mtie", "ITU-T G.823 (03/2000), clause 6.2.1" + _VIA_SEMTECH, _US,
          (1, 1000, {1: 0.275e-3, 0: 0.025}), (1000, np.inf, {1: 1e-5, 0: 0.29})),
    _mask("G.823 PRC network TDEV", "tdev", "ITU-T G.823 (03/2000), clause 6.2.1" + _VIA_SEMTECH, _NS,
          (1, 100, {0: 3.0}), (100, 1000, {1: 0.03}), (1000, 1e4, {0: 30.0}), (1e4, 1e6, {0: 27.0, 1: 3e-4})),
    _mask("G.823 SSU network MTIE", "mtie", "ITU-T G.823 (03/2000), clause 6.2.2" + _VIA_SEMTECH, _NS,
          (1, 2.5, {0: 25.0}), (2.5, 200, {1: 10.0}), (200, 2000, {0: 2000.0}), _NETWORK_MTIE_TAIL),
    _mask("G.823 SSU network TDEV", "tdev", "ITU-T G.823 (03/2000), clause 6.2.2" + _VIA_SEMTECH, _NS,
          (1, 4.3, {0: 3.0}), (4.3, 100, {1: 0.7}), _NETWORK_TDEV_TAIL),
    _mask("G.823 SEC network MTIE", "mtie", "ITU-T G.823 (03/2000), clause 6.2.3" + _VIA_SEMTECH
          + "; the same pieces as G.8261 Table 4", _NS,
          (1, 2.5, {0: 250.0}), (2.5, 20, {1: 100.0}), (20, 2000, {0: 2000.0}), _NETWORK_MTIE_TAIL),
    _mask("G.823 SEC network TDEV", "tdev", "ITU-T G.823 (03/2000), clause 6.2.3" + _VIA_SEMTECH
          + "; the same pieces as G.8261 Table 5", _NS,
          (1, 17.14, {0: 12.0}), (17.14, 100, {1: 0.7}), _NETWORK_TDEV_TAIL),
    _mask("G.823 PDH network MTIE", "mtie", "ITU-T G.823 (03/2000), clause 6.2.4" + _VIA_SEMTECH, _NS,
          (1, 7.3, {0: 732.0}), (7.3, 20, {1: 100.0}), (20, 2000, {0: 2000.0}), _NETWORK_MTIE_TAIL),
    _mask("G.823 PDH network TDEV", "tdev", "ITU-T G.823 (03/2000), clause 6.2.4" + _VIA_SEMTECH, _NS,
          (1, 48, {0: 34.0}), (48, 100, {1: 0.7}), _NETWORK_TDEV_TAIL),
    _mask("G.824 DS1 network MTIE", "mtie", "ITU-T G.824 (03/2000), DS1 (1544 kbit/s) synchronization interface"
          + _VIA_SEMTECH, _NS, (1, 280, {0: 300.0, 1: 2.5}), (280, np.inf, {0: 997.0, 1: 0.01})),
    _mask("G.824 DS1 network TDEV", "tdev", "ITU-T G.824 (03/2000), DS1 (1544 kbit/s) synchronization interface"
          + _VIA_SEMTECH, _NS, (1, 10, {0: 100.0}), (10, 1000, {0.5: 31.623})),
)

#: Every mask by name: clocks' wander generation at constant temperature, and network limits at interfaces.
MASKS = MappingProxyType({mask.name: mask for mask in _ALL})


def find_mask(mask: Any, statistic: str) -> Mask:
    """The :class:`Mask` ``mask`` names for ``statistic`` (``"mtie"`` or ``"tdev"``).

    ``mask`` is a :class:`Mask`, a name of :data:`MASKS`, or a clock's name without the
    statistic (``"G.8262 EEC option 1"``): the mask of that clock for ``statistic``.

    >>> find_mask("G.8262 EEC option 1", "tdev").name
    'G.8262 EEC option 1 TDEV'
    """
    if isinstance(mask, str):
        name = mask if mask in MASKS else f"{mask} {str(statistic).upper()}"
        if name not in MASKS:
            clocks = sorted({known.rsplit(" ", 1)[0] for known in MASKS})
            raise ValueError(f"mask: unknown mask {short_repr(mask)} for {str(statistic).upper()}; known clocks: "
                             f"{', '.join(clocks)} (or a full name of avar.MASKS)")
        mask = MASKS[name]
    if not isinstance(mask, Mask):
        raise TypeError(f"mask must be a name of avar.MASKS or a Mask, got {type(mask).__name__}")
    if mask.statistic != statistic:
        raise ValueError(f"mask {mask.name!r} limits {mask.statistic.upper()}, not {str(statistic).upper()}")
    return mask


@dataclass(frozen=True, eq=False)
class MaskCheck:
    """A measured MTIE or TDEV against a mask, tau by tau.

    Attributes
    ----------
    mask : Mask
    taus : ndarray
        The result's taus that the mask covers (s).
    measured : ndarray
        The result's MTIE or TDEV there (s).
    limit : ndarray
        The mask's limit there (s).
    margin : ndarray
        limit / measured: above 1 passes (inf where the measured value is 0).
    passes : ndarray of bool
        measured <= limit, per tau.
    """

    mask: Mask
    taus: np.ndarray
    measured: np.ndarray
    limit: np.ndarray
    margin: np.ndarray
    passes: np.ndarray

    def __post_init__(self) -> None:
        for name in ("taus", "measured", "limit", "margin"):
            object.__setattr__(self, name, frozen_array(getattr(self, name)))
        passes = np.array(self.passes, dtype=bool)
        passes.flags.writeable = False
        object.__setattr__(self, "passes", passes)

    @property
    def passed(self) -> bool:
        """Whether every tau the mask covers passes."""
        return bool(self.passes.all())

    def summary(self):
        """A table: Tau (s), Measured (s), Limit (s), Margin, Pass."""
        import pandas as pd

        return pd.DataFrame({"Tau (s)": self.taus, "Measured (s)": self.measured, "Limit (s)": self.limit,
                             "Margin": self.margin, "Pass": self.passes})

    def plot(self, **kwargs: Any):
        """The measured curve under the mask; see :func:`avar.plotting.plot_mask_check`."""
        from avar.plotting import plot_mask_check

        return plot_mask_check(self, **kwargs)

    def __repr__(self) -> str:
        verdict = "passes" if self.passed else f"fails at {int((~self.passes).sum())} of {self.taus.size} taus"
        worst = float(np.min(self.margin)) if self.margin.size else float("nan")
        return f"<MaskCheck {self.mask.name}: {verdict}, least margin {worst:.3g}>"


def mask_check(result: Any, mask: str | Mask) -> MaskCheck:
    """Check an MTIE or TDEV result against an ITU-T mask, tau by tau.

    Parameters
    ----------
    result : Deviation
        From :func:`avar.mtie` or :func:`avar.tdev` of the clock's time error (phase data, s).
    mask : str or Mask
        A name of :data:`MASKS` (e.g. ``"G.8262 EEC option 1 MTIE"``) or a :class:`Mask`.
        Its statistic must be the result's.

    Returns
    -------
    MaskCheck
        At the result's taus inside the mask's range: the limit, the margin limit / measured
        and pass/fail; ``.passed`` for the verdict. Taus outside the range are left out (a
        result with none inside is an error).

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> x = np.random.default_rng(1).standard_normal(10_000) * 1e-9   # 1 ns white PM
    >>> check = avar.mask_check(avar.tdev(x, data_type="phase"), "G.8262 EEC option 1 TDEV")
    >>> check.passed, check.mask.source
    (True, 'ITU-T G.8262 (07/2010), Table 3')
    """
    if isinstance(mask, str):
        if mask not in MASKS:
            raise ValueError(f"unknown mask {short_repr(mask)}; known: {', '.join(MASKS)}")
        mask = MASKS[mask]
    if not isinstance(mask, Mask):
        raise TypeError(f"mask must be a name of avar.MASKS or a Mask, got {type(mask).__name__}")
    statistic = getattr(result, "estimator", None)
    if statistic is None or not hasattr(result, "taus") or not hasattr(result, "deviation"):
        raise TypeError(f"result must be an MTIE or TDEV Deviation (avar.mtie, avar.tdev), got {type(result).__name__}")
    if statistic != mask.statistic:
        raise ValueError(f"mask {mask.name!r} limits {mask.statistic.upper()}, but result is {str(statistic).upper()}; "
                         f"compute avar.{mask.statistic}(phase, data_type='phase')")
    taus = np.asarray(result.taus, dtype=np.float64)
    limit = mask.limit(taus)
    inside = np.isfinite(limit)
    if not inside.any():
        low, high = mask.taus
        raise ValueError(f"no tau of the result ({taus.min():g} .. {taus.max():g} s) lies in the range of "
                         f"{mask.name!r} ({low:g} .. {high:g} s)")
    measured = np.asarray(result.deviation, dtype=np.float64)[inside]
    limit = limit[inside]
    with np.errstate(divide="ignore"):
        margin = np.where(measured > 0, limit / np.where(measured > 0, measured, 1.0), np.inf)
    return MaskCheck(mask, taus[inside], measured, limit, margin, measured <= limit)
