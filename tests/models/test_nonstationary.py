"""Tests of avar.nonstationary: theoretical MOAV / NOAV (Xu et al. 2017) and covmats."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from avar.models.covariance import covmat_ar1blocks, covmat_bi, covmat_nswn
from avar.models.nonstationary import moav, noav
from avar.models.theory import av_ar1, av_rw, av_wn


# ----------------------------------------------------------------- references
def direct_av(n: int, covmat: np.ndarray, starts) -> float:
    """R's loop, transcribed: sum the n x n sub-blocks of every window."""
    total = 0.0
    for s in starts:
        a, b, c = s, s + n, s + 2 * n
        total += covmat[a:b, a:b].sum() + covmat[b:c, b:c].sum() - 2.0 * covmat[a:b, b:c].sum()
    return total / (n * n * 2 * len(starts))


def direct_moav(n: int, covmat: np.ndarray) -> float:
    return direct_av(n, covmat, range(covmat.shape[0] - 2 * n + 1))


def direct_noav(n: int, covmat: np.ndarray) -> float:
    return direct_av(n, covmat, range(0, 2 * n * (covmat.shape[0] // (2 * n)), 2 * n))


def toeplitz_ar1(t: int, phi: float, sigma2: float) -> np.ndarray:
    lag = np.abs(np.subtract.outer(np.arange(t), np.arange(t)))
    return sigma2 / (1 - phi**2) * phi ** lag.astype(float)


# R's output of the manual example: sapply(1:8, function(y){MOAV(2^y, covmat)})
R_MANUAL = [0.52325, 0.350727081, 0.203446388, 0.108896684,
            0.056242028, 0.028569436, 0.014396823, 0.007226438]


# ----------------------------------------------------------------- R's manual example
def test_manual_example_moav_noav():
    covmat = 0.3 ** np.abs(np.subtract.outer(np.arange(1000), np.arange(1000))).astype(float)
    ns = 2 ** np.arange(1, 9)
    mo, no = moav(ns, covmat), noav(ns, covmat)
    # R printed 9 decimals: agree to half a unit of the last printed digit
    np.testing.assert_allclose(mo, R_MANUAL, rtol=0, atol=5e-10)
    np.testing.assert_allclose(no, R_MANUAL, rtol=0, atol=5e-10)
    np.testing.assert_allclose(no, mo, rtol=1e-8)
    assert mo[0] == pytest.approx(0.52325, rel=1e-12)  # = av_ar1(2, 0.3, 0.91) exactly
    # stationary process: equal to Zhang's closed form with innovation variance 1 - 0.3^2
    np.testing.assert_allclose(mo, av_ar1(ns, 0.3, 0.91), rtol=1e-12)


# ----------------------------------------------------------------- cross-checks
def test_stationary_ar1_equals_closed_form():
    t, phi, s2 = 2000, 0.9, 1.5
    covmat = toeplitz_ar1(t, phi, s2)
    ns = 2 ** np.arange(1, int(np.log2(t)))  # all octave scales, 2 .. 512
    expected = av_ar1(ns, phi, s2)
    np.testing.assert_allclose(moav(ns, covmat), expected, rtol=1e-10)
    np.testing.assert_allclose(noav(ns, covmat), expected, rtol=1e-10)


def test_white_noise_equals_av_wn():
    s2, t = 2.5, 257
    ns = np.arange(1, t // 2 + 1)
    np.testing.assert_allclose(moav(ns, s2 * np.eye(t)), av_wn(s2, ns), rtol=1e-13)
    np.testing.assert_allclose(noav(ns, s2 * np.eye(t)), av_wn(s2, ns), rtol=1e-13)


def test_random_walk_covariance_equals_av_rw():
    # x_t = sum of t increments of variance w2: cov = w2 min(i, j); stationary increments
    t, w2 = 2000, 0.37
    i = np.arange(1, t + 1)
    covmat = w2 * np.minimum.outer(i, i).astype(float)
    ns = 2 ** np.arange(0, int(np.log2(t)))
    np.testing.assert_allclose(moav(ns, covmat), av_rw(w2, ns), rtol=1e-9)
    np.testing.assert_allclose(noav(ns, covmat), av_rw(w2, ns), rtol=1e-9)


@pytest.mark.parametrize("t", [64, 101])
def test_nswn_against_exact_direct_computation(t):
    s2 = Fraction(3, 10)
    covmat = covmat_nswn(0.3 * np.arange(1, t + 1), t)  # variance growing linearly in time
    for n in (1, 2, 5, 16, t // 2):
        # exact rational transcription of the definition for a diagonal covmat
        w = t - 2 * n + 1
        mo = sum(sum(s2 * (i + 1) for i in range(s, s + 2 * n)) for s in range(w))
        mo /= 2 * n * n * w
        m = t // (2 * n)
        no = sum(s2 * (i + 1) for i in range(2 * n * m)) / (2 * n * n * m)
        assert moav(n, covmat) == pytest.approx(float(mo), rel=1e-13)
        assert noav(n, covmat) == pytest.approx(float(no), rel=1e-13)
        # closed forms: the white noise AV of the average variance (Xu et al.)
        assert mo == s2 * (t + 1) / (2 * n)
        assert no == s2 * (2 * n * m + 1) / (2 * n)
        assert moav(n, covmat) == pytest.approx(direct_moav(n, covmat), rel=1e-13)


@pytest.mark.parametrize("t, seed", [(60, 1), (151, 2), (200, 3)])
def test_random_psd_against_direct_transcription(t, seed):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((t, t))
    covmat = a @ a.T
    # odd n and the largest valid n
    ns = sorted(k for k in {1, 2, 3, 7, 16, 33, t // 3, t // 2 - 1, t // 2} if 2 * k <= t)
    mo, no = moav(ns, covmat), noav(ns, covmat)
    for k, n in enumerate(ns):
        assert mo[k] == pytest.approx(direct_moav(n, covmat), rel=1e-10)
        assert noav(n, covmat) == pytest.approx(direct_noav(n, covmat), rel=1e-10)
        assert no[k] == noav(n, covmat)
        assert moav(n, covmat) == mo[k]


@pytest.mark.parametrize("t", [2, 7, 64, 151])
def test_noav_both_algorithms_agree(t):
    # one scale: segment sums per row and scale; many scales: one prefix scan per row
    a = np.random.default_rng(t).standard_normal((t, t))
    covmat = a @ a.T
    ns = np.arange(1, t // 2 + 1)
    many = noav(ns, covmat)
    for k, n in enumerate(ns):
        single = noav(int(n), covmat)
        assert many[k] == pytest.approx(single, rel=1e-12)
        assert single == pytest.approx(direct_noav(int(n), covmat), rel=1e-12)


def test_nonstationary_heteroscedastic_ar1():
    t = 300
    sd = np.exp(np.random.default_rng(4).standard_normal(t))
    covmat = sd[:, None] * toeplitz_ar1(t, 0.95, 1.0) * sd[None, :]
    for n in (1, 4, 37, 150):
        assert moav(n, covmat) == pytest.approx(direct_moav(n, covmat), rel=1e-10)
        assert noav(n, covmat) == pytest.approx(direct_noav(n, covmat), rel=1e-10)


def test_blocks_processes_against_direct():
    for covmat in (covmat_ar1blocks(240, 20, 0.9, 1.0), covmat_bi(2.0, 240, 24)):
        for n in (1, 3, 10, 20, 64, 120):
            assert moav(n, covmat) == pytest.approx(direct_moav(n, covmat), rel=1e-10)
            assert noav(n, covmat) == pytest.approx(direct_noav(n, covmat), rel=1e-10)
    # bias instability at n = 1: Var(x_(s+1) - x_s) is 2 sigma2 for the K - 1 windows
    # that straddle a block edge and 0 otherwise, so moav = sigma2 (K - 1) / (T - 1)
    t, nb = 240, 24
    assert moav(1, covmat_bi(2.0, t, nb)) == pytest.approx(2.0 * (t // nb - 1) / (t - 1))


@settings(max_examples=50, deadline=None)
@given(t=st.integers(2, 24), seed=st.integers(0, 2**31), data=st.data())
def test_property_random_covmat(t, seed, data):
    n = data.draw(st.integers(1, t // 2))
    a = np.random.default_rng(seed).standard_normal((t, t + 1))
    covmat = a @ a.T
    assert moav(n, covmat) == pytest.approx(direct_moav(n, covmat), rel=1e-10)
    assert noav(n, covmat) == pytest.approx(direct_noav(n, covmat), rel=1e-10)


def test_result_types_and_shapes():
    c = np.eye(16)
    assert type(moav(2, c)) is float and type(noav(np.int64(2), c)) is float
    assert type(moav(2.0, c)) is float
    out = moav(np.array([[1, 2], [4, 8]]), c)
    assert out.shape == (2, 2) and out.dtype == np.float64
    np.testing.assert_allclose(out, [[1, 0.5], [0.25, 0.125]])
    assert moav([2], c).shape == (1,)
    # integer and list input, T = 2
    assert moav(1, [[2, 1], [1, 2]]) == 1.0 == noav(1, [[2, 1], [1, 2]])


def test_nearly_symmetric_accepted():
    covmat = toeplitz_ar1(50, 0.5, 1.0)
    covmat[3, 7] *= 1 + 1e-13
    assert moav(4, covmat) == pytest.approx(av_ar1(4, 0.5, 1.0), rel=1e-12)


# ----------------------------------------------------------------- covariance matrices
def test_covmat_ar1blocks():
    c = covmat_ar1blocks(n_total=6, n_block=3, phi=0.5, sigma2=0.75)
    block = np.array([[1, 0.5, 0.25], [0.5, 1, 0.5], [0.25, 0.5, 1]])
    expected = np.zeros((6, 6))
    expected[:3, :3] = expected[3:, 3:] = block
    np.testing.assert_allclose(c, expected, rtol=1e-15)
    c = covmat_ar1blocks(1000, 10, 0.9, 1.0)
    assert c.shape == (1000, 1000)
    assert c[0, 0] == pytest.approx(1 / 0.19) and c[0, 9] == pytest.approx(0.9**9 / 0.19)
    assert c[9, 10] == 0.0 and c[10, 10] == c[0, 0]
    # n_total not a multiple of n_block: as R (kronecker), floor(n_total/n_block) blocks
    assert covmat_ar1blocks(10, 4, 0.5, 1.0).shape == (8, 8)


def test_covmat_bi_uses_sigma2_not_its_square():
    # R 0.1.3 fills the blocks with sigma2^2 (defect 4): covmat_bi(2, 6, 3) would hold 4
    c = covmat_bi(sigma2=2.0, n_total=6, n_block=3)
    expected = np.kron(np.eye(2), np.full((3, 3), 2.0))
    np.testing.assert_array_equal(c, expected)
    assert c.max() == 2.0
    assert covmat_bi(2.0, 800, 20).shape == (800, 800)
    assert covmat_bi(2.0, 7, 3).shape == (6, 6)


def test_covmat_nswn():
    # R: diag(sigma2, n_total, n_total) is sigma2 * I for a scalar sigma2
    np.testing.assert_array_equal(covmat_nswn(0.5, 4), 0.5 * np.eye(4))
    np.testing.assert_array_equal(covmat_nswn(1.5, 150), 1.5 * np.eye(150))
    ns = np.arange(2, 33)
    np.testing.assert_allclose(moav(ns, covmat_nswn(1.5, 150)), av_wn(1.5, ns), rtol=1e-13)
    assert covmat_nswn(sigma2=2, n_total=800).shape == (800, 800)
    # a vector of per-sample variances is used as is, like R's diag(sigma2, n, n)
    np.testing.assert_array_equal(covmat_nswn([1.0, 3.0, 2.0], 3), np.diag([1.0, 3.0, 2.0]))
    with pytest.raises(ValueError, match="sigma2 must be a scalar or have length n_total = 3"):
        covmat_nswn([1.0, 2.0], 3)


# ----------------------------------------------------------------- empirical check
def test_empirical_mo_av_of_white_noise():
    avar = pytest.importorskip("avar")
    s2, n_series, length = 2.0, 200, 1000
    rng = np.random.default_rng(20240601)
    runs = []
    for _ in range(n_series):
        res = avar.avar(rng.normal(0.0, np.sqrt(s2), length), type="mo", freq=1.0, taus="octave")
        runs.append(res.allan)
    m = np.asarray(res.averaging_factors)
    np.testing.assert_array_equal(m, 2 ** np.arange(1, 9))
    runs = np.array(runs)
    mean, se = runs.mean(axis=0), runs.std(axis=0, ddof=1) / np.sqrt(n_series)
    theory = av_wn(s2, m)
    assert np.all(np.abs(mean - theory) < 3 * se), (mean, theory, se)
    # and the theoretical MOAV of the same process agrees with the closed form
    np.testing.assert_allclose(moav(m, s2 * np.eye(length)), theory, rtol=1e-13)


# ----------------------------------------------------------------- bad input
@pytest.mark.parametrize("f", [moav, noav])
def test_bad_covmat(f):
    c = np.eye(8)
    asym = c.copy()
    asym[0, 5] = 0.3
    with pytest.raises(ValueError, match="covmat must be symmetric"):
        f(2, asym)
    with pytest.raises(ValueError, match=r"must be a square T x T matrix, got shape \(8, 7\)"):
        f(2, np.ones((8, 7)))
    with pytest.raises(ValueError, match="covmat must be a square T x T matrix"):
        f(1, np.ones(8))
    with pytest.raises(ValueError, match="covmat must be at least 2 x 2"):
        f(1, np.ones((1, 1)))
    bad = c.copy()
    bad[2, 2] = np.nan
    with pytest.raises(ValueError, match="covmat must be finite"):
        f(2, bad)
    bad[2, 2] = np.inf
    with pytest.raises(ValueError, match="covmat must be finite"):
        f(2, bad)
    with pytest.raises(TypeError, match="covmat must be a square numeric matrix"):
        f(2, "eye")
    with pytest.raises(TypeError, match="covmat must be a square numeric matrix"):
        f(2, np.eye(4, dtype=complex))


@pytest.mark.parametrize("f", [moav, noav])
def test_check_reads_every_entry(f):
    # the check splits the matrix in 64 x 64 tiles between two tasks (upper rows,
    # lower rows, and the top-right block from either side): a defect in any region,
    # on either side of the diagonal, at the edges of tiles, must be found
    t = 200
    edges = [0, 1, 63, 64, 127, 128, 150, 191, 192, 199]
    for i in edges:
        for j in edges:
            c = np.eye(t)
            c[i, j] = np.nan if (i + j) % 2 else -np.inf
            with pytest.raises(ValueError, match="covmat must be finite"):
                f(2, c)
            if i != j:
                c[i, j] = 1e-6
                with pytest.raises(ValueError, match="covmat must be symmetric"):
                    f(2, c)


@pytest.mark.parametrize("f", [moav, noav])
def test_bad_n(f):
    c = np.eye(10)
    with pytest.raises(ValueError, match=r"n must satisfy 1 <= n <= T/2 = 5 .*got 6"):
        f(6, c)
    with pytest.raises(ValueError, match=r"n must satisfy 1 <= n <= T/2 = 5 .*got 6"):
        f([1, 2, 6], c)
    with pytest.raises(ValueError, match="n must be >= 1, got 0"):
        f(0, c)
    with pytest.raises(ValueError, match=r"n must be whole numbers.*got 2\.5"):
        f(2.5, c)
    with pytest.raises(TypeError, match="n must be a real number"):
        f("2", c)


def test_bad_covmat_builder_input():
    with pytest.raises(ValueError, match=r"phi must satisfy \|phi\| < 1"):
        covmat_ar1blocks(100, 10, 1.0, 1.0)
    with pytest.raises(ValueError, match=r"sigma2 must be >= 0"):
        covmat_ar1blocks(100, 10, 0.5, -1.0)
    with pytest.raises(ValueError, match=r"sigma2 must be >= 0"):
        covmat_bi(-2.0, 100, 10)
    with pytest.raises(ValueError, match=r"sigma2 must be >= 0"):
        covmat_nswn(-1.0, 100)
    with pytest.raises(ValueError, match="n_block must be <= n_total"):
        covmat_bi(1.0, 10, 20)
    with pytest.raises(ValueError, match=r"n_total must be whole numbers.*got 10\.5"):
        covmat_bi(1.0, 10.5, 2)
    with pytest.raises(ValueError, match="n_block must be >= 1"):
        covmat_ar1blocks(10, 0, 0.5, 1.0)
    with pytest.raises(ValueError, match="n_total must be a single whole number"):
        covmat_nswn(1.0, [3, 4])
    with pytest.raises(ValueError, match="phi must be a single number"):
        covmat_ar1blocks(10, 5, [0.5, 0.6], 1.0)
