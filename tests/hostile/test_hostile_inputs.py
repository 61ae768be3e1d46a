"""Hostile inputs: wide and strange files, time indexes, extreme magnitudes, models and Dask graphs.

Files are written and read for real; values are checked against NumPy on the
same data or against exact scaling laws (a power-of-two scale is exact).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar
from avar.stability.shared.registry import CLASSIC as CLASSIC_STATISTICS
from avar.stability.shared.registry import DEVIATION_STATISTICS
from tests._support.cli_runner import cli

RNG = np.random.default_rng(2027)
X = RNG.standard_normal(3000)


# --------------------------------------------------------------------------- files
def test_a_100_kb_header_is_read_whole_through_the_cli(tmp_path, capsys):
    """The header is 108 KB, beyond the 64 KiB sniffed: no column may be lost or mislabelled."""
    names = [f"gyroscope_channel_number_{i:05d}" for i in range(3_500)]
    values = np.random.default_rng(1).standard_normal((8, len(names))).round(4)
    path = tmp_path / "wide.csv"
    pd.DataFrame(values, columns=names).to_csv(path, index=False)
    code, _, err = cli(capsys, "compute", path, "--taus", "all", "--output", tmp_path / "o.csv")
    assert code == 0, err
    table = pd.read_csv(tmp_path / "o.csv")
    assert list(dict.fromkeys(table["Channel"])) == names
    last = table[table["Channel"] == names[-1]]["AVar"].to_numpy()
    np.testing.assert_allclose(last, avar.avar(values[:, -1], taus="all").allan, rtol=1e-12)


def test_a_headerless_10000_column_file_has_10000_columns(tmp_path):
    values = np.random.default_rng(2).standard_normal((6, 10_000)).round(3)
    path = tmp_path / "plain.csv"
    np.savetxt(path, values, delimiter=",", fmt="%.3f")
    recording = avar.read(path)
    assert len(recording.columns) == 10_000
    np.testing.assert_array_equal(recording.columns["x10000"], values[:, -1])


def test_a_70000_character_header_name_is_one_column_and_messages_stay_short(tmp_path, capsys):
    path = tmp_path / "long.csv"
    name = "g" * 70_000
    pd.DataFrame({"time": np.arange(200) / 100.0, name: X[:200], "gy": X[200:400]}).to_csv(path, index=False)
    recording = avar.read(path)
    assert list(recording.columns) == [name, "gy"]
    np.testing.assert_array_equal(recording.columns["gy"], X[200:400])
    code, _, err = cli(capsys, "compute", path, "--column", "nope")
    assert code == 1 and "'nope'" in err and len(err) < 2000
    code, stdout, err = cli(capsys, "compute", path)
    assert code == 0, err
    assert max(len(line) for line in stdout.splitlines()) < 200  # the name is cut for the terminal


@pytest.mark.parametrize("encoding", ["utf-16-le", "utf-16-be", "utf-16", "utf-32-le", "utf-32"])
def test_utf16_and_utf32_with_or_without_bom_are_read(encoding, tmp_path):
    text = "time,gx\n" + "".join(f"{i / 100!r},{float(v)!r}\n" for i, v in enumerate(X[:500]))
    path = tmp_path / "wide_chars.csv"
    path.write_bytes(text.encode(encoding))
    recording = avar.read(path)
    assert recording.freq == pytest.approx(100.0)
    np.testing.assert_array_equal(recording.columns["gx"], X[:500])


def test_binary_data_is_named_as_such(tmp_path):
    path = tmp_path / "noise.csv"
    path.write_bytes(np.arange(1024, dtype=np.float64).tobytes())  # raw doubles: zero bytes without a pattern
    with pytest.raises(ValueError, match="not a text table"):
        avar.read(path)


def test_a_line_with_more_values_than_the_header_is_refused(tmp_path):
    path = tmp_path / "extra.csv"
    path.write_text("time,gx\n" + "".join(f"{i / 10},{i}\n" for i in range(100)) + "10.0,1,2\n")
    with pytest.raises(ValueError, match=r"Expected 2 fields in line 102, saw 3|more values than the header"):
        avar.read(path)


def test_trailing_bytes_after_an_npy_array_are_refused(tmp_path, capsys):
    path = tmp_path / "tail.npy"
    np.save(path, X[:100])
    with path.open("ab") as handle:
        handle.write(X[:95].tobytes())
    code, _, err = cli(capsys, "compute", path, "--output", tmp_path / "o.csv")
    assert code == 1
    assert "760 byte(s) follow the (100,) array" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o.csv").exists()


def test_two_time_columns_with_different_rates_are_a_conflict(tmp_path, capsys):
    path = tmp_path / "clocks.csv"
    pd.DataFrame({"time": np.arange(1000) / 100.0, "timestamp": np.arange(1000) / 50.0, "gx": X[:1000]}).to_csv(
        path, index=False)
    code, _, err = cli(capsys, "compute", path)
    assert code == 1
    assert "the time columns 'time' (100 Hz) and 'timestamp' (50 Hz) disagree" in err
    assert avar.read(path, time_column="timestamp").freq == pytest.approx(50.0)
    same = tmp_path / "same.csv"  # two clocks that agree (s and ms) are no conflict
    pd.DataFrame({"time": np.arange(1000) / 100.0, "t_ms": np.arange(1000) * 10.0, "gx": X[:1000]}).to_csv(
        same, index=False)
    assert avar.read(same).freq == pytest.approx(100.0)


# --------------------------------------------------------------------------- time indexes
DEVIATIONS = [getattr(avar, name) for name in DEVIATION_STATISTICS]
#: The classic family rescales data near the float64 limits itself (the others refuse tiny data).
CLASSIC = CLASSIC_STATISTICS


@pytest.mark.parametrize("estimator", DEVIATIONS, ids=lambda f: f.__name__)
def test_every_deviation_takes_the_rate_of_a_time_index(estimator):
    series = pd.Series(X, index=pd.date_range("2026-01-01", periods=X.size, freq="10ms"))
    got, want = estimator(series), estimator(X, rate=100.0)
    np.testing.assert_array_equal(got.taus, want.taus)
    assert got.rate == 100.0 and got.taus[0] == pytest.approx(0.015 if estimator.__name__ == "theo1" else 0.01)
    np.testing.assert_allclose(got.deviation, want.deviation, rtol=1e-12)
    explicit = estimator(series, rate=1.0)  # an explicit rate wins, as freq in avar.avar
    assert explicit.rate == 1.0 and np.allclose(explicit.taus, got.taus * 100.0, rtol=1e-12, atol=0)
    gappy = pd.Series(np.delete(X, 700), index=series.index.delete(700))  # a missing sample: a 20 ms step
    with pytest.raises(ValueError, match=r"data has an irregular time index \(steps from 10000 to 20000 us\)"):
        estimator(gappy)


@pytest.mark.parametrize("estimator", DEVIATIONS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("rate, error", [(0.0, ValueError), (-2.0, ValueError), (np.inf, ValueError), ("1", TypeError)])
def test_every_deviation_names_a_bad_rate(estimator, rate, error):
    with pytest.raises(error, match="rate"):
        estimator(X[:500], rate=rate)


def test_pair_statistics_take_the_rate_of_a_time_index():
    index = pd.date_range("2026-01-01", periods=1000, freq="10ms")
    a, b = pd.Series(X[:1000], index=index), pd.Series(X[1000:2000], index=index)
    assert avar.gcodev(a, b).taus[0] == pytest.approx(0.01)
    assert avar.three_cornered_hat(a - b, b, -a, data_type="freq").a.taus[0] == pytest.approx(0.01)


def test_a_datetime64_seconds_index_with_400_year_steps():
    step = np.timedelta64(400 * 365 * 86_400, "s")
    index = pd.DatetimeIndex(np.datetime64("1000-01-01T00:00:00", "s") + step * np.arange(8))
    result = avar.avar(pd.Series(X[:8], index=index), taus="all")
    np.testing.assert_allclose(result.levels, np.array([1, 2, 3, 4]) * (step / np.timedelta64(1, "s")), rtol=1e-15)
    zoned = pd.date_range("2026-03-29", periods=X.size, freq="10ms", tz="Europe/Paris")  # tz-aware, across DST
    assert avar.avar(pd.Series(X, index=zoned)).freq == avar.oadev(pd.Series(X, index=zoned)).rate == 100.0


# --------------------------------------------------------------------------- magnitudes and bounds
@pytest.mark.filterwarnings("error::RuntimeWarning")  # an overflow is the function's error, not a stray warning
@pytest.mark.parametrize("estimator", DEVIATIONS, ids=lambda f: f.__name__)
def test_deviations_of_data_near_the_float64_limits(estimator):
    base = estimator(X[:512])
    for scale in (2.0 ** -480, 2.0 ** 480):  # squares under- or overflow; the scaled computation is exact
        got = estimator(X[:512] * scale)
        np.testing.assert_allclose(got.deviation, base.deviation * scale, rtol=1e-12)
    if estimator.__name__ not in CLASSIC:  # unscaled: tiny data are an error, huge ones overflow clearly
        if estimator.__name__ != "mtie":
            with pytest.raises(ValueError, match="data of magnitude .* is below the float64 range"):
                estimator(X[:512] * 1e-300)
        with pytest.raises(ValueError, match="overflows float64; rescale the data"):
            estimator(X[:512] * 1e300)
        return
    tiny = estimator(X[:512] * 1e-300)  # the deviation is exact; its square rounds to 0 in float64
    np.testing.assert_allclose(tiny.deviation / 1e-300, base.deviation, rtol=1e-12)
    assert np.all(tiny.variance == 0.0) and np.all(tiny.lci <= tiny.deviation)
    with pytest.raises(ValueError, match="variance of data of magnitude .* is beyond the float64 range"):
        estimator(X[:512] * 1e300)  # the deviation fits float64, its variance cannot: one clear error


def test_the_allan_variance_of_data_near_1e_300_is_an_error_not_zero():
    with pytest.raises(ValueError, match="below the float64 range"):
        avar.avar(X * 1e-300)
    assert avar.avar(np.full(64, 1e-300)).allan.max() == 0.0  # a constant is exactly 0


@pytest.mark.parametrize("confidence", [0.01, 0.1, 0.3])
def test_a_low_confidence_band_still_holds_the_deviation(confidence):
    for result in (avar.oadev(X, confidence=confidence, taus="all"),
                   avar.avar(X, ci="chi2", confidence=confidence, taus="all")):
        deviation = result.deviation if hasattr(result, "deviation") else result.adev
        assert np.all(result.lci <= deviation) and np.all(deviation <= result.uci)


def test_dr_simulation_beyond_float64_is_refused():
    with pytest.raises(ValueError, match=r"the simulation of DR\(omega=1e\+306\) overflows float64 within 1000"):
        avar.DR(omega=1e306).simulate(1000)
    np.testing.assert_array_equal(avar.DR(omega=1e300).simulate(3), [1e300, 2e300, 3e300])


@pytest.mark.parametrize("kwargs, kind, fragment", [
    (dict(model="WN + WN"), ValueError, "model has WN 2 times"),
    (dict(model=[avar.RW, avar.RW]), ValueError, "model has RW 2 times"),
    (dict(model="WN", ci=True, B=10**9), ValueError, "B = 1000000000 replicates is too many"),
    (dict(model="WN", ci=True, B=5, seed="abc"), TypeError, "seed must be None, a non-negative int"),
])
def test_gmwm_refuses_what_it_cannot_estimate(kwargs, kind, fragment):
    with pytest.raises(kind, match=None) as info:
        avar.gmwm(X, **kwargs)
    assert fragment in str(info.value) and len(str(info.value)) < 600


# --------------------------------------------------------------------------- Dask
def test_dask_many_chunks_equal_numpy():
    da = pytest.importorskip("dask.array")
    x = np.random.default_rng(5).standard_normal(1_000_000)
    got = avar.avar(da.from_array(x, chunks=1000))  # 1,000 chunks: computed once, then the NumPy kernels
    np.testing.assert_allclose(got.allan, avar.avar(x).allan, rtol=1e-12)
    tiny = avar.avar(da.from_array(x[:1024], chunks=1), taus="all")  # 1,024 chunks of one sample
    np.testing.assert_allclose(tiny.allan, avar.avar(x[:1024], taus="all").allan, rtol=1e-12)


def test_dask_unknown_chunks_all_taus_and_huge_values(monkeypatch):
    da = pytest.importorskip("dask.array")
    from avar.stability.allan import dask as dask_backend

    x = np.random.default_rng(6).standard_normal(5000)
    unknown = da.from_array(x, chunks=500)
    unknown = unknown[unknown > -np.inf]  # boolean indexing: NaN chunk sizes
    assert np.isnan(unknown.chunks[0][0])
    np.testing.assert_allclose(avar.avar(unknown, taus="all").allan, avar.avar(x, taus="all").allan, rtol=1e-12)
    # the larger-than-memory path, rechunked: 1e300 data are finite and their AV fits float64 (scaled)
    monkeypatch.setattr(dask_backend, "IN_MEMORY_BYTES", 0)
    monkeypatch.setattr(dask_backend, "MIN_CHUNK", 1000)
    huge = avar.avar(da.from_array(x * 1e150, chunks=100))
    np.testing.assert_allclose(huge.allan, avar.avar(x).allan * 1e300, rtol=1e-12)
    with pytest.raises(ValueError, match="make .* tasks, more than"):
        avar.avar(da.from_array(np.tile(x, 60), chunks=1000), taus="all")


def test_lost_workers_end_in_one_line():
    distributed = pytest.importorskip("dask.distributed")
    import os

    from avar.stability.allan.dask import WorkerLost, map_on_cluster

    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0",
                                  silence_logs=50) as cluster, distributed.Client(cluster) as client:
        import dask

        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            with pytest.raises(WorkerLost) as info:
                map_on_cluster(os._exit, [3], scheduler=client, progress=False)
    assert str(info.value).startswith("the worker process computing 3 died repeatedly")
    assert "\n" not in str(info.value)


# --------------------------------------------------------------------------- figures
def test_a_figure_of_400_series_caps_its_legend(tmp_path, capsys):
    frame = pd.DataFrame(np.random.default_rng(8).standard_normal((256, 400)),
                         columns=[f"s{i}" for i in range(400)])
    path = tmp_path / "many.csv"
    frame.to_csv(path, index=False)
    from avar.plotting.compare import plot_compare

    figure = plot_compare([avar.avar(frame[c].to_numpy()) for c in frame.columns[:400]], labels=list(frame.columns))
    texts = [t.get_text() for t in figure.axes[0].get_legend().get_texts()]
    assert len(texts) == 20 and texts[-1] == "... and 381 more (legend capped at 20)"
    assert len(figure.axes[0].lines) >= 400  # every series is drawn
    code, _, err = cli(capsys, "compute", path, "--plot", tmp_path / "many.png")
    assert code == 0, err
    assert (tmp_path / "many.png").read_bytes().startswith(b"\x89PNG")
