"""Conditioning: outliers and jumps found, reported and corrected; gaps filled; averaging."""

import numpy as np
import pytest

import avar


def record(seed=1, n=10_000):
    """Random-walk phase (white FM), 1 ps steps at 1 Hz."""
    return np.cumsum(np.random.default_rng(seed).standard_normal(n)) * 1e-12


def test_a_phase_step_and_a_spike_are_reported_and_corrected():
    """The issue's case: a 1 ns phase step and a 5 ns spike in 10,000 points raise ADEV(1 s) and
    flip the identified noise to white PM; reported with position and size, and once corrected
    ADEV(1 s) is the clean record's within 5 % and alpha is restored."""
    clean = record()
    x = clean.copy()
    x[4000:] += 1e-9
    x[7000] += 5e-9
    report = avar.check(x, data_type="phase")
    assert [(e.kind, e.index) for e in report.events] == [("phase jump", 4000), ("phase spike", 7000)]
    assert report.events[0].size == pytest.approx(1e-9, rel=0.01)
    assert report.events[1].size == pytest.approx(5e-9, rel=0.01)
    assert report.events[0].time == 4000.0
    before = avar.adev(x, data_type="phase", taus=[1.0]).deviation[0]
    after = avar.adev(report.corrected(), data_type="phase", taus=[1.0]).deviation[0]
    truth = avar.adev(clean, data_type="phase", taus=[1.0]).deviation[0]
    assert before > 9 * truth
    assert after == pytest.approx(truth, rel=0.05)
    assert avar.adev(x, data_type="phase").alpha[0] == 2
    assert avar.adev(report.corrected(), data_type="phase").alpha[0] == avar.adev(clean, data_type="phase").alpha[0]
    text = str(report)
    assert "phase jump at index 4000" in text and "phase spike at index 7000" in text
    assert list(report.summary()["Index"]) == [4000, 7000]
    np.testing.assert_array_equal(x, report.data)  # the data as given are kept, not changed


def test_frequency_spikes_and_a_frequency_jump():
    rng = np.random.default_rng(2)
    clean = rng.standard_normal(10_000) * 1e-11
    y = clean.copy()
    y[1234] += 3e-10
    y[6000:] += 1e-11
    report = avar.check(y)
    kinds = [(e.kind, e.index) for e in report.events]
    assert ("frequency spike", 1234) in kinds
    jumps = report.kinds("frequency jump")
    assert len(jumps) == 1 and abs(jumps[0].index - 6000) <= 20 and jumps[0].size == pytest.approx(1e-11, rel=0.2)
    fixed = report.corrected()
    assert fixed[1234] == pytest.approx(np.median(y))
    assert np.isnan(avar.check(y, outliers="nan").corrected()[1234])
    # the jump removed: the later mean is the clean mean within the step's standard error
    assert np.mean(fixed[6100:]) == pytest.approx(np.mean(clean[6100:]), abs=2e-12)


def test_a_frequency_jump_in_phase_data_is_a_ramp_removed():
    rng = np.random.default_rng(3)
    y = rng.standard_normal(10_000) * 1e-11
    y[6000:] += 1e-11
    x = np.concatenate(([0.0], np.cumsum(y)))
    jumps = avar.check(x, data_type="phase").kinds("frequency jump")
    assert len(jumps) == 1 and abs(jumps[0].index - 6001) <= 20
    slope = np.diff(avar.check(x, data_type="phase").corrected())
    assert np.mean(slope[6100:]) - np.mean(slope[:5900]) == pytest.approx(0.0, abs=2e-12)


@pytest.mark.parametrize("seed", range(10))
def test_clean_records_have_no_events(seed):
    rng = np.random.default_rng(100 + seed)
    assert avar.check(rng.standard_normal(5000)).events == ()
    assert avar.check(np.cumsum(rng.standard_normal(5000)) * 1e-12, data_type="phase").events == ()
    assert avar.check(rng.standard_normal(5000) * 1e-9, data_type="phase").events == ()  # white PM


def test_fill_gaps_and_average_against_plain_loops():
    y = np.array([np.nan, 1.0, 2.0, np.nan, np.nan, 8.0, 9.0, np.nan])
    res = avar.fill_gaps(y)
    assert res.data.tolist() == [1.0, 2.0, 4.0, 6.0, 8.0, 9.0]
    assert res.changed.tolist() == [3, 4] and res.dropped == 2 and "2 gap value(s) filled" in res.note
    kept = avar.fill_gaps(y, method="none")
    assert np.isnan(kept.data).sum() == 4 and kept.changed.tolist() == [0, 3, 4, 7]
    z = np.random.default_rng(4).standard_normal(1003)
    res = avar.average(z, 10)
    assert res.dropped == 3
    np.testing.assert_allclose(res.data, [sum(z[10 * k:10 * k + 10]) / 10 for k in range(100)], rtol=1e-13)
    # averaging frequency data by m equals taking every m-th phase point of its integral
    x = np.concatenate(([0.0], np.cumsum(z[:1000])))
    np.testing.assert_allclose(np.diff(avar.average(x, 10, data_type="phase").data) / 10,
                               avar.average(z[:1000], 10).data, rtol=1e-10)


def test_errors_name_the_argument():
    with pytest.raises(ValueError, match="factor"):
        avar.check(np.zeros(100), factor=0)
    with pytest.raises(ValueError, match="window"):
        avar.check(np.random.default_rng(0).standard_normal(100), window=2)
    with pytest.raises(ValueError, match="data_type"):
        avar.check(np.zeros(100), data_type="time")
    with pytest.raises(ValueError, match="no samples"):
        avar.fill_gaps(np.full(5, np.nan))
    with pytest.raises(ValueError, match="factor"):
        avar.average(np.zeros(10), 0)
