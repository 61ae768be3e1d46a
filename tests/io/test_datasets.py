"""Tests of avar.datasets: the five IMU Allan variance data sets of R avar 0.1.3.

The data sets ship inside the package (``avar/io/data/*.npz``). The maintainers' tests that
compare them with the R package's ``.rda`` files run when the environment variable
``AVAR_RDA_DIR`` names a folder holding those files, and are skipped otherwise.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from avar.io import datasets
from avar.stability.allan.results import AllanVariance, ImuAllanVariance
from avar.stability.shared.term_counts import n_differences

GYRO, ACCEL = "Gyroscope", "Accelerometer"
REPOSITORY = Path(__file__).resolve().parents[2]
DATA_DIR = Path(os.environ.get("AVAR_RDA_DIR", "")) if os.environ.get("AVAR_RDA_DIR") else None
needs_rda = pytest.mark.skipif(
    DATA_DIR is None or not DATA_DIR.is_dir() or importlib.util.find_spec("rdata") is None,
    reason="the R package's .rda files (folder named by AVAR_RDA_DIR) and rdata are not available",
)

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
    import rdata

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


@needs_rda
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


@needs_rda
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


def test_shipped_files_are_plain_arrays():
    """No pickles: every file loads with allow_pickle=False, one .npz per data set, small."""
    data = REPOSITORY / "src" / "avar" / "io" / "data"
    assert sorted(p.name for p in data.iterdir()) == sorted(f"{name}.npz" for name in EXPECTED)
    for name in EXPECTED:
        assert datasets.data_file(name).is_file()
        with np.load(data / f"{name}.npz", allow_pickle=False) as arrays:
            assert all(arrays[key].dtype.kind in "fiU" for key in arrays.files)
        assert (data / f"{name}.npz").stat().st_size < 20_000


def test_load_needs_no_r_reader():
    """Loading a data set imports neither rdata nor anything from the network."""
    code = (
        "import sys, avar; avar.datasets.load('ln200_av');"
        "print(sorted(m for m in ('rdata', 'urllib.request', 'http.client') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=REPOSITORY, env={"PYTHONPATH": str(REPOSITORY / "src"), "PATH": ""})
    assert out.stdout.strip() == "[]"


@needs_rda
def test_converter_reproduces_the_shipped_files(tmp_path):
    """tools/convert_datasets.py, run on the .rda files, writes exactly the shipped arrays."""
    spec = importlib.util.spec_from_file_location("convert_datasets", REPOSITORY / "tools" / "convert_datasets.py")
    convert = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(convert)
    assert convert.main([str(DATA_DIR), "--target", str(tmp_path)]) == 0
    for name in EXPECTED:
        with np.load(tmp_path / f"{name}.npz") as fresh, datasets.data_file(name).open("rb") as stream:
            shipped = np.load(stream)
            assert fresh.files == shipped.files
            for key in fresh.files:
                np.testing.assert_array_equal(fresh[key], shipped[key])
                assert fresh[key].dtype == shipped[key].dtype
