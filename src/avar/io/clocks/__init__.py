"""Clock logs: time error (phase) or fractional frequency with its time stamps, from the logs people have.

:func:`~avar.io.clocks.detect.read_clock_log` finds the format from the first lines (or takes
``kind=``) and returns a :class:`~avar.io.clocks.result.ClockLog`. A module per format family:

* :mod:`~avar.io.clocks.chrony`: chrony's ``tracking.log``, ``statistics.log``, ``measurements.log``;
* :mod:`~avar.io.clocks.ntpd`: ntpd's ``loopstats`` and ``peerstats``;
* :mod:`~avar.io.clocks.linuxptp`: ``ptp4l``, ``phc2sys`` and ``ts2phc`` output (stdout, syslog);
* :mod:`~avar.io.clocks.rinex`: RINEX clock files (``.clk``, versions 2.00 to 3.04);
* :mod:`~avar.io.clocks.stable32`: Stable32 data files (one or two columns);

and what they share: :mod:`~avar.io.clocks.table` (the text, whitespace fields, numbers, the
choice of a source), :mod:`~avar.io.clocks.build` (the column, its units, the stamps) and
:mod:`~avar.io.clocks.result` (``ClockLog``, ``Gaps``, ``ClockLogError``, the rate and the gaps).
"""
