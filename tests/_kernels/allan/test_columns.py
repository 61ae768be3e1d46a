"""The streaming kernel entry point against a plain loop and exact rational arithmetic."""

from __future__ import annotations

from fractions import Fraction

import numba
import numpy as np
import pytest

from avar._kernels import streaming_allan_variance as allan_variance_columns


def loop_reference(x, m: int, type: str) -> float:
    """The estimator formulas as plain loops over cluster means (float64)."""
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    if type == "mo":
        starts = range(n - 2 * m + 1)
        d = [x[t + m : t + 2 * m].sum() / m - x[t : t + m].sum() / m for t in starts]
    else:
        k = n // m
        means = [x[j * m : (j + 1) * m].sum() / m for j in range(k)]
        d = [means[j + 1] - means[j] for j in range(k - 1)]
    return float(np.sum(np.square(d)) / (2 * len(d)))


def exact(values, factors, type: str) -> list[float]:
    """AV in exact rationals over the exact values (Python ints or float64 as Fractions)."""
    v = [Fraction(int(a)) if isinstance(a, (int, np.integer)) else Fraction(float(a)) for a in values]
    s = [Fraction(0)]
    for a in v:
        s.append(s[-1] + a)
    n = len(v)
    out = []
    for m in factors:
        m = int(m)
        starts = range(n - 2 * m + 1) if type == "mo" else range(0, (n // m - 1) * m, m)
        total = sum((s[b + 2 * m] - 2 * s[b + m] + s[b]) ** 2 for b in starts)
        out.append(float(total / (2 * m * m * len(starts))))
    return out


def octave(n):
    return 2 ** np.arange(1, n.bit_length() - 1, dtype=np.int64)


def adversarial(n=6000):
    rng = np.random.default_rng(2024)
    t = np.arange(n)
    return {
        "offset": 1e6 + 1e-3 * rng.standard_normal(n),
        "drift": 1e-3 * t + 1e-6 * rng.standard_normal(n),
        "random walk": np.cumsum(rng.standard_normal(n)),
    }


@pytest.mark.parametrize("name", ["offset", "drift", "random walk"])
@pytest.mark.parametrize("type", ["mo", "to"])
def test_exact_on_adversarial_inputs(name, type):
    x = adversarial()[name]
    factors = np.array([1, 2, 3, 4, 7, 16, 100, 1000, 2048, 2999], dtype=np.int64)
    got = allan_variance_columns(x[:, None], factors, type)[0]
    np.testing.assert_allclose(got, exact(x, factors, type), rtol=1e-10, atol=0)


@pytest.mark.parametrize("type", ["mo", "to"])
def test_long_series_crosses_blocks_and_tasks_exactly(type):
    # Beyond NEAR and one task of CHUNK_BLOCKS blocks: region buffers and carried states.
    n = 600_000
    x = 1e6 + 1e-3 * np.random.default_rng(5).standard_normal(n)
    factors = np.array([2, 4096, 5000, 8192, 50_000, 131_072, 299_999], dtype=np.int64)
    got = allan_variance_columns(x[:, None], factors, type)[0]
    # Integer image of the data (the float64 values are multiples of 2**-33 here).
    scaled = np.round((x - 1e6) * 2.0**33).astype(np.int64)
    assert np.array_equal(scaled / 2.0**33 + 1e6, x)
    s = np.concatenate(([0], np.cumsum(scaled).astype(object)))
    for k, m in enumerate(map(int, factors)):
        b = np.arange(n - 2 * m + 1) if type == "mo" else np.arange(n // m - 1) * m
        d = s[b + 2 * m] - 2 * s[b + m] + s[b]
        want = float(Fraction(int(np.sum(d * d)), 2 * m * m * b.size * 2**66))
        assert got[k] == pytest.approx(want, rel=1e-10)


@pytest.mark.parametrize("n", [4, 5, 7, 33])
@pytest.mark.parametrize("type", ["mo", "to"])
def test_tiny_series_every_scale_matches_loop(n, type):
    x = np.random.default_rng(n).standard_normal(n) * 3 + 1
    factors = np.arange(1, n // 2 + 1, dtype=np.int64)
    got = allan_variance_columns(x[:, None], factors, type)[0]
    np.testing.assert_allclose(got, [loop_reference(x, m, type) for m in factors], rtol=1e-12)


# every kind (float, signed and unsigned, the narrowest and the widest; numba compiles each one, some
# 2 s a dtype on a cold cache, so the middle widths are left to the octave kernels' own dtype test)
@pytest.mark.parametrize("dtype", [np.float32, np.int8, np.int16, np.int64, np.uint16, np.uint64])
@pytest.mark.parametrize("type", ["mo", "to"])
def test_dtypes_are_exact(dtype, type):
    rng = np.random.default_rng(3)
    if np.dtype(dtype).kind == "f":
        x = (rng.standard_normal(3000) * 100).astype(dtype)
    else:
        info = np.iinfo(dtype)
        x = rng.integers(info.min, info.max, size=3000, dtype=dtype, endpoint=True)
    factors = np.array([1, 2, 5, 64, 1000, 1500], dtype=np.int64)
    got = allan_variance_columns(x[:, None], factors, type)[0]
    values = x.tolist()
    np.testing.assert_allclose(got, exact(values, factors, type), rtol=1e-12)


@pytest.mark.parametrize("dtype", [np.int64, np.uint64])
@pytest.mark.parametrize("type", ["mo", "to"])
def test_full_range_64_bit_integers(dtype, type):
    if dtype == np.int64:
        x = np.array([2**63 - 1, -(2**63), 0, 5, 2**62, -(2**62)] * 4, dtype=np.int64)
    else:
        x = np.array([2**64 - 1, 0, 2**63, 5, 2**62, 1] * 4, dtype=np.uint64)
    factors = np.arange(1, 13, dtype=np.int64)
    got = allan_variance_columns(x[:, None], factors, type)[0]
    # exact up to the final float64 roundings (sum of D**2, division): zeros are exact zeros
    np.testing.assert_allclose(got, exact([int(v) for v in x], factors, type), rtol=1e-15, atol=0)


def test_layouts_slices_and_memmap_agree(tmp_path):
    rng = np.random.default_rng(4)
    base = np.cumsum(rng.standard_normal((20_000, 3)), axis=0)
    factors = octave(20_000)
    for type in ("mo", "to"):
        want = np.stack([allan_variance_columns(np.ascontiguousarray(base[:, c]), factors, type)[0] for c in range(3)])
        np.testing.assert_array_equal(allan_variance_columns(base, factors, type), want)
        np.testing.assert_array_equal(allan_variance_columns(np.asfortranarray(base), factors, type), want)
        np.testing.assert_array_equal(allan_variance_columns(base[:, 1:], factors, type), want[1:])
        path = tmp_path / f"x_{type}.npy"
        np.save(path, base)
        mapped = np.load(path, mmap_mode="r")
        np.testing.assert_array_equal(allan_variance_columns(mapped, factors, type), want)


def test_unsorted_and_invalid_factors():
    x = np.random.default_rng(6).standard_normal(100)
    got = allan_variance_columns(x, np.array([8, 2, 0, 51, 4]), "mo")[0]
    np.testing.assert_allclose(got[[0, 1, 4]], [loop_reference(x, m, "mo") for m in (8, 2, 4)], rtol=1e-12)
    assert np.isnan(got[2]) and np.isnan(got[3])


def test_overflow_is_returned_not_raised():
    got = allan_variance_columns(np.array([1e300, -1e300, 1e300, -1e300, 1e300]), np.array([1]), "mo")
    assert np.isinf(got[0, 0])
    np.testing.assert_allclose(
        allan_variance_columns(np.array([1e150, -1e150, 1e150, -1e150, 1e150]), np.array([1]), "mo"), [[2e300]]
    )


@pytest.mark.parametrize("type", ["mo", "to"])
def test_bits_do_not_depend_on_thread_count(type):
    x = np.cumsum(np.random.default_rng(7).standard_normal((1_200_000, 2)), axis=0)
    factors = octave(1_200_000)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = allan_variance_columns(x, factors, type)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = allan_variance_columns(x, factors, type)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, two)
