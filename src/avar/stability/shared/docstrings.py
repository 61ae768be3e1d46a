"""Docstring templates shared by the statistics of the family (NumPy style).

A statistic's docstring holds ``{parameters}``; :func:`fill_parameters` puts the family's
common parameters and return value there, with the statistic's own extra parameters.
"""

from __future__ import annotations

from collections.abc import Callable

PARAMETERS = """
    Parameters
    ----------
    data : array_like or pandas.Series
        1-D real data: fractional frequency y (``data_type="freq"``) or phase
        (time error) x in seconds (``data_type="phase"``). NaN marks a gap
        (see ``nan_policy``); infinite values are refused.
    rate : float, optional
        Sampling rate in Hz; tau0 = 1 / rate. Default: the rate of the
        regular time index of a pandas Series (DatetimeIndex, TimedeltaIndex,
        PeriodIndex or float seconds), else 1 Hz; an irregular index is
        refused (resample it, or pass ``rate``), as in :func:`avar.avar`.
    data_type : {"freq", "phase"}
        What ``data`` holds (default ``"freq"``; ``allantools`` defaults to ``"phase"``).
    taus : {"octave", "decade", "all"} or array_like of float
        Averaging times: m = 1, 2, 4, ...; 1, 2, 4 x 10**k; every m; or
        explicit taus in seconds (rounded to whole m; one outside the valid
        range raises ``ValueError`` naming it).
    confidence : float
        Two-sided confidence level of ``lci``/``uci`` in (0, 1); one sigma (0.6827,
        printed 0.683 as Stable32) by default.
    nan_policy : {"raise", "omit"}
        ``"raise"``: NaN raises ``ValueError`` naming its index; ``"omit"``:
        terms touching a NaN are skipped and ``n`` counts the terms used.

    Returns
    -------
    Deviation
        ``taus``, ``deviation``, ``variance``, ``n``, ``alpha``, ``edf``,
        ``lci``, ``uci``, ``summary()``, ``plot()``.
"""


def fill_parameters(function: Callable, extra: str = "") -> Callable:
    """Replace ``{parameters}`` in ``function.__doc__`` by :data:`PARAMETERS`, with ``extra``
    (parameter entries, indented as they are) before its Returns section."""
    head, returns = PARAMETERS.split("\n\n    Returns")
    function.__doc__ = function.__doc__.replace("{parameters}", head + "\n" + extra + "\n    Returns" + returns)
    return function
