"""Tests of avar.datasets: the five IMU Allan variance data sets of R avar 0.1.3.

The files are read from AVAR_DATA_DIR (set by conftest.py to ../shared/data);
the download path is exercised with a local file:// source, never the network.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import rdata

from avar import datasets
from avar.estimate import n_differences
from avar.results import AllanVariance, ImuAllanVariance

GYRO, ACCEL = "Gyroscope", "Accelerometer"
DATA_DIR = Path(os.environ["AVAR_DATA_DIR"])

# name -> (sensor, freq, n, gyro channels, accel channels, levels)
EXPECTED = {
    "adis_av": ("ADIS 16405 IMU 100 Hz", 100.0, 1_000_000, 3, 3, 18),
    "imar_av": ("IMAR", 400.0, 5_760_000, 3, 0, 21),
    "kvh1750_av": ("KVH 1750 IMU", 1000.0, 1_000_000, 3, 3, 18),
    "ln200_av": ("LN200", 400.0, 8_640_000, 3, 3, 22),
    "navchip_av": ("NAVCHIP_FLT", 250.0, 3_105_250, 3, 3, 20),
}


def raw(name: str) -> dict:
    """The R object exactly as rdata reads it."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Missing constructor", category=UserWarning)
        return rdata.read_rda(DATA_DIR / f"{name}.rda")[name]


def test_list_names_descriptions_and_sources():
    table = datasets.list()
    assert isinstance(table, pd.DataFrame)
    assert table["name"].tolist() == list(EXPECTED)
    assert list(table.columns) == ["name", "description", "source"]
    assert table["description"].str.len().gt(10).all()
    sources = dict(zip(table["name"], table["source"]))
    assert "Calgary" in sources["adis_av"] and "Calgary" in sources["kvh1750_av"]
    assert all("EPFL" in sources[name] for name in ("imar_av", "ln200_av", "navchip_av"))


def test_navchip_metadata():
    nav = datasets.load("navchip_av")
    assert isinstance(nav, ImuAllanVariance)
    assert nav.sensor == "NAVCHIP_FLT"
    assert nav.freq == 250.0
    assert nav.n == 3_105_250 and isinstance(nav.n, int)
    assert tuple(nav.channels) == ("Gyro. X", "Gyro. Y", "Gyro. Z", "Accel. X", "Accel. Y", "Accel. Z")
    assert nav.axes == ("X", "Y", "Z") * 2
    gyro_x = nav["Gyro. X"]
    assert len(gyro_x) == 20
    assert gyro_x.levels[0] == 0.008
    np.testing.assert_array_equal(gyro_x.averaging_factors, 2 ** np.arange(1, 21))
    assert nav.type == "mo"


@pytest.mark.parametrize("name", list(EXPECTED))
def test_each_data_set_loads_with_its_channels(name):
    sensor, freq, n, n_gyro, n_accel, n_levels = EXPECTED[name]
    res = datasets.load(name)
    assert (res.sensor, res.freq, res.n) == (sensor, freq, n)
    assert res.sensor_types == (GYRO,) * n_gyro + (ACCEL,) * n_accel
    assert len(res) == n_gyro + n_accel
    for channel, av in res.channels.items():
        assert isinstance(av, AllanVariance)
        assert av.name == channel
        assert (av.freq, av.n, av.type) == (freq, n, "mo")
        assert len(av) == n_levels


@pytest.mark.parametrize("name", list(EXPECTED))
def test_fields_equal_the_r_object(name):
    obj = raw(name)
    res = datasets.load(name)
    assert res.sensor_types == tuple(obj["type"])
    assert res.axes == tuple(obj["axis"])
    assert list(res.channels) == [str(k) for k in obj["avar"]]
    freq = float(obj["freq"][0])
    n = int(obj["n"][0])
    for key, stored in obj["avar"].items():
        av = res[str(key)]
        np.testing.assert_array_equal(av.levels, stored["levels"])
        np.testing.assert_array_equal(av.allan, stored["allan"])
        np.testing.assert_array_equal(av.errors, stored["errors"])
        factors = np.round(stored["levels"] * freq).astype(np.int64)
        np.testing.assert_array_equal(av.averaging_factors, factors)
        np.testing.assert_allclose(av.levels * freq, factors, rtol=1e-12)
        np.testing.assert_array_equal(av.n_differences, n_differences(n, factors, "mo"))
        # stored adev / lci / uci are what AllanVariance derives
        np.testing.assert_allclose(av.adev, stored["adev"], rtol=1e-12, atol=0)
        np.testing.assert_allclose(av.lci, stored["lci"], rtol=1e-12, atol=0)
        np.testing.assert_allclose(av.uci, stored["uci"], rtol=1e-12, atol=0)
        np.testing.assert_allclose(av.adev, np.sqrt(stored["allan"]), rtol=1e-12, atol=0)
        np.testing.assert_allclose(av.lci, stored["adev"] * (1 - 2 * stored["errors"]), rtol=1e-12, atol=0)
        np.testing.assert_allclose(av.uci, stored["adev"] * (1 + 2 * stored["errors"]), rtol=1e-12, atol=0)


