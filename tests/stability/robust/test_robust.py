"""avar.robust_avar and avar.count_outliers: plain twins, closed forms and simulations with known spikes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.ndimage import median_filter

import avar
from avar._kernels import intact_squares, interpolation_residuals, release_candidates, running_median
from avar.stability.robust.estimator import intact_counts, robust_scale


def residuals_loop(x: np.ndarray, flagged: np.ndarray) -> np.ndarray:
    """Plain twin of interpolation_residuals: np.interp through the unflagged samples other than t."""
    n = len(x)
    out = np.empty(n)
    for t in range(n):
        keep = ~flagged.copy()
        keep[t] = False
        left, right = np.flatnonzero(keep[:t]), t + 1 + np.flatnonzero(keep[t + 1:])
        if left.size and right.size:
            a, b = left[-1], right[0]
            out[t] = x[t] - np.interp(t, [a, b], [x[a], x[b]])
        elif left.size or right.size:
            out[t] = x[t] - x[left[-1] if left.size else right[0]]
        else:
            out[t] = 0.0
    return out


def median_loop(x: np.ndarray, half: int) -> np.ndarray:
    """Plain twin of running_median: the median of the mirrored window, sample by sample."""
    n = len(x)

    def mirror(i):
        i = -i if i < 0 else i
        i = 2 * (n - 1) - i if i >= n else i
        return min(max(i, 0), n - 1)

    return np.array([sorted(x[mirror(i)] for i in range(t - half, t + half + 1))[half] for t in range(n)])


def mo_loop(x: np.ndarray, m: int, bad: np.ndarray | None = None) -> float:
    """The "mo" Allan variance as a loop over its differences, skipping those that touch a flagged sample."""
    total, count = 0.0, 0
    for t in range(len(x) - 2 * m + 1):
        if bad is not None and bad[t:t + 2 * m].any():
            continue
        d = x[t + m:t + 2 * m].mean() - x[t:t + m].mean()
        total += d * d / 2
        count += 1
    return total / count


def white_plus_walk(n: int, seed: int, sigma: float = 1.0, gamma: float = 0.01) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return sigma * rng.standard_normal(n) + np.cumsum(gamma * rng.standard_normal(n))


def add_spikes(x: np.ndarray, rate: float, size: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    where = np.sort(rng.choice(x.size, int(round(rate * x.size)), replace=False))
    spiky = x.copy()
    spiky[where] += size * rng.choice([-1.0, 1.0], where.size)
    return spiky, where


# --------------------------------------------------------------------------- the kernel and helpers
@pytest.mark.parametrize("n", [2, 3, 5, 40, 300])
@pytest.mark.parametrize("density", [0.0, 0.1, 0.5, 1.0])
def test_interpolation_residuals_match_loop(n, density):
    rng = np.random.default_rng(n)
    x = np.cumsum(rng.standard_normal(n)) + 100.0
    flagged = rng.random(n) < density
    out = np.empty(n)
    interpolation_residuals(x, flagged, out)
    np.testing.assert_allclose(out, residuals_loop(x, flagged), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("n", [1, 2, 5, 11, 12, 300])
@pytest.mark.parametrize("half", [0, 1, 5])
def test_running_median_matches_loop(n, half):
    x = np.round(np.random.default_rng(n * 10 + half).standard_normal(n), 1)  # ties on purpose
    out = np.empty(n)
    running_median(x, half, out)
    np.testing.assert_array_equal(out, median_loop(x, half))
    if n > half:
        np.testing.assert_array_equal(out, median_filter(x, 2 * half + 1, mode="mirror"))


def test_residuals_of_a_spike_and_the_line_that_skips_it():
    x = np.zeros(9)
    x[4] = 10.0
    residuals = np.empty(9)
    flagged = np.zeros(9, dtype=bool)
    interpolation_residuals(x, flagged, residuals)
    assert residuals.tolist() == [0, 0, 0, -5, 10, -5, 0, 0, 0]
    flagged[4] = True
    interpolation_residuals(x, flagged, residuals)
    assert residuals.tolist() == [0, 0, 0, 0, 10, 0, 0, 0, 0]


def test_intact_counts_match_a_loop():
    rng = np.random.default_rng(3)
    n = 400
    bad = rng.random(n) < 0.03
    bad[[0, 1, n - 1]] = True
    factors = np.array([1, 2, 3, 8, 50, 200])
    loop = [sum(not bad[t:t + 2 * m].any() for t in range(n - 2 * m + 1)) for m in factors]
    assert intact_counts(np.flatnonzero(bad), n, factors).tolist() == loop


def test_robust_scale_of_gaussian_and_quantized_noise():
    rng = np.random.default_rng(0)
    assert robust_scale(3.0 * rng.standard_normal(200_000)) == pytest.approx(3.0, rel=0.01)
    # 95 % of the residuals are 0: the MAD is 0; the grouped quartiles spread each value over its bin
    quantized = np.zeros(1000)
    quantized[:50] = np.tile([1.0, -1.0], 25)
    quantized[500] = 100.0
    q1, q3 = -0.5 + (250 - 25) / 949, -0.5 + (750 - 25) / 949  # both in the bin [-1/2, 1/2) of the 949 zeros
    assert robust_scale(quantized) == pytest.approx((q3 - q1) / 1.3489795003921634)


@pytest.mark.parametrize("sigma", [0.6, 1.0, 2.0])
def test_robust_scale_of_quantized_gaussian_noise_follows_sheppard(sigma):
    """Rounded to whole steps, the MAD is a whole or half step (0 at sigma = 0.6, 1 at sigma = 1: +42 %);
    the grouped quartiles are within 8 % of sqrt(sigma**2 + 1/12), the standard deviation of the
    rounded values (Sheppard's correction)."""
    z = np.round(sigma * np.random.default_rng(int(10 * sigma)).standard_normal(400_000))
    assert robust_scale(z) == pytest.approx(np.sqrt(sigma**2 + 1 / 12), rel=0.08)
    assert robust_scale(z * 0.05) == pytest.approx(0.05 * np.sqrt(sigma**2 + 1 / 12), rel=0.08)  # 0.05 inexact


    assert robust_scale(np.full(10, 4.0)) == 0.0


# --------------------------------------------------------------------------- count_outliers
@pytest.mark.parametrize("walk", [0.0, 0.05])
def test_count_outliers_finds_known_spikes(walk):
    x = white_plus_walk(100_000, 1, gamma=walk)
    spiky, where = add_spikes(x, 0.01, 12.0, seed=2)
    found = avar.count_outliers(spiky)
    assert abs(found.count - where.size) <= 3
    assert np.isin(where, found.indices).mean() > 0.99
    # residual x_t - (x_{t-1} + x_{t+1}) / 2: variance 1.5 sigma**2 + gamma**2 / 2, not inflated by the spikes
    assert found.scale == pytest.approx(np.sqrt(1.5 + walk**2 / 2), rel=0.02)
    assert found.fraction == found.count / 100_000 and int(found) == found.count
    assert "beyond 6 robust SD" in repr(found)
    assert np.array_equal(avar.count_outliers(spiky, threshold=6).indices, found.indices)


@pytest.mark.parametrize("kind", ["white", "walk", "white+walk"])
def test_count_outliers_on_clean_gaussian_series_is_zero(kind):
    rng = np.random.default_rng(11)
    steps = rng.standard_normal(200_000)
    x = {"white": steps, "walk": np.cumsum(steps), "white+walk": white_plus_walk(200_000, 4, gamma=0.3)}[kind]
    assert avar.count_outliers(x).count == 0
    assert avar.count_outliers(x, threshold=4.0).count < 200_000 * 2e-3  # Gaussian tail beyond ~4 sd: 6e-5


def test_count_outliers_of_adjacent_spikes_and_a_burst():
    x = np.random.default_rng(5).standard_normal(3000)
    truth = [10, 11, 500, 1000, 1001, 1002, 2999]
    x[truth] += [25.0, -25.0, 30.0, 40.0, 40.0, 40.0, 30.0]
    assert avar.count_outliers(x).indices.tolist() == truth
    assert avar.count_outliers(pd.Series(x), threshold=100.0).count == 0


def test_count_outliers_of_quantized_data():
    rng = np.random.default_rng(6)
    x = np.round(rng.standard_normal(20_000) * 0.3)  # 1 LSB steps, most samples 0
    x[[50, 900]] = [40.0, -40.0]
    assert avar.count_outliers(x).indices.tolist() == [50, 900]


# --------------------------------------------------------------------------- robust_avar
def test_without_outliers_it_is_the_ordinary_allan_variance():
    x = white_plus_walk(5000, 5) + 1e6
    res = avar.robust_avar(x, rate=100.0, taus="decade")
    ref = avar.avar(x, type="mo", freq=100.0, taus="decade")
    assert res.outliers.count == 0 and res.type == "mo"
    np.testing.assert_array_equal(res.averaging_factors, ref.averaging_factors)
    np.testing.assert_allclose(res.levels, ref.levels)
    np.testing.assert_allclose(res.allan, ref.allan, rtol=1e-12)
    np.testing.assert_array_equal(res.n_differences, ref.n_differences)
    assert res.intact.all() and np.all(res.contaminated == 0)
    assert isinstance(res, avar.AllanVariance)


def test_intact_and_filled_levels_match_plain_loops():
    x = white_plus_walk(1200, 8)
    spiky, where = add_spikes(x, 0.05, 30.0, seed=9)
    res = avar.robust_avar(spiky, taus="all")
    assert res.outliers.indices.tolist() == where.tolist()
    bad = np.zeros(spiky.size, dtype=bool)
    bad[where] = True
    keep = ~bad
    filled = spiky.copy()
    filled[bad] = np.interp(where, np.flatnonzero(keep), spiky[keep])
    assert res.intact[0] and not res.intact[-1]
    for j in [*range(25), *range(len(res) - 3, len(res))]:  # the intact levels, filled ones, the largest
        m = res.averaging_factors[j]
        if res.intact[j]:
            expected = mo_loop(spiky, m, bad)
        else:  # less the white noise's fill excess p s**2 / m, at most a share 1.5 p / (1 + 1.5 p)
            raw = mo_loop(filled, m)
            p, s2 = where.size / spiky.size, res.outliers.scale**2
            expected = raw - min(p * s2 / m, raw * 1.5 * p / (1 + 1.5 * p))
        assert res.allan[j] == pytest.approx(expected, rel=1e-10), m
        if res.intact[j]:
            assert res.n_differences[j] == sum(not bad[t:t + 2 * m].any() for t in range(spiky.size - 2 * m + 1))
    total = spiky.size - 2 * res.averaging_factors + 1
    np.testing.assert_allclose(res.contaminated, 1 - intact_counts(where, spiky.size, res.averaging_factors) / total)


@pytest.mark.parametrize("process", ["white", "walk"])
def test_consistent_on_clean_gaussian_data(process):
    """Expectation equals the closed form within sampling error; no loss against the ordinary estimator."""
    n = 2**18
    rng = np.random.default_rng(21)
    steps = rng.standard_normal(n)
    x = steps if process == "white" else np.cumsum(steps)
    res = avar.robust_avar(x)
    ordinary = avar.avar(x)
    m = res.averaging_factors
    theory = avar.av_wn(1.0, m) if process == "white" else avar.av_rw(1.0, m)
    useful = n / (2 * m) >= 100
    # relative standard error of the "mo" AV: about sqrt(2 m / N) (white), sqrt(3 m / N) (random walk)
    bound = 4 * np.sqrt(3 * m / n)
    assert np.all(np.abs(res.allan[useful] / theory[useful] - 1) < bound[useful])
    assert res.outliers.count < 2e-4 * n  # a Gaussian residual beyond 4 sd: probability 6.3e-5 (17 expected)
    # the few clean extremes set aside move each level by < 0.2 %, or by < 10 % of its standard error (2 errors)
    assert np.all(np.abs(res.allan / ordinary.allan - 1) < np.maximum(2e-3, 0.1 * 2 * ordinary.errors))


@pytest.mark.parametrize("seed", [0, 1])
def test_resists_five_percent_spikes_of_20_sigma(seed):
    n = 2**17
    clean = white_plus_walk(n, seed)
    spiky, where = add_spikes(clean, 0.05, 20.0, seed=seed + 100)
    reference = avar.avar(clean, freq=200.0)
    res = avar.robust_avar(spiky, rate=200.0)
    ordinary = avar.avar(spiky, freq=200.0)
    useful = n / (2 * reference.averaging_factors) >= 100
    assert useful.sum() >= 9
    ratio = res.allan / reference.allan
    assert np.all(np.abs(ratio[useful] - 1) < 0.10), ratio
    assert np.all(ordinary.allan[:6] / reference.allan[:6] > 10)  # the spikes dominate the ordinary AV
    assert abs(res.outliers.count - where.size) <= 0.01 * where.size
    # the breakdown measure: about 1 - (1 - p)**(2m) of the differences touch a spike
    np.testing.assert_allclose(res.contaminated[:4], 1 - 0.95 ** (2 * res.averaging_factors[:4]), atol=0.02)
    assert res.intact[0] and not res.intact[useful].all()


def test_the_fill_excess_of_white_noise_is_removed():
    """White noise, 5 % spikes: an interpolated sample adds 1.5 sigma**2 to a cluster sum; the filled levels
    would be 7.5 % high, and are not once p s**2 / m is subtracted."""
    n = 2**17
    clean = np.random.default_rng(31).standard_normal(n)
    spiky, _ = add_spikes(clean, 0.05, 20.0, seed=32)
    res = avar.robust_avar(spiky)
    filled = ~res.intact & (n / (2 * res.averaging_factors) >= 100)
    assert filled.sum() >= 4
    assert res.outliers.scale == pytest.approx(np.sqrt(1.5), rel=0.02)
    ratio = (res.allan / avar.avar(clean).allan)[filled]
    assert abs(np.mean(ratio) - 1) < 0.025 and np.all(np.abs(ratio - 1) < 0.06), ratio


def test_results_are_read_only_and_checked():
    res = avar.robust_avar(add_spikes(white_plus_walk(2000, 1), 0.02, 20.0, 2)[0])
    for name in ("allan", "intact", "contaminated"):
        with pytest.raises(ValueError):
            getattr(res, name)[0] = 1
    with pytest.raises(ValueError):
        res.outliers.indices[0] = 0
    fields = {f: getattr(res, f) for f in ("levels", "averaging_factors", "allan", "errors", "n_differences")}
    with pytest.raises(TypeError, match="outliers must be"):
        avar.RobustAllanVariance(**fields, type="mo", freq=1.0, n=2000, intact=res.intact,
                                 contaminated=res.contaminated)
    with pytest.raises(ValueError, match="one value per level"):
        avar.RobustAllanVariance(**fields, type="mo", freq=1.0, n=2000, outliers=res.outliers,
                                 intact=res.intact[:-1], contaminated=res.contaminated)


def test_levels_follow_avar_grids():
    x = add_spikes(white_plus_walk(3000, 2), 0.02, 20.0, 3)[0]
    for taus in ("octave", "decade", "all", [0.1, 0.5, 2.0]):
        res = avar.robust_avar(x, rate=10.0, taus=taus)
        np.testing.assert_array_equal(res.averaging_factors, avar.avar(x, freq=10.0, taus=taus).averaging_factors)
        assert len(res.intact) == len(res) and res.freq == 10.0
    assert "robust: 60 outlying samples" in res.describe()
    assert set(res.summary().columns) >= {"Time", "AVar", "ADev"}


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(threshold=0.0), ValueError, "threshold must be > 0"),
    (dict(threshold="5"), TypeError, "threshold must be a real number"),
    (dict(threshold=float("nan")), ValueError, "threshold must be finite"),
    (dict(freq=-1.0), ValueError, "freq"),
])
def test_validation_names_the_argument(kwargs, error, words):
    with pytest.raises(error, match=words):
        avar.robust_avar(np.arange(100.0), **kwargs)


