"""The octave kernels (Haar pyramid "to", cache-blocked sweep "mo") and the small path.

Each is run with tiny blocks and tasks so that a few thousand samples cross
every boundary (blocks, window slides, regions, tasks, upper pyramid
levels), and checked against exact rational arithmetic and a plain loop.
"""

from __future__ import annotations

from fractions import Fraction

import numba
import numpy as np
import pytest

from avar._kernels.allan import columns
from avar._kernels.allan.small import small_allan_variance
from tests._support.reference import allan_mo_loop, allan_to_loop


def exact(values, factors, type: str) -> list[float]:
    """AV in exact rationals over the exact values (Python ints, or float64 as Fractions)."""
    ints = [int(v) if isinstance(v, (int, np.integer)) else Fraction(float(v)) for v in values]
    s = [Fraction(0)]
    for v in ints:
        s.append(s[-1] + v)
    n = len(ints)
    out = []
    for m in map(int, factors):
        starts = range(n - 2 * m + 1) if type == "mo" else range(0, (n // m - 1) * m, m)
        total = sum((s[b + 2 * m] - 2 * s[b + m] + s[b]) ** 2 for b in starts)
        out.append(float(total / (2 * m * m * len(starts))))
    return out


def loop_reference(x, m, type):
    return allan_mo_loop(x, m) if type == "mo" else allan_to_loop(x, m)


def octave(n, first=1):
    return 2 ** np.arange(first, n.bit_length() - 1, dtype=np.int64)


def adversarial(n):
    rng = np.random.default_rng(99)
    t = np.arange(n)
    step = np.where(t < n // 3, 1e6, -1e6) + 1e-3 * rng.standard_normal(n)
    return {
        "offset": 1e6 + 1e-3 * rng.standard_normal(n),
        "drift": 1e-3 * t + 1e-6 * rng.standard_normal(n),
        "random walk": np.cumsum(rng.standard_normal(n)),
        "step": step,
    }


def n_diff(n, factors, type):
    return n - 2 * factors + 1 if type == "mo" else n // factors - 1


def run(x, factors, type, **tiny):
    data = np.asarray(x)[:, None] if np.ndim(x) == 1 else x
    nd = n_diff(data.shape[0], factors, type)
    if type == "mo":
        return columns.run_sweep(data, factors, nd, **tiny)
    return columns.run_haar(data, factors, nd, **tiny)


TINY = {"mo": dict(block=64, near=256, chunk=3, fine=16), "to": dict(exp=5, chunk=3)}


@pytest.mark.parametrize("name", ["offset", "drift", "random walk", "step"])
@pytest.mark.parametrize("type", ["mo", "to"])
def test_octave_kernels_exact_on_adversarial_inputs(name, type):
    n = 3000
    x = adversarial(n)[name]
    factors = octave(n, first=0)
    got = run(x, factors, type, **TINY[type])[0]
    np.testing.assert_allclose(got, exact(x, factors, type), rtol=1e-10, atol=0)


@pytest.mark.parametrize("type", ["mo", "to"])
def test_octave_kernels_on_grids_with_gaps_and_one_level(type):
    n = 3001
    x = adversarial(n)["random walk"]
    for factors in (np.array([1, 4, 64, 256, 1024]), np.array([128]), np.array([2, 1024])):
        got = run(x, factors.astype(np.int64), type, **TINY[type])[0]
        np.testing.assert_allclose(got, [loop_reference(x, m, type) for m in factors], rtol=1e-11)


@pytest.mark.parametrize(
    "dtype", [np.float32, np.int8, np.int32, np.int64, np.uint16, np.uint64]
)
@pytest.mark.parametrize("type", ["mo", "to"])
def test_octave_kernels_read_every_dtype_exactly(dtype, type):
    rng = np.random.default_rng(3)
    n = 1100
    if np.dtype(dtype).kind == "f":
        x = (rng.standard_normal(n) * 100).astype(dtype)
    else:
        info = np.iinfo(dtype)
        x = rng.integers(info.min, info.max, size=n, dtype=dtype, endpoint=True)
    factors = octave(n, first=0)
    got = run(x, factors, type, **TINY[type])[0]
    np.testing.assert_allclose(got, exact(x.tolist(), factors, type), rtol=1e-12)


@pytest.mark.parametrize("type", ["mo", "to"])
def test_octave_kernels_extreme_magnitudes_are_rescaled(type):
    x = adversarial(2000)["random walk"]
    factors = octave(2000)
    want = run(x, factors, type, **TINY[type])
    for scale in (2.0**450, 2.0**-450):  # beyond 2**+-400: the kernels rescale by a power of two
        np.testing.assert_allclose(run(x * scale, factors, type, **TINY[type]) / scale / scale, want, rtol=1e-13)


@pytest.mark.parametrize("type", ["mo", "to"])
def test_default_parameters_match_the_level_by_level_path(type, tmp_path):
    # Above the small path: default blocks and tasks, two columns, a memmap.
    rng = np.random.default_rng(8)
    x = np.cumsum(rng.standard_normal((300_001, 2)), axis=0) + 1e4
    factors = octave(300_001)
    nd = n_diff(300_001, factors, type)
    want = columns.run_levels(x, factors, nd, type == "mo")
    got = columns.allan_variance_columns(x, factors, type)
    np.testing.assert_allclose(got, want, rtol=1e-12)
    path = tmp_path / "x.npy"
    np.save(path, x)
    np.testing.assert_array_equal(columns.allan_variance_columns(np.load(path, mmap_mode="r"), factors, type), got)
    single = columns.allan_variance_columns(np.ascontiguousarray(x[:, 1]), factors, type)
    np.testing.assert_array_equal(single[0], got[1])


@pytest.mark.parametrize("type", ["mo", "to"])
def test_octave_kernels_bits_do_not_depend_on_thread_count(type):
    x = np.cumsum(np.random.default_rng(7).standard_normal((40_000, 2)), axis=0)
    factors = octave(40_000)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = run(x, factors, type, **TINY[type])
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = run(x, factors, type, **TINY[type])
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, two)


@pytest.mark.parametrize("type", ["mo", "to"])
def test_small_path_matches_loop_on_every_scale(type):
    x = adversarial(301)["step"]
    factors = np.arange(1, 151, dtype=np.int64)
    got = small_allan_variance(columns._as_kernel_input(x), factors, n_diff(301, factors, type), type == "mo", False)[0]
    np.testing.assert_allclose(got, exact(x, factors, type), rtol=1e-10)


@pytest.mark.parametrize("n", [5, 300, 40_000, 300_000])  # small path, on threads, sweep / pyramid / levels
@pytest.mark.parametrize("type", ["mo", "to"])
def test_non_finite_values_are_found_by_the_kernel_pass(type, n, monkeypatch):
    """No up-front scan: a NaN or infinity anywhere (also in a tail no "to" cluster covers)
    makes the kernels' centre non-finite, and the error names its index, on every path."""
    import avar

    monkeypatch.setattr(columns, "SMALL_MO_MAX", 1 << 18)  # 300,000 samples take the sweep and levels

    for taus in ("octave", [2.0] if n < 10 else [3.0, 6.0, 7.0]):
        for position in (0, n // 2, n - 1):
            for value, label in ((np.inf, r"0 NaN, 1 inf"), (np.nan, r"1 NaN, 0 inf")):
                x = np.zeros(n, dtype=np.float32 if position else np.float64)
                x[position] = value
                with pytest.raises(ValueError, match=rf"1 non-finite value\(s\) \({label}\); the first is at index {position}"):
                    avar.avar(x, type=type, taus=taus)


def test_certified_plain_sums_are_taken_only_when_provably_accurate():
    """White noise takes the plain float64 sums (equal to the compensated ones to 1e-13); an
    offset far above the noise, a drift or a random walk fail the bound and take the
    compensated path, so the result stays exact."""
    from avar._kernels.allan.blocks import certified_squares, fill_prefix, plain_squares, squares

    n, m = 5000, 4
    for name, x, plain_expected in [("white", np.random.default_rng(5).standard_normal(n), True),
                                    *[(k, v, False) for k, v in adversarial(n).items() if k != "offset"]]:
        data = x[:, None]
        hi, lo, bounds = np.empty(n + 1), np.empty(n + 1), np.zeros(2)
        fill_prefix(data, 0, 0, n, float(np.mean(x)), 1.0, 0.0, 0.0, hi, lo, 0, bounds)
        count = n + 1 - 2 * m
        got = certified_squares(hi, lo, 0, m, count, np.empty(0), bounds)
        compensated = squares(hi, lo, 0, hi, lo, m, hi, lo, 2 * m, count, np.empty(count))
        assert (got == plain_squares(hi, 0, m, count)) == plain_expected, name
        assert got == pytest.approx(compensated, rel=1e-13), name
        assert got / (2.0 * m * m * count) == pytest.approx(exact(x, [m], "mo")[0], rel=1e-10), name


@pytest.mark.parametrize("name", ["white", "offset", "drift", "random walk", "step"])
def test_small_path_on_threads_is_exact_and_thread_independent(name):
    """The small path with the levels shared among the threads (N up to SMALL_MO_MAX)."""
    from avar._kernels.allan.small import small_allan_variance_parallel

    n = columns.SMALL_MAX + 1001
    x = np.random.default_rng(8).standard_normal(n) if name == "white" else adversarial(n)[name]
    factors = octave(n, first=0)
    nd = n_diff(n, factors, "mo")
    got = small_allan_variance_parallel(x[:, None], factors, nd, True, False)[0]
    np.testing.assert_array_equal(got, small_allan_variance(columns._as_kernel_input(x), factors, nd, True, False)[0])
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        np.testing.assert_array_equal(small_allan_variance_parallel(x[:, None], factors, nd, True, False)[0], got)
    finally:
        numba.set_num_threads(threads)
    picks = factors[[0, 5, -1]]
    np.testing.assert_allclose(got[[0, 5, -1]], exact(x, picks, "mo"), rtol=1e-10)


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int64, np.int16])
@pytest.mark.parametrize("count", [1, 5, 31, 32, 100, 1000])
def test_sweep_steps_and_chained_squares_match_exact_arithmetic(dtype, count):
    """The sweep's large levels: steps ``x[t+2m] - 2 x[t+m] + x[t]`` rounded once, and the sum of
    the squares of the running ``D`` they drive (started from an exact ``D_0``), against
    Fractions, on an offset far above the noise (where a prefix-sum method would cancel)."""
    from avar._kernels.allan.far_steps import chained_squares, second_differences

    rng = np.random.default_rng(count)
    n, m, t0 = 3 * 4096, 1024, 37
    if np.dtype(dtype).kind == "f":
        x = (1e6 + rng.standard_normal(n)).astype(dtype)
    else:
        info = np.iinfo(dtype)
        x = rng.integers(info.min // 2, info.max // 2, size=n, dtype=dtype)
    data = x[:, None]
    steps = np.full(count, np.nan)
    second_differences(data.T, 0, t0, m, count, 1.0, steps)
    v = [Fraction(int(a)) if np.dtype(dtype).kind == "i" else Fraction(float(a)) for a in x]
    exact_steps = [v[t0 + i + 2 * m] - 2 * v[t0 + i + m] + v[t0 + i] for i in range(count - 1)]
    np.testing.assert_allclose(steps[: count - 1], [float(g) for g in exact_steps], rtol=2**-52, atol=0)
    assert steps[count - 1] == 0.0
    d0 = sum(v[t0 + 2 * m - j] for j in range(1, m + 1)) - sum(v[t0 + m - j] for j in range(1, m + 1))
    d, want = d0, Fraction(0)
    for i in range(count):
        want += d * d
        d += exact_steps[i] if i < count - 1 else 0
    got = chained_squares(float(d0), steps, count)
    assert got == pytest.approx(float(want), rel=1e-12)


@pytest.mark.parametrize("name", ["white", "offset", "drift", "random walk", "step"])
def test_far_levels_exact_with_local_prefixes_exact_steps_or_either(name):
    """The large levels (residue classes, pieces of ``fine`` samples): exact against Fractions
    whether every piece keeps its plain local prefixes (tol = inf), takes the once-rounded
    steps (tol = 0) or is certified piece by piece (the default)."""
    n = 3000
    x = np.random.default_rng(4).standard_normal(n) if name == "white" else adversarial(n)[name]
    factors = np.array([1, 2, 256, 512, 1024], dtype=np.int64)  # near=256: three large levels
    want = exact(x, factors, "mo")
    for tol in (np.inf, 0.0, None):
        extra = {} if tol is None else {"tol": tol}
        for span in (2, 512):  # span=2: the large levels in groups of two and one
            got = run(x, factors, "mo", **TINY["mo"], **extra, span=span)[0]
            np.testing.assert_allclose(got, want, rtol=1e-10, atol=0, err_msg=f"tol={tol}, span={span}")


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int16])
@pytest.mark.parametrize("name", ["white", "offset", "drift", "random walk", "step", "periodic"])
def test_local_prefixes_err_within_their_certified_bound(name, dtype):
    """Every value of a plain local prefix (against Fractions) is within
    :func:`prefix_error_bound`, and each level's sum of squares of the differences built from
    three of them, three levels in one fused pass (m, 2m, 4m: five prefixes), is within the
    bound :func:`certified` derives from :func:`difference_error_bound`. Noise is certified,
    also on a large offset (the prefixes are of the centred samples); a period dividing ``m``
    far above the noise is not (``D`` is then only the noise), so such pieces take the
    once-rounded steps."""
    from avar._kernels.allan.blocks import CERTIFY_TOL, certified
    from avar._kernels.allan.far import difference_error_bound, local_prefix, prefix_error_bound
    from avar._kernels.allan.far_squares import fused_squares

    n, m, t0, count = 3000, 256, 123, 500
    rng = np.random.default_rng(6)
    if name == "white":
        base = rng.standard_normal(n)
    elif name == "periodic":
        base = 1e3 * np.sin(2 * np.pi * np.arange(n) / 64) + 1e-6 * rng.standard_normal(n)
    else:
        base = adversarial(n)[name]
    x = np.round(base * 100).astype(dtype) if dtype == np.int16 else base.astype(dtype)
    centre = float(np.mean(x.astype(np.float64)))
    v = [Fraction(float(a)) for a in x]
    c = Fraction(centre)
    offsets = (0, 1, 2, 4, 8)  # the fused pass's prefixes, in units of m
    ring = np.full(len(offsets) * (count + 1), np.nan)
    errors, bigs = {}, {}
    for k, j in enumerate(offsets):
        start = t0 + j * m
        out = ring[k * (count + 1) : (k + 1) * (count + 1)]
        bigs[j] = local_prefix(x[None, :], 0, start, count, centre, 1.0, out, start)
        spread = float(np.max(np.abs(x[start : start + count].astype(np.float64) - centre)))
        errors[j] = prefix_error_bound(count, spread, bigs[j])
        exact_prefix = Fraction(0)
        for i in range(count + 1):
            assert abs(Fraction(float(out[i])) - exact_prefix) <= errors[j], (j, i)
            exact_prefix += v[start + i] - c if i < count else 0
    s = {j: sum(v[: t0 + j * m], Fraction(0)) - (t0 + j * m) * c for j in offsets}
    pairs = [(float(d), float(d - Fraction(float(d)))) for d in (s[2 * h] - 2 * s[h] + s[0] for h in (1, 2, 4))]
    bases = np.array([hi + lo for hi, lo in pairs])
    slots = np.arange(len(offsets)) * (count + 1)
    totals = np.full(3, np.nan)
    fused_squares(ring, slots, bases, 3, count, totals)
    single = np.full(1, np.nan)
    fused_squares(ring, slots, bases, 1, count, single)
    assert single[0] == pytest.approx(totals[0], rel=4 * count * 2.0**-53)  # one level alone: the same sum
    for w, h in enumerate((1, 2, 4)):
        d = s[2 * h] - 2 * s[h] + s[0]
        exact_total = Fraction(0)
        for i in range(count):
            exact_total += d * d
            d += v[t0 + i + 2 * h * m] - 2 * v[t0 + i + h * m] + v[t0 + i]
        delta = difference_error_bound(errors[0] + 2 * errors[h] + errors[2 * h], bigs[0] + 2 * bigs[h] + bigs[2 * h],
                                       pairs[w][0], pairs[w][1], 0.0)
        total = totals[w]
        bound = 2.0 * delta * np.sqrt(count * total) + count * delta**2 + 2 * count * 2.0**-53 * total
        assert abs(float(exact_total) - total) <= bound, w
        if dtype == np.float64 and name in ("white", "offset", "periodic"):
            assert certified(total, delta, count, CERTIFY_TOL) == (name != "periodic"), w


