"""The Dask backend against the NumPy (streaming kernel) path."""

from __future__ import annotations

import numpy as np
import pytest

da = pytest.importorskip("dask.array")
distributed = pytest.importorskip("dask.distributed")

from avar._kernels import streaming_allan_variance as allan_variance_columns  # noqa: E402
from avar.stability.allan.dask import allan_variance_dask, allan_variance_files  # noqa: E402


def octave(n):
    return 2 ** np.arange(1, n.bit_length() - 1, dtype=np.int64)


@pytest.mark.parametrize("type", ["mo", "to"])
def test_sixteen_chunks_match_numpy_path(type):
    n = 1_000_000
    x = 1e3 + np.cumsum(np.random.default_rng(1).standard_normal(n))
    factors = np.concatenate((octave(n), [3, 1000, 77_777]))
    want = allan_variance_columns(x, factors, type)
    got = allan_variance_dask(da.from_array(x, chunks=n // 16), factors, type, min_chunk=1)
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_uneven_chunks_columns_and_invalid_factors():
    x = np.random.default_rng(2).standard_normal((5003, 2)).astype(np.float32)
    factors = np.array([1, 2, 7, 2502, 2501], dtype=np.int64)
    for type in ("mo", "to"):
        want = allan_variance_columns(x, factors, type)
        got = allan_variance_dask(da.from_array(x, chunks=(777, 2)), factors, type, min_chunk=1)
        np.testing.assert_allclose(got, want, rtol=1e-12)
        assert np.isnan(got[:, 3]).all()


def test_local_cluster_threads_and_files(tmp_path):
    rng = np.random.default_rng(3)
    paths = []
    for i in range(3):
        path = tmp_path / f"series{i}.npy"
        np.save(path, rng.standard_normal(20_000 + 1000 * i))
        paths.append(str(path))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        with distributed.Client(cluster) as client:
            x = np.load(paths[0])
            got = allan_variance_dask(da.from_array(x, chunks=3000), octave(x.size), "mo", min_chunk=1)
            np.testing.assert_allclose(got, allan_variance_columns(x, octave(x.size), "mo"), rtol=1e-12)
            results = allan_variance_files(paths, np.load, octave, "to", scheduler=client, progress=False)
    for path, (factors, allan) in zip(paths, results):
        x = np.load(path)
        np.testing.assert_array_equal(factors, octave(x.size))
        np.testing.assert_array_equal(allan, allan_variance_columns(x, factors, "to"))


def test_avar_of_a_dask_array_is_the_numpy_result():
    import avar

    x = np.random.default_rng(8).standard_normal(1_000_000)
    for type in ("mo", "to"):
        got = avar.avar(da.from_array(x, chunks=x.size // 16), type=type, freq=50.0, taus="decade")
        want = avar.avar(x, type=type, freq=50.0, taus="decade")
        np.testing.assert_allclose(got.allan, want.allan, rtol=1e-12)
        np.testing.assert_array_equal(got.levels, want.levels)
        np.testing.assert_array_equal(got.n_differences, want.n_differences)
        assert got.n == x.size and got.freq == 50.0
    y = x.copy()
    y[123_456] = np.nan
    with pytest.raises(ValueError, match=r"x has 1 non-finite value"):  # in memory: the NumPy path's check
        avar.avar(da.from_array(y, chunks=100_000))
    with pytest.raises(ValueError, match="x must be 1-D"):
        avar.avar(da.ones((100, 2), chunks=50))


@pytest.fixture(scope="module")
def ten_million():
    """A random walk of 10**7 samples (80 MB): large values, levels growing over 7 decades."""
    return np.cumsum(np.random.default_rng(9).standard_normal(10**7))


def test_larger_than_memory_path_refuses_non_finite_values_and_chi2(monkeypatch):
    import avar
    from avar.stability.allan import dask as dask_backend

    monkeypatch.setattr(dask_backend, "IN_MEMORY_BYTES", 0)  # as for a series larger than memory
    monkeypatch.setattr(dask_backend, "MIN_CHUNK", 1)
    x = np.random.default_rng(8).standard_normal(100_000)
    got = avar.avar(da.from_array(x, chunks=10_000))
    np.testing.assert_allclose(got.allan, avar.avar(x).allan, rtol=1e-12)
    y = x.copy()
    y[23_456] = np.nan
    with pytest.raises(ValueError, match=r"x \(a Dask array\) holds NaN or infinite values"):
        avar.avar(da.from_array(y, chunks=10_000))
    with pytest.raises(ValueError, match="a Dask array larger than memory takes ci='r' and nan_policy='raise'"):
        avar.avar(da.from_array(x, chunks=10_000), ci="chi2")


@pytest.mark.parametrize("type", ["mo", "to"])
def test_ten_million_samples_in_sixteen_chunks_equal_the_numpy_array(ten_million, type):
    """About 3 s per type on 2 cores (352 chunk-level tasks on the threaded scheduler)."""
    import avar

    x, n = ten_million, ten_million.size
    got = avar.avar(da.from_array(x, chunks=n // 16), type=type, taus="octave")
    want = avar.avar(x, type=type, taus="octave")
    assert got.averaging_factors.tolist() == [2**j for j in range(1, 23)]
    np.testing.assert_array_equal(got.averaging_factors, want.averaging_factors)
    np.testing.assert_array_equal(got.n_differences, want.n_differences)
    np.testing.assert_allclose(got.allan, want.allan, rtol=1e-12, atol=0)
