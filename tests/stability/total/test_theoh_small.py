"""ThêoH's bias factor kf by its NumPy twin (:mod:`avar.stability.total.small_theobr`) against the compiled kernels."""

import numpy as np
import pytest

import avar
from avar._kernels.runtime.paths import forced
from avar._kernels.total.theobr import oavar_sums
from avar._kernels.total.windows import theo1_sum
from avar.stability.total import small_theobr, theobr

RNG = np.random.default_rng(3939)
N = 3001
WHITE = RNG.standard_normal(N)
FREQ = np.fft.rfftfreq(2 * N)
FREQ[0] = 1.0
FLICKER = np.fft.irfft((RNG.standard_normal(FREQ.size) + 1j * RNG.standard_normal(FREQ.size)) / np.sqrt(FREQ))[:N]
#: Frequency data (theoh's default data_type) of each noise.
FREQUENCY = {"white PM": np.diff(WHITE), "white FM": WHITE, "flicker FM": FLICKER,
             "random-walk FM": np.cumsum(WHITE), "offset": WHITE * 1e-3 + 5e9}


def _detrended(x: np.ndarray) -> np.ndarray:
    t = np.arange(x.size)
    return x - np.polyval(np.polyfit(t, x, 1), t)


@pytest.mark.parametrize("name", sorted(FREQUENCY))
@pytest.mark.parametrize("size", [N - 1, N - 2, 18, 19, 24, 101])
def test_theoh_numpy_equals_compiled(name, size):
    """Both paths on the same data (N even and odd, down to MIN_THEOBR_POINTS phase points)."""
    y = FREQUENCY[name][:size]
    taus = "all" if size < 200 else "octave"
    with forced("numpy"):
        twin = avar.theoh(y, taus=taus)
    with forced("compiled"):
        kernel = avar.theoh(y, taus=taus)
    assert twin.averaging_factors.tolist() == kernel.averaging_factors.tolist()
    np.testing.assert_allclose(twin.deviation, kernel.deviation, rtol=1e-9, atol=0)


@pytest.mark.parametrize("name", sorted(FREQUENCY))
def test_kf_twin_equals_kernels_and_definition(name):
    """kf's terms by the twin, by the kernels, and (every 37th) by the direct sums."""
    x = _detrended(np.concatenate(([0.0], np.cumsum(FREQUENCY[name]))))
    terms = theobr.twin_terms(x)
    assert terms is not None  # these records are well-conditioned: the twin answers
    kernel, n = theobr.theobr_terms(x)
    assert n == theobr.theobr_count(x.size) == terms.size - 1
    np.testing.assert_allclose(terms, kernel, rtol=1e-8, atol=0)
    with forced("numpy"):
        kf_twin = theobr.theobr_factor(x)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    assert kf_twin.n == kf_kernel.n == n
    assert kf_twin.kf == pytest.approx(kf_kernel.kf, rel=theobr.KF_TOLERANCE)
    no_gaps = np.zeros(0, dtype=np.int64)
    for i in range(0, n + 1, 37):
        m_avar, m_theo = 9 + 3 * i, 12 + 4 * i
        avar_i = oavar_sums(x, np.array([m_avar]))[0] / (2.0 * m_avar**2 * (x.size - 2 * m_avar))
        theo_i = theo1_sum(x, m_theo, no_gaps, 0).total / (0.75 * (x.size - m_theo) * m_theo**2)
        assert terms[i] == pytest.approx(avar_i / theo_i, rel=1e-9)


def test_ill_conditioned_kf_falls_back_to_the_kernels():
    """A phase far from zero: the expanded sums cancel, the twin declines and the kernels' kf is used."""
    x = np.cumsum(WHITE[:600]) + 1e9
    assert theobr.twin_terms(x) is None
    with forced("numpy"):
        kf_twin = theobr.theobr_factor(x)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    assert kf_twin == kf_kernel


def test_triangle_products_follow_their_definitions():
    """The FFT recursions with NumPy leaves against plain loops (several leaf levels)."""
    y, f, g = RNG.standard_normal((3, 700))
    kappa = RNG.standard_normal(1400)
    count = 600
    hankel = [sum(y[i] * kappa[k + i] for i in range(k)) for k in range(count)]
    np.testing.assert_allclose(small_theobr.hankel_lower(y, kappa, count), hankel, rtol=1e-10, atol=1e-11)
    half = [sum(f[a] * g[m - a] for a in range(0, m // 2 + 1) if m - a < 700) for m in range(count)]
    np.testing.assert_allclose(small_theobr.half_convolution(f, g, count), half, rtol=1e-10, atol=1e-11)
