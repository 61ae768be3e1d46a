"""avar.Stream: chunks of random sizes give the batch functions' numbers; exact arithmetic; memory bounds."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import avar
from avar.stability.uncertainty.edf import estimator_edf

STATISTICS = ["oadev", "adev", "mdev", "tdev", "hdev", "ohdev"]


def _feed(stream, data, rng, pieces=40):
    for chunk in np.split(data, np.sort(rng.integers(0, data.size, pieces))):
        stream.update(chunk)
    return stream.result()


@pytest.mark.parametrize("statistic", STATISTICS)
def test_stream_equals_batch_on_random_chunks(statistic):
    rng = np.random.default_rng(len(statistic))
    n = 200_000
    cases = [("freq", 1e-3 + 1e-9 * rng.standard_normal(n)),  # an offset 10**6 times the noise
             ("freq", np.cumsum(rng.standard_normal(n))),  # random-walk FM
             ("phase", 5.0 + 1e-3 * np.arange(n) + rng.standard_normal(n))]  # white PM on a frequency offset
    taus = [1.0, 3.0, 16.0, 100.0, 1000.0]
    for data_type, data in cases:
        result = _feed(avar.Stream(statistic, taus=taus, data_type=data_type), data, rng)
        batch = getattr(avar, statistic)(data, taus=taus, data_type=data_type)
        # the batch MDEV of random-walk FM is 1.1e-12 off at m = 1 (the stream equals math.fsum there)
        rtol = 2e-12 if statistic in ("mdev", "tdev") else 1e-12
        np.testing.assert_allclose(result.deviation, batch.deviation, rtol=rtol, atol=0)
        assert result.n.tolist() == batch.n.tolist()


def test_stream_is_exact_where_rounding_is_hard():
    # random-walk FM phase (|x| ~ 1e7, terms ~ 1): exact rational arithmetic is the reference
    rng = np.random.default_rng(3)
    x = np.cumsum(np.cumsum(rng.standard_normal(12_000)))
    stream = _feed(avar.Stream("mdev", taus=[1.0, 3.0], data_type="phase"), x, rng)
    xs = [Fraction(float(v)) for v in x]
    for m, got in zip((1, 3), stream.deviation):
        d = [xs[i + 2 * m] - 2 * xs[i + m] + xs[i] for i in range(len(xs) - 2 * m)]
        window = sum(d[:m])
        total = window * window
        for j in range(1, len(d) - m + 1):
            window += d[j + m - 1] - d[j - 1]
            total += window * window
        exact = math.sqrt(float(total / (2 * m**4 * (len(d) - m + 1))))
        assert got == pytest.approx(exact, rel=1e-13)


def test_stream_reports_partial_results_and_memory_is_bounded():
    stream = avar.Stream("ohdev", taus=[1.0, 10.0], rate=2.0, data_type="phase", alpha=-1)
    with pytest.raises(ValueError, match="no level has a term yet"):
        stream.result()
    stream.update(np.arange(8.0) ** 2)  # 8 points: one level (m = 2) with 8 - 3 m = 2 terms
    res = stream.result()
    assert res.averaging_factors.tolist() == [2] and res.n.tolist() == [2] and res.alpha.tolist() == [-1]
    assert res.deviation[0] == 0.0  # a parabola has no third difference
    stream.update(np.zeros(0))
    assert stream.n_samples == 8 and stream.n_phase == 8
    assert stream._ring_hi.size == 3 * 20 + 1  # the last 3 max(m) + 1 points, whatever the length
    assert stream.expected_terms().tolist() == [8 - 3 * 2, 8 - 3 * 20]


def test_stream_bounds_use_the_given_alpha():
    y = np.random.default_rng(1).standard_normal(5000)
    res = avar.Stream("oadev", taus=[1.0, 10.0]).update(y).result()
    batch = avar.oadev(y, taus=[1.0, 10.0])
    np.testing.assert_allclose(res.edf, estimator_edf("oadev", [0, 0], [1, 10], 5001))
    assert np.all(res.lci < res.deviation) and np.all(res.deviation < res.uci)
    np.testing.assert_allclose(res.deviation, batch.deviation, rtol=1e-12)


def test_stream_validation():
    with pytest.raises(ValueError, match="statistic must be one of"):
        avar.Stream("totdev", taus=[1.0])
    with pytest.raises(TypeError, match="taus must be an array"):
        avar.Stream("oadev", taus="octave")
    with pytest.raises(ValueError, match="data_type"):
        avar.Stream("oadev", taus=[1.0], data_type="time")
    with pytest.raises(TypeError, match="cannot identify"):
        avar.Stream("oadev", taus=[1.0], alpha=None)
    stream = avar.Stream("oadev", taus=[1.0])
    with pytest.raises(ValueError, match="NaN"):
        stream.update([1.0, np.nan])
