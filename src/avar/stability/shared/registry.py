"""The registry of the public deviation statistics, by name.

Every name in :data:`DEVIATION_STATISTICS` is a public function of ``avar``
with the signature ``(data, rate=None, data_type="freq", taus="octave",
confidence=ONE_SIGMA (0.6827), nan_policy="raise", alpha=None, ...)`` returning a
:class:`avar.Deviation`; the command line (``avar deviation --stat NAME``)
looks them up here and calls ``getattr(avar, name)``. A new statistic is one
line in each table.
"""

from __future__ import annotations

#: Public deviation functions of ``avar``, in the order the command line lists them.
DEVIATION_STATISTICS = (
    "adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev",
    "mtotdev", "ttotdev", "htotdev", "theo1", "theoh",
    "pdev", "mtie", "tierms",
)

#: Statistics of two series that also give a :class:`avar.Deviation` (not on the command line).
PAIR_STATISTICS = ("gcodev",)

#: Long names of the statistics beyond the first seven, for labels and summaries.
EXTRA_LONG_NAMES = {
    "pdev": "parabolic deviation",
    "mtie": "maximum time interval error",
    "tierms": "time interval error rms",
    "gcodev": "Groslambert codeviation",
}

#: Statistics that carry no chi-squared bounds (their ``edf``, ``lci`` and ``uci`` are NaN).
UNBOUNDED = ("mtie", "tierms", "gcodev")


def is_statistic(name: object) -> bool:
    """Whether ``name`` is a registered deviation statistic.

    >>> is_statistic("oadev"), is_statistic("mtie"), is_statistic("avar")
    (True, True, False)
    """
    return isinstance(name, str) and name in DEVIATION_STATISTICS
