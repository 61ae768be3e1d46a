"""The registry of the deviation statistics: one record per statistic.

Every statistic of the family is one :class:`Statistic` in :data:`STATISTICS`: its
name (the public function ``avar.NAME`` and ``avar deviation --stat NAME``), long name,
family folder, whether it carries chi-squared bounds, and for the classic statistics the
kernel code and the fewest phase points with one term. The tables the rest of the
package reads (:data:`DEVIATION_STATISTICS`, :data:`CLASSIC`, :data:`TOTAL`,
:data:`LONG_NAMES`, ...) are views of it, so a new statistic is one record here.

Public functions of :data:`DEVIATION_STATISTICS` share the signature ``(data,
rate=None, data_type="freq", taus="octave", confidence=ONE_SIGMA (0.6827),
nan_policy="raise", alpha=None, ...)`` and return a :class:`avar.Deviation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType


@dataclass(frozen=True)
class Statistic:
    """One statistic of the family.

    Attributes
    ----------
    name : str
        Its public function ``avar.<name>`` and ``--stat`` name.
    long_name : str
        For labels and summaries.
    family : {"classic", "total", "time_error", "pair"}
        Its folder in :mod:`avar.stability`; "pair" statistics take two series.
    bounded : bool
        Whether it carries chi-squared bounds (else ``edf``, ``lci``, ``uci`` are NaN).
    kernel_code : int or None
        Classic statistics: the variance core's code (:mod:`avar._kernels.classic.levels`).
    min_phase_points : int or None
        Classic statistics: the fewest phase points with one term at m = 1.
    """

    name: str
    long_name: str
    family: str
    bounded: bool = True
    kernel_code: int | None = None
    min_phase_points: int | None = None


_RECORDS = (
    Statistic("adev", "Allan deviation", "classic", kernel_code=0, min_phase_points=3),
    Statistic("oadev", "overlapping Allan deviation", "classic", kernel_code=0, min_phase_points=3),
    Statistic("mdev", "modified Allan deviation", "classic", kernel_code=2, min_phase_points=3),
    Statistic("tdev", "time deviation", "classic", kernel_code=2, min_phase_points=3),
    Statistic("hdev", "Hadamard deviation", "classic", kernel_code=1, min_phase_points=4),
    Statistic("ohdev", "overlapping Hadamard deviation", "classic", kernel_code=1, min_phase_points=4),
    Statistic("totdev", "total deviation", "classic", kernel_code=3, min_phase_points=3),
    Statistic("mhdev", "modified Hadamard deviation", "classic", kernel_code=4, min_phase_points=4),
    Statistic("htdev", "Hadamard time deviation", "classic", kernel_code=4, min_phase_points=4),
    Statistic("mtotdev", "modified total deviation", "total"),
    Statistic("ttotdev", "time total deviation", "total"),
    Statistic("htotdev", "Hadamard total deviation", "total"),
    Statistic("theo1", "Theo1 deviation", "total"),
    Statistic("theoh", "ThêoH deviation (OADEV and bias-removed Theo1)", "total"),
    Statistic("mhtotdev", "modified Hadamard total deviation", "total"),
    Statistic("pdev", "parabolic deviation", "time_error"),
    Statistic("mtie", "maximum time interval error", "time_error", bounded=False),
    Statistic("tierms", "time interval error rms", "time_error", bounded=False),
    Statistic("gcodev", "Groslambert codeviation", "pair", bounded=False),
)

#: Every statistic by name, in the order the command line lists them.
STATISTICS = MappingProxyType({record.name: record for record in _RECORDS})

#: Statistics of one series: public deviation functions of ``avar`` and ``--stat`` names.
DEVIATION_STATISTICS = tuple(name for name, s in STATISTICS.items() if s.family != "pair")
#: Statistics of two series that also give a :class:`avar.Deviation` (not on the command line).
PAIR_STATISTICS = tuple(name for name, s in STATISTICS.items() if s.family == "pair")
#: The classic seven of NIST SP 1065 and the modified Hadamard pair (MHDEV, HTDEV), with their own variance core.
CLASSIC = tuple(name for name, s in STATISTICS.items() if s.family == "classic")
#: The total and Theo statistics.
TOTAL = tuple(name for name, s in STATISTICS.items() if s.family == "total")
#: Statistics that carry no chi-squared bounds (their ``edf``, ``lci`` and ``uci`` are NaN).
UNBOUNDED = tuple(name for name, s in STATISTICS.items() if not s.bounded)
#: Long names, for labels and summaries.
LONG_NAMES = MappingProxyType({name: s.long_name for name, s in STATISTICS.items()})
#: Kernel code of every classic statistic (see :mod:`avar._kernels.classic.levels`).
KERNEL_CODES = MappingProxyType({name: STATISTICS[name].kernel_code for name in CLASSIC})
#: Smallest number of phase points of every classic statistic (one term at m = 1).
MIN_PHASE_POINTS = MappingProxyType({name: STATISTICS[name].min_phase_points for name in CLASSIC})


def is_statistic(name: object) -> bool:
    """Whether ``name`` is a registered deviation statistic of one series.

    >>> is_statistic("oadev"), is_statistic("mtie"), is_statistic("avar")
    (True, True, False)
    """
    return isinstance(name, str) and name in DEVIATION_STATISTICS
