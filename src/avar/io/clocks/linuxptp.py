"""linuxptp's ``ptp4l``, ``phc2sys`` and ``ts2phc`` output: standard output, syslog or the journal.

The servo prints one line per clock update (ptp4l(8), phc2sys(8); linuxptp's ``clock.c`` and
``phc2sys.c``)::

    ptp4l[5374018.735]: master offset        -23 s2 freq   +1234 path delay       567
    phc2sys[5374019.001]: CLOCK_REALTIME phc offset       -12 s2 freq   -3456 delay    789

The bracketed number is the monotonic time (s, to the ms) of the line, and the time stamp of
the sample; through syslog it follows the colon (``ptp4l: [5374018.735] master offset ...``,
``ptp4l[812]: [5374018.735] ...`` with the process id first), and a ``message_tag`` may follow
it. The offset (ns) is the default column (phase, s), ``freq`` the servo's frequency
adjustment (ppb; fractional frequency x 1e-9 with ``column="freq"``), ``delay`` the path delay
(ptp4l) or the clock reading delay (phc2sys, ns) and ``servo state`` the number after ``s``:
0 unlocked, 1 clock step, 2 locked, 3 locked and stable (linuxptp 3 and later).

A log is free text: every line of another kind (port state changes, ``rms`` summaries, other
programs' syslog lines) is counted and skipped, an offset line that does not parse too. Only
the samples of a locked servo are taken (``states=("s2", "s3")``; ``states="all"`` takes every
one) and those dropped are counted by state. When the log holds several servos (ptp4l and
phc2sys, or phc2sys ``-a`` updating several clocks) one is taken (``source=``, by default the
most frequent) and the others are listed.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import pandas as pd

from avar.io.clocks.build import Field, Parsed, numeric_frame
from avar.io.clocks.table import Text, fail, pick_source

#: One servo update; the monotonic stamp is in ``[...]`` after the program name or after the colon.
OFFSET_LINE = re.compile(
    r"(ptp4l|phc2sys|ts2phc)(?:\[(\d+)(?:\.(\d+))?\])?:[ \t]+(?:\[(\d+)\.(\d+)\][ \t]+)?(?:\[[^\]\n]*\][ \t]+)?"
    r"(?:(\S+)[ \t]+)??(?:(master|phc|sys)[ \t]+)?offset[ \t]+([-+]?\d+)[ \t]+s(\d)[ \t]+freq[ \t]+([-+]?\d+)"
    r"(?:[ \t]+(?:path[ \t]+)?delay[ \t]+([-+]?\d+))?[ \t\r]*$", re.M)
#: Any offset line of the three programs, parsed or not (to count those that do not parse).
ANY_OFFSET_LINE = re.compile(r"\b(?:ptp4l|phc2sys|ts2phc)(?:\[[\d.]+\])?:[^\n]*\boffset\b[^\n]*")
#: Any line of the three programs.
PROGRAM = r"\b(?:ptp4l|phc2sys|ts2phc)(?:\[[\d.]+\])?:"
FIELDS = {
    "offset": Field("ns", "the offset of the clock from its source clock"),
    "freq": Field("ppb", "the servo's frequency adjustment"),
    "delay": Field("ns", "the delay of reading the source clock"),
    "servo state": Field("state", "the servo state (0 unlocked, 1 clock step, 2 locked, 3 locked stable)"),
}
#: ptp4l's words for its offset and delay.
PTP4L_FIELDS = {**FIELDS, "offset": Field("ns", "the master offset (the clock's offset from its master)"),
                "delay": Field("ns", "the path delay to the master")}
STATE_NAMES = {0: "unlocked", 1: "clock step", 2: "locked", 3: "locked stable"}
LOCKED = (2, 3)


def servo_states(states: Any) -> tuple[int, ...] | None:
    """The servo states to keep: None for all; ``"s2"``, ``2``, ``("s2", "s3")``, ``"s1,s2"``...

    >>> servo_states(None), servo_states("all"), servo_states("s2"), servo_states(["s1", 2])
    ((2, 3), None, (2,), (1, 2))
    """
    if states is None:
        return LOCKED
    if isinstance(states, str):
        if states.strip().lower() == "all":
            return None
        states = states.replace(",", " ").split()
    elif isinstance(states, (int, np.integer)):
        states = [states]
    kept = []
    for state in states:
        text = str(state).strip().lower().removeprefix("s")
        if not text.isdigit():
            raise ValueError(f"states: {state!r} is not a servo state (s0, s1, s2, s3, or 'all')")
        kept.append(int(text))
    return tuple(sorted(set(kept)))


def read_linuxptp(text: Text, source: Any = None, states: Any = None) -> Parsed:
    """The offsets of one ptp4l/phc2sys/ts2phc servo, from its log lines; other lines are counted.

    Examples
    --------
    >>> import os, tempfile
    >>> from avar.io.clocks.table import load_text
    >>> path = os.path.join(tempfile.mkdtemp(), "ptp4l.log")
    >>> with open(path, "w") as f:
    ...     _ = f.write("ptp4l[359.224]: master offset       3304 s0 freq      +0 path delay      9202\\n"
    ...                 "ptp4l[361.224]: master offset      -3145 s2 freq  -32637 path delay      9202\\n"
    ...                 "ptp4l[361.224]: port 1: UNCALIBRATED to SLAVE on MASTER_CLOCK_SELECTED\\n"
    ...                 "ptp4l[362.223]: master offset       -145 s2 freq  -30580 path delay      9202\\n")
    >>> parsed = read_linuxptp(load_text(path))
    >>> parsed.frame["offset"].tolist(), parsed.seconds.tolist(), dict(parsed.skipped)
    ([-3145.0, -145.0], [0.0, 0.999], {'lines of other kinds': 1, 'servo state s0 (unlocked)': 1})
    """
    keep = servo_states(states)
    joined = "\n".join(text.lines)
    found = [(m.start(), " ".join(filter(None, (m[1], m[6], m[7]))), m[4] or (m[2] if m[3] else None), m[5] or m[3],
              m[8], m[9], m[10], m[11]) for m in OFFSET_LINE.finditer(joined)]
    columns = [np.array(column, dtype=object) for column in zip(*found)] if found else [np.zeros(0, object)] * 8
    at, keys, whole, fraction, offset, state, freq, delay = columns
    starts = np.cumsum([0, *(len(line) + 1 for line in text.lines)])
    rows = np.searchsorted(starts, at.astype(np.int64), side="right") - 1
    candidates = np.array([i for i, line in enumerate(text.lines) if "offset" in line], dtype=np.int64)
    hit = np.searchsorted(rows, candidates).clip(max=max(rows.size - 1, 0))  # rows: sorted, among the candidates
    unmatched = candidates[rows[hit] != candidates] if rows.size else candidates
    malformed = sum(1 for i in unmatched.tolist() if ANY_OFFSET_LINE.search(text.lines[i]))
    blank = sum(1 for line in text.lines if not line.strip())
    skipped: dict[str, int] = {}
    if other := len(text.lines) - len(found) - malformed - blank:
        skipped["lines of other kinds"] = other
    if malformed:
        skipped["offset lines that do not parse"] = malformed
    if blank:
        skipped["blank lines"] = blank
    timed = np.not_equal(whole, None)
    if (~timed).any():
        skipped["offset lines without a monotonic time stamp"] = int((~timed).sum())
    rows, keys, whole, fraction, offset, state, freq, delay = (
        column[timed] for column in (rows, keys, whole, fraction, offset, state, freq, delay))
    if not rows.size:
        raise fail(text.path, None, f"holds no ptp4l, phc2sys or ts2phc offset lines ({len(text.lines)} lines: "
                                    f"{', '.join(f'{n} {why}' for why, n in skipped.items())})")
    mask, selected, available = pick_source(keys, source, "servo", text.path)
    state = state.astype(np.int64)
    if keep is not None:
        for value in sorted(set(state[mask]) - set(keep)):
            skipped[f"servo state s{value} ({STATE_NAMES.get(int(value), 'unknown')})"] = int(
                np.sum(mask & (state == value)))
        mask &= np.isin(state, keep)
    if not mask.any():
        raise fail(text.path, None, f"holds no offset line of {selected.split(' (')[0]} in servo state "
                                    f"{', '.join(f's{k}' for k in keep)} (pass states='all' to take every state); "
                                    f"skipped: {', '.join(f'{n} {why}' for why, n in skipped.items())}")
    columns = {"offset": offset[mask].astype(np.float64), "freq": freq[mask].astype(np.float64),
               "delay": pd.to_numeric(pd.Series(delay[mask], dtype=object)), "servo state": state[mask]}
    program = str(keys[mask][0]).split()[0]
    return Parsed(f"linuxptp {program}", numeric_frame(columns), PTP4L_FIELDS if program == "ptp4l" else FIELDS,
                  "offset", _seconds(whole[mask], fraction[mask]), rows[mask] + 1, selected=selected,
                  available=available, skipped=skipped)


def _seconds(whole: np.ndarray, fraction: np.ndarray) -> np.ndarray:
    """Monotonic stamps (``"5374018"``, ``"735"``) as s from the first, differenced exactly in integer ns."""
    digits = pd.Series(fraction, dtype=object).str.len().to_numpy(dtype=np.int64)
    ns = whole.astype(np.int64) * 1_000_000_000 + fraction.astype(np.int64) * 10 ** (9 - np.minimum(digits, 9))
    return (ns - ns[0]) / 1e9
