"""The Haar pyramid of ADEV and HDEV (octave factors, frequency data) against exact arithmetic
and against the general kernels; its noise-identification moments against a NumPy transcription
and against the two-pass lag-1 kernel on the stored phase."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.classic.levels import level_sums
from avar._kernels.classic.phase import scan
from avar._kernels.classic.pyramid import BLOCK_EXP, MOMENTS, SPLIT_BLOCKS, TAIL, octave_moments
from avar._kernels.uncertainty.lag1 import lag1_alpha_decimated
from avar._kernels.uncertainty.noise_id import ILL_CONDITIONED, lag1_alpha_from_moments
from avar.stability.classic.core import OctaveMoments, deviation_levels, octave_sums, phase_parts
from avar.stability.shared.grids import deviation_factors
from avar.stability.shared.registry import KERNEL_CODES
from avar.stability.shared.term_counts import term_ranges
from avar.stability.uncertainty.noise_id import NOISE_ID_ESTIMATORS, octave_noise, phase_noise
from tests._support.deviation_reference import exact_variance
from tests._support.powerlaw import powerlaw_phase

ORDER = {"adev": 1, "hdev": 2}
#: Shortest series cut in two stretches (one per thread).
TWO = SPLIT_BLOCKS << BLOCK_EXP
#: Lengths within one block, over several (the last partial), and in two stretches.
LENGTHS = [3, 4, 5, 1000, 4097, TWO - 1, TWO, TWO + 3, 300_001]


def adversarial(seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [
        1e9 + 1e-6 * rng.standard_normal(257),  # offset over noise
        1e9 + 1e3 * np.arange(130.0) + 1e-6 * rng.standard_normal(130),  # and a drift
        rng.standard_normal(100) * 1e-11,
    ]


@pytest.mark.parametrize("estimator", ["adev", "hdev"])
def test_pyramid_is_exact(estimator):
    for y in adversarial(7):
        factors = deviation_factors(estimator, y.size + 1)
        variance, n = deviation_levels(estimator, y, factors, "freq")
        for m, v, count in zip(factors, variance, n):
            expected, terms = exact_variance(estimator, y, int(m), "freq")
            assert count == terms
            assert v == pytest.approx(float(expected), rel=1e-12)


def test_two_stretches_are_exact_on_an_offset():
    y = 1e9 + 1e-6 * np.random.default_rng(3).standard_normal(TWO + 5)
    for estimator in ("adev", "hdev"):
        factors = deviation_factors(estimator, y.size + 1)
        variance, _ = deviation_levels(estimator, y, factors, "freq")  # all octave factors: the pyramid
        for m, v in zip(factors[[0, 1, 4, 8]], variance[[0, 1, 4, 8]]):  # exact sums of 65 k terms: a few levels
            assert v == pytest.approx(float(exact_variance(estimator, y, int(m), "freq")[0]), rel=1e-12)


@pytest.mark.parametrize("estimator", ["adev", "hdev"])
@pytest.mark.parametrize("n", LENGTHS)
def test_pyramid_equals_the_general_kernels(estimator, n):
    y = np.random.default_rng(n).standard_normal(n) + 3.0
    if n < 4 and estimator == "hdev":
        return
    factors = deviation_factors(estimator, n + 1)
    sums, counts, scale, moments, _ = octave_sums(estimator, y, factors, scan(y))
    parts = phase_parts(y, "freq", estimator)
    hi, lo, scale2 = parts.hi, parts.lo, parts.scale
    strides, first, last = term_ranges(estimator, n + 1, factors)
    general, general_counts = level_sums(hi, lo, KERNEL_CODES[estimator], factors, strides, first, last)
    np.testing.assert_array_equal(counts, general_counts)
    np.testing.assert_allclose(sums / scale**2, general / scale2**2, rtol=1e-12)
    assert isinstance(moments, OctaveMoments)


def numpy_moments(v: np.ndarray, levels: int) -> np.ndarray:
    """The columns of MOMENTS by plain NumPy: cluster sums, their running sum and differences."""
    rows = []
    for level in range(levels):
        m = 2**level
        c = v[: v.size // m * m].reshape(-1, m).sum(axis=1)
        z = np.concatenate(([0.0], np.cumsum(c)))
        t = np.arange(z.size) - c.size / 2
        d1, d2, d3 = np.diff(c), np.diff(c, 2), np.diff(c, 3)
        rows.append([c.size, z.sum(), (t * z).sum(), (t * t * z).sum(), (z * z).sum(), (c * c).sum(),
                     (d1**2).sum(), (d2**2).sum(), (d3**2).sum(), z[-1], c[0], c[-1], d1[0], d1[-1], d2[0], d2[-1]])
    return np.array(rows)


@pytest.mark.parametrize("n", [40, 1000, 3 << BLOCK_EXP, TWO + 3, 300_001])
def test_moments_equal_a_numpy_transcription(n):
    y = 5.0 + np.random.default_rng(n).standard_normal(n)
    levels = max(1, int(np.log2(n)) - 3)
    stats = np.zeros((levels, len(MOMENTS)))
    tails = np.zeros((levels, TAIL))
    octave_moments(y, 5.0, 0.0, 1.0, 2, levels, stats, tails)
    want = numpy_moments(y - 5.0, levels)
    scale = np.abs(want).max(axis=0, initial=0.0)
    np.testing.assert_allclose(stats, want, rtol=1e-9, atol=1e-12 * scale.max())
    for level in range(levels):  # the small levels hand back their clusters
        count = n >> level
        if count <= TAIL:
            np.testing.assert_allclose(tails[level, :count], (y - 5.0)[: count << level].reshape(count, -1).sum(1))


def series(alpha: int, seed: int, n: int, kind: int) -> np.ndarray:
    y = np.diff(powerlaw_phase(n + 1, alpha, seed))
    if kind == 1:
        y = y + 1e6 * np.abs(y).max()  # an offset far above the noise
    elif kind == 2:
        y = y + 1e-3 * np.arange(n) * np.abs(y).max()  # a drift far above it
    return y


@pytest.mark.parametrize("estimator", ["adev", "hdev"])
def test_moments_decide_as_the_two_pass_kernel(estimator):
    """Every level the moments decide gets the two-pass kernel's alpha; where cancellation
    took too many digits they say so (only ADEV under a strong drift, which it keeps)."""
    dmax = NOISE_ID_ESTIMATORS[estimator]
    decided = undecided = 0
    for alpha in (2, 1, 0, -1, -2):
        for seed in range(6):
            for n, kind in ((1000, seed % 3), (20_000, seed % 3), (300_000, seed % 3 if seed < 3 else 0)):
                y = series(alpha, seed, n, kind)
                factors = deviation_factors(estimator, n + 1)
                _, _, _, moments, _ = octave_sums(estimator, y, factors, scan(y))
                phase = moments.phase()
                for level, m in enumerate(factors.tolist()):
                    if n // m + 1 < 30:
                        continue
                    got = lag1_alpha_from_moments(moments.stats[level], dmax)
                    if got == ILL_CONDITIONED:
                        assert estimator == "adev" and kind == 2
                        undecided += 1
                        continue
                    decided += 1
                    assert got == lag1_alpha_decimated(phase, m, dmax, np.nan), (alpha, seed, n, kind, m)
    assert decided >= 600 and undecided < decided / 4


@pytest.mark.parametrize("estimator", ["adev", "hdev"])
@pytest.mark.parametrize("alpha", [2, 0, -2])
def test_octave_noise_equals_the_phase_path(estimator, alpha):
    """B1 from the tails, R(n) and ill-conditioned levels through the phase: the same alphas."""
    for kind in (0, 2):
        y = series(alpha, 11, 50_000, kind)
        factors = deviation_factors(estimator, y.size + 1)
        _, _, _, moments, drift = octave_sums(estimator, y, factors, scan(y))
        dmax = NOISE_ID_ESTIMATORS[estimator]
        got = octave_noise(moments.stats, moments.tails, factors, dmax, drift, moments.phase, moments.clusters)
        want = phase_noise(moments.phase(), factors, dmax, drift, line_free=True)
        np.testing.assert_array_equal(got, want)


def test_constant_level_has_no_alpha():
    stats = np.zeros((1, len(MOMENTS)))
    stats[0, 0] = 100.0
    assert np.isnan(lag1_alpha_from_moments(stats[0], 2))


@pytest.mark.parametrize("step", [1, 4, 64])
@pytest.mark.parametrize("n", [10_003, 64 * 157 - 1])
def test_rn_clusters_equal_the_phase_and_its_running_sum(step, n):
    from avar._kernels.uncertainty.noise_id import rn_clusters

    y = 2.0 + np.random.default_rng(step).standard_normal(n)
    centre, slope, scale = 2.0, 1e-5, 0.5
    x = np.concatenate(([0.0], np.cumsum((y - centre - slope * np.arange(n)) * scale)))
    z = np.empty(n // step + 1)
    running = np.empty((n + 1) // step + 1)
    rn_clusters(y, centre, slope, scale, step, z, running)
    np.testing.assert_allclose(z, x[np.arange(z.size) * step], rtol=1e-10, atol=1e-10 * np.abs(x).max())
    sums = np.concatenate(([0.0], np.cumsum(x)))[np.arange(running.size) * step]
    np.testing.assert_allclose(running, sums, rtol=1e-10, atol=1e-10 * np.abs(sums).max())


def test_r_n_from_clusters_never_builds_the_phase():
    """White FM often makes B1 say PM at the top levels; R(n) then runs on the clusters.

    HDEV's drift, removed from the moments, is data to the lag-1 rule (Stable32): it is
    added back to the moments (:func:`avar._kernels.uncertainty.noise_id.moments_with_drift`)."""
    built = {"adev": 0, "hdev": 0}
    for seed in range(6):
        y = np.random.default_rng(seed).standard_normal(200_000)
        for estimator in ("adev", "hdev"):
            factors = deviation_factors(estimator, y.size + 1)
            _, _, _, moments, drift = octave_sums(estimator, y, factors, scan(y))
            dmax = NOISE_ID_ESTIMATORS[estimator]
            calls = []

            def phase(moments=moments, calls=calls):
                calls.append(1)
                return moments.phase()

            got = octave_noise(moments.stats, moments.tails, factors, dmax, drift, phase, moments.clusters)
            np.testing.assert_array_equal(got, phase_noise(moments.phase(), factors, dmax, drift, line_free=True))
            built[estimator] += len(calls)
    assert built == {"adev": 0, "hdev": 0}


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("count", [128, 511, 1024, 1537])
def test_array_chunk_equals_its_plain_twin(order, count):
    """:func:`_chunk_fast` (array by array, in pieces) carries a level's state as the
    one-cluster-at-a-time :func:`_chunk_body` does: the same pair sums and last clusters
    bit for bit, the same moments to rounding, on double-double clusters over an offset."""
    from avar._kernels.classic.pyramid import PIECE, STATE, _chunk_body, _chunk_fast, _start

    rng = np.random.default_rng(count + order)
    first = 7  # clusters the plain twin takes first (a stretch's start is always plain)
    hi = 1e6 + rng.standard_normal(first + count)
    lo = rng.standard_normal(first + count) * 1e-11
    state = np.zeros(STATE)
    _start(state, first + count + 10, 0, 0.25)
    head_hi, head_lo = np.empty(first), np.empty(first)
    _chunk_body(hi[:first], lo[:first], order, first, 0, state, head_hi, head_lo, np.empty(0), 0)
    plain, fast = state.copy(), state.copy()
    pairs_plain = np.full((2, count // 2), np.nan)
    _chunk_body(hi[first:], lo[first:], order, count, first + 1, plain, pairs_plain[0], pairs_plain[1],
                np.empty(0), 0)
    hh, ll = np.r_[np.zeros(3), hi[first:]], np.r_[np.zeros(3), lo[first:]]
    dst_hh, dst_ll = np.full(count + 3, np.nan), np.full(count + 3, np.nan)
    work = [np.empty(PIECE + 1) for _ in range(5)]
    _chunk_fast(hh, ll, order, count, fast, dst_hh, dst_ll, *work)
    np.testing.assert_array_equal(dst_hh[3 : 3 + count // 2], pairs_plain[0])
    np.testing.assert_array_equal(dst_ll[3 : 3 + count // 2], pairs_plain[1])
    exact_fields = [9, 10, 11, 12, 13, 14, 19]  # last three clusters, centred index
    np.testing.assert_array_equal(fast[exact_fields], plain[exact_fields])
    sums = [0, 1, 2, 3, 4, 5, 6, 7, 8, 15, 16]  # running moments, last differences
    np.testing.assert_allclose(fast[sums], plain[sums], rtol=1e-12, atol=0)
    assert plain[6] > 0 and plain[7] > 0 and (order == 1 or plain[8] > 0)


def test_first_level_pairs_are_phase_increments_bit_for_bit():
    """Level 1's exact pairs (y - centre) scale, written out branch free when no drift is removed,
    are phase_increment's, bits and signs of zero included. Their second parts lie below any
    tolerance a sum could show (a mutant that drops them passes the value tests): bits can fail."""
    from avar._kernels.classic.phase import phase_increment
    from avar._kernels.classic.pyramid import _NO_LO, _increments

    rng = np.random.default_rng(4)
    y = np.concatenate([rng.standard_normal(3000) * 10.0 ** rng.integers(-8, 9, 3000), [0.0, -0.0, 1e-300, 3.0]])
    centre, scale = float(np.mean(y)), 2.0**-5
    hh, ll = np.zeros(y.size + 3), np.zeros(y.size + 3)
    _increments(y, 0, y.size, centre, 0.0, scale, hh, ll)
    pairs = np.array([tuple(phase_increment(y, _NO_LO, i, 0, centre, 0.0, scale)) for i in range(y.size)])
    assert np.array_equal(hh[3:], pairs[:, 0]) and np.array_equal(ll[3:], pairs[:, 1])
    assert np.array_equal(np.signbit(ll[3:]), np.signbit(pairs[:, 1]))
    assert np.count_nonzero(ll[3:]) > 100  # the second parts are exercised