def test_files_without_per_channel_freq_are_complete():
    obj = raw("adis_av")
    assert all("freq" not in record for record in obj["avar"].values())
    res = datasets.load("adis_av")
    assert all(av.freq == 100.0 for av in res.channels.values())
    assert res["Accel. Z"].levels[0] == 0.02


def test_unknown_name():
    with pytest.raises(ValueError, match=r"unknown data set 'nav_av'; available: adis_av, imar_av"):
        datasets.load("nav_av")
    with pytest.raises(TypeError, match="must be a string"):
        datasets.load(3)


def test_sha256_constants_match_the_shipped_files():
    for name, digest in datasets.SHA256.items():
        assert hashlib.sha256((DATA_DIR / f"{name}.rda").read_bytes()).hexdigest() == digest


# --- where the files come from ----------------------------------------------------


@pytest.fixture
def corrupted_source(tmp_path):
    """A copy of the data directory whose navchip file has one byte changed."""
    source = tmp_path / "source"
    shutil.copytree(DATA_DIR, source)
    for path in source.iterdir():
        path.chmod(0o644)
    target = source / "navchip_av.rda"
    content = bytearray(target.read_bytes())
    content[-1] ^= 0xFF
    target.write_bytes(bytes(content))
    return source


@pytest.fixture
def download_env(tmp_path, monkeypatch):
    """No AVAR_DATA_DIR, an empty cache, AVAR_DATA_URL a file:// URL of the shipped data."""
    monkeypatch.delenv("AVAR_DATA_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setattr(datasets.sys, "platform", "linux")
    monkeypatch.setenv("AVAR_DATA_URL", DATA_DIR.as_uri())
    return tmp_path / "cache" / "avar"


def test_data_dir_checksum_mismatch(corrupted_source, monkeypatch):
    monkeypatch.setenv("AVAR_DATA_DIR", str(corrupted_source))
    with pytest.raises(datasets.ChecksumError, match="expected ea92f118"):
        datasets.load("navchip_av")
    assert datasets.load("imar_av").sensor == "IMAR"


def test_data_dir_missing_file(tmp_path, monkeypatch):
    monkeypatch.setenv("AVAR_DATA_DIR", str(tmp_path))
    with pytest.raises(FileNotFoundError, match="no file navchip_av.rda"):
        datasets.load("navchip_av")


def test_cache_dir_default(monkeypatch, tmp_path):
    monkeypatch.setattr(datasets.sys, "platform", "linux")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert datasets.cache_dir() == tmp_path / "avar"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert datasets.cache_dir() == tmp_path / ".cache" / "avar"


def test_default_url_is_upstream():
    assert datasets.DEFAULT_DATA_URL == "https://raw.githubusercontent.com/SMAC-Group/avar/master/data/"
    assert datasets.UPSTREAM_REF_MASTER == "master"


def test_download_on_first_use_then_cache(download_env, monkeypatch):
    cache = download_env
    res = datasets.load("navchip_av")
    assert res.sensor == "NAVCHIP_FLT"
    cached = cache / "navchip_av.rda"
    assert cached.read_bytes() == (DATA_DIR / "navchip_av.rda").read_bytes()
    assert [p.name for p in cache.iterdir()] == ["navchip_av.rda"]
    # the second load reads the cache: the source is no longer needed
    monkeypatch.setenv("AVAR_DATA_URL", (cache.parent / "nowhere").as_uri())
    assert datasets.load("navchip_av").n == 3_105_250


def test_download_checksum_mismatch_is_not_kept(download_env, corrupted_source, monkeypatch):
    monkeypatch.setenv("AVAR_DATA_URL", corrupted_source.as_uri() + "/")
    with pytest.raises(datasets.ChecksumError, match="the download file://.*navchip_av.rda has SHA-256"):
        datasets.load("navchip_av")
    assert not download_env.exists() or list(download_env.iterdir()) == []


def test_corrupt_cache_entry_is_downloaded_again(download_env):
    download_env.mkdir(parents=True)
    (download_env / "imar_av.rda").write_bytes(b"not an rda file")
    assert datasets.load("imar_av").sensor == "IMAR"
    assert (download_env / "imar_av.rda").read_bytes() == (DATA_DIR / "imar_av.rda").read_bytes()


def test_download_failure(download_env, tmp_path, monkeypatch):
    monkeypatch.setenv("AVAR_DATA_URL", (tmp_path / "missing").as_uri())
    with pytest.raises(OSError, match="could not download data set 'ln200_av'"):
        datasets.load("ln200_av")
    assert not (download_env / "ln200_av.rda").exists()