def test_validation_of_the_series():
    with pytest.raises(ValueError, match="x must be 1-D"):
        avar.count_outliers(np.zeros((10, 2)))
    with pytest.raises(ValueError, match="x"):
        avar.robust_avar(np.array([1.0, np.nan, 2.0, 3.0]))
    imu = avar.IMU(np.zeros((100, 6)), freq=10.0, gyro=[0, 1, 2], accel=[3, 4, 5])
    for table in (imu, pd.DataFrame({"a": np.arange(10.0)})):
        with pytest.raises(TypeError, match="x must be one series"):
            avar.robust_avar(table)
        with pytest.raises(TypeError, match="x must be one series"):
            avar.count_outliers(table)


def release_loop(x: np.ndarray, flagged: np.ndarray, limit: float) -> np.ndarray:
    """Plain twin of release_candidates: residuals of the whole pass first, then the releases."""
    flagged = flagged.copy()
    while True:
        residuals = residuals_loop(x, flagged)
        released = flagged & (np.abs(residuals) <= limit)
        if not released.any():
            return flagged
        flagged &= ~released


@pytest.mark.parametrize("seed", range(4))
def test_release_candidates_matches_loop(seed):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.standard_normal(300))
    x[rng.choice(300, 6, replace=False)] += 15.0
    candidates = np.abs(x - median_loop(x, 5)) > 1.0
    flagged = candidates.copy()
    residuals = np.empty(300)
    passes = release_candidates(x, flagged, residuals, 6.0, 50)
    np.testing.assert_array_equal(flagged, release_loop(x, candidates, 6.0))
    np.testing.assert_allclose(residuals, residuals_loop(x, flagged), atol=1e-12)
    assert 1 <= passes < 50 and flagged.sum() >= 5