@pytest.mark.parametrize("width", range(1, 5))
def test_fused_squares_sum_each_level_of_the_pass(width):
    """Each of a fused pass's levels against its own plain sum: level ``w`` reads prefixes
    ``0``, ``w + 1`` and ``w + 2`` of the pass (the pieces at ``t``, ``t + 2**w m``, ``t + 2**(w+1) m``)."""
    from avar._kernels.allan.far_squares import fused_squares

    count, stride = 777, 800
    rng = np.random.default_rng(width)
    ring = rng.standard_normal(10 * stride) * 1e3
    slots = rng.permutation(10)[: width + 2] * stride
    bases = rng.standard_normal(8) * 1e4
    out = np.full(8, np.nan)
    fused_squares(ring, slots, bases, width, count, out)
    p = [ring[slot : slot + count] for slot in slots]
    want = [np.sum((bases[w] + (p[w + 2] - 2.0 * p[w + 1] + p[0])) ** 2) for w in range(width)]
    np.testing.assert_allclose(out[:width], want, rtol=1e-12)
    assert np.isnan(out[width:]).all()  # nothing written beyond the pass's levels


def test_far_levels_fused_four_at_a_time_end_to_end():
    """Ten far levels in one group (tiny pieces, a wide span): passes of four, four and two
    levels where every level has a full piece, shorter ones near the end of the series, against
    the loop."""
    n = 70_000
    x = adversarial(n)["random walk"]
    factors = 2 ** np.arange(0, 16, dtype=np.int64)  # 1 .. 32768; far from 64
    got = run(x, factors, "mo", block=64, near=64, chunk=3, fine=16, span=1024)[0]
    np.testing.assert_allclose(got, [allan_mo_loop(x, m) for m in factors], rtol=1e-11)


