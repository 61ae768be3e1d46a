"""The Recording container: read-only named columns, the rate and its note."""

from __future__ import annotations

import numpy as np
import pytest

from avar.recording import Recording


def test_columns_are_read_only_copies():
    source = np.arange(10.0)
    rec = Recording({"gx": source, "n": np.arange(10)}, rate=50.0, rate_source="given")
    source[0] = 99.0
    assert rec["gx"][0] == 0.0  # a copy: the caller's array stays the caller's
    with pytest.raises(ValueError):
        rec["gx"][1] = 5.0
    assert rec["n"].dtype == np.int64 and rec.names == ("gx", "n") and len(rec) == 10
    with pytest.raises(TypeError):
        rec.columns["x"] = np.zeros(10)
    frame = rec.to_dataframe()
    assert frame.index[1] == pytest.approx(0.02) and list(frame.columns) == ["gx", "n"]


def test_notes_say_where_the_rate_came_from():
    timed = Recording({"x": np.zeros(8)}, rate=300.0, rate_source="time column 'time'", time_column="time",
                      jitter=3.3e-4, gap_rows=[5], gap_steps=[0.25], gaps_ignored=True, source="log.csv")
    assert timed.rate_note() == (
        "at 300 Hz from time column 'time' (jitter 0.33 ms rms); 1 gap(s) ignored: samples treated as "
        "contiguous, the first before row 6 (0.25 s long)"
    )
    assert str(timed).startswith("log.csv: 1 column(s) x 8 samples at 300 Hz")


@pytest.mark.parametrize(
    "columns, message",
    [({}, "at least one column"), ({"a": np.zeros(4), "b": np.zeros(5)}, "same length"),
     ({"a": np.zeros((4, 2))}, "1-D")],
)
def test_bad_columns(columns, message):
    with pytest.raises(ValueError, match=message):
        Recording(columns, rate=1.0, rate_source="given")
    with pytest.raises(TypeError, match="numeric"):
        Recording({"a": np.array(["x"] * 4)}, rate=1.0, rate_source="given")