@pytest.mark.parametrize("m", [1, 3, 17, 600])
def test_intact_squares_matches_loop(m):
    rng = np.random.default_rng(m)
    x = np.cumsum(rng.standard_normal(3000)) + 1e3  # an offset and a walk: the sliding sum must not drift
    flagged = rng.random(3000) < (0.02 if m < 100 else 0.0005)
    centred = x - x.mean()
    squares, used = intact_squares(centred, flagged, m)
    expected = [(centred[t + m:t + 2 * m].sum() - centred[t:t + m].sum()) ** 2
                for t in range(3000 - 2 * m + 1) if not flagged[t:t + 2 * m].any()]
    assert used == len(expected) > 0
    assert squares == pytest.approx(sum(expected), rel=1e-11)


def test_huge_and_tiny_magnitudes_scale_exactly():
    x = white_plus_walk(4000, 12)
    spiky, where = add_spikes(x, 0.05, 20.0, seed=13)
    base = avar.robust_avar(spiky)
    assert base.intact.any()
    for factor in (2.0**500, 2.0**-500):
        res = avar.robust_avar(spiky * factor)
        np.testing.assert_array_equal(res.outliers.indices, base.outliers.indices)
        np.testing.assert_allclose(res.allan, base.allan * factor**2, rtol=1e-12)
    with pytest.raises(ValueError, match="overflows float64"):
        avar.robust_avar(spiky * 1e306)
    with pytest.raises(ValueError, match="below the float64 range"):  # as avar.avar: never a silent 0
        avar.robust_avar(spiky * 2.0**-600)


def test_resists_spikes_on_quantized_data():
    """LSB of half the white noise's sigma: the grouped robust scale; no clean sample counted at 6 SD."""
    n = 2**17
    clean = np.round(white_plus_walk(n, 4) / 0.5) * 0.5
    spiky, where = add_spikes(clean, 0.05, 20.0, seed=5)
    assert avar.count_outliers(clean).count == 0
    res = avar.robust_avar(spiky)
    assert abs(res.outliers.count - where.size) <= 0.005 * where.size
    reference = avar.avar(clean)
    useful = n / (2 * res.averaging_factors) >= 100
    assert np.all(np.abs(res.allan / reference.allan - 1)[useful] < 0.10)