def test_second_differences_scale_extreme_samples_before_rounding():
    from avar._kernels.allan.far_steps import second_differences

    x = np.array([1e300, -1e300, 1e300, 3e300, -1e300, 2e300])[:, None]
    steps = np.empty(3)
    second_differences(x.T, 0, 0, 1, 3, 2.0**-1000, steps)
    want = [(x[i + 2, 0] * 2.0**-1000 - 2 * x[i + 1, 0] * 2.0**-1000 + x[i, 0] * 2.0**-1000) for i in range(2)]
    np.testing.assert_allclose(steps[:2], want, rtol=1e-15)
    assert np.isfinite(steps).all()


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int16])
def test_block_magnitude_is_the_largest_magnitude_or_nan(dtype):
    """The Haar pyramid's magnitude probe: max |x sc| (bit patterns for float64), NaN if a
    sample is inf or NaN, at any position (vector body and tail)."""
    from avar._kernels.allan.haar import block_magnitude

    rng = np.random.default_rng(1)
    x = (rng.standard_normal(37) * 1e3).astype(dtype)
    x[5] = -3e4 if np.dtype(dtype).kind == "f" else -30000
    assert block_magnitude(x, 0.5) == 15000.0
    assert block_magnitude(np.zeros(3, dtype=dtype), 1.0) == 0.0
    if np.dtype(dtype).kind == "f":
        for bad in (np.inf, -np.inf, np.nan):
            for position in (0, 20, 36):
                y = x.copy()
                y[position] = bad
                assert np.isnan(block_magnitude(y, 1.0)), (bad, position)


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int16])
@pytest.mark.parametrize("name", ["white", "random walk", "periodic"])
def test_exact_pieces_in_numpy_equal_the_compiled_ones(name, dtype):
    """A few marked far pieces are redone in NumPy (nothing to compile), many by the kernel:
    both take the same once-rounded steps from the same start, on pieces cut at the end too."""
    from avar._kernels.allan.far_steps import exact_pieces, numpy_pieces

    n, fine = 5000, 16
    rng = np.random.default_rng(2)
    base = {"white": rng.standard_normal(n), "random walk": np.cumsum(rng.standard_normal(n)),
            "periodic": 1e3 * np.sin(2 * np.pi * np.arange(n) / 64) + 1e-6 * rng.standard_normal(n)}[name]
    x = np.round(base * 100).astype(dtype) if dtype == np.int16 else base.astype(dtype)
    data = columns._as_kernel_input(x)
    th, tl, _, scale, _ = columns._table(data, fine)
    factors = np.array([256, 512, 1024], dtype=np.int64)
    nd = n - 2 * factors + 1
    cols, pieces, levels = np.nonzero(np.arange(-(-nd[0] // fine))[None, :, None] * fine < nd[None, None, :])
    want = np.empty(cols.size)
    exact_pieces(data.T, cols, pieces, levels, 0, cols.size, scale, th, tl, factors, nd, fine, want)
    got = numpy_pieces(data.T, cols, pieces, levels, scale, th, tl, factors, nd, fine)
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=0)
