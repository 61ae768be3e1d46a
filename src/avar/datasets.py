"""The IMU Allan variance data sets of the R package ``avar`` 0.1.3.

Five data sets, each the maximal-overlap Allan variance of every channel of a
real inertial measurement unit, as stored by the R package:

=============  ======================================================
``adis_av``    ADIS 16405 gyroscopes and accelerometers
``imar_av``    IMAR gyroscopes
``kvh1750_av`` KVH 1750 gyroscopes and accelerometers
``ln200_av``   LN200 gyroscopes and accelerometers
``navchip_av`` NavChip gyroscopes and accelerometers
=============  ======================================================

:func:`load` returns an :class:`avar.ImuAllanVariance`; :func:`list` names
the data sets with their description and source.

Where the files come from
-------------------------
* the directory in the environment variable ``AVAR_DATA_DIR`` when it is set
  (nothing is downloaded; a missing file is an error);
* otherwise a per-user cache, ``$XDG_CACHE_HOME/avar`` or ``~/.cache/avar``
  (``%LOCALAPPDATA%\\avar`` on Windows), filled on first use by downloading
  ``<name>.rda`` from the base URL in ``AVAR_DATA_URL`` or, by default,
  :data:`DEFAULT_DATA_URL` (the ``data/`` folder of the upstream repository
  https://github.com/SMAC-Group/avar).

Every file, local or downloaded, must match the SHA-256 digest in
:data:`SHA256`: the upstream files are fetched from the branch
:data:`UPSTREAM_REF_MASTER`, not a pinned commit, so the digest is what
guarantees that the bytes are those of R ``avar`` 0.1.3. A downloaded file
that does not match raises :class:`ChecksumError` and is not kept; a cached
file that no longer matches is replaced by a fresh download.
"""

from __future__ import annotations

import hashlib
import io
import os
import sys
import tempfile
import urllib.error
import urllib.request
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from avar.estimate import check_type, n_differences
from avar.results import AllanVariance, ImuAllanVariance

#: Git ref the files are downloaded from. No commit hash could be verified
#: offline, so the branch is used and :data:`SHA256` guarantees integrity.
UPSTREAM_REF_MASTER = "master"
#: Raw-file URL template of the upstream ``data/`` folder.
DATA_URL_TEMPLATE = "https://raw.githubusercontent.com/SMAC-Group/avar/{ref}/data/"
#: Default base URL of the ``.rda`` files (override with ``AVAR_DATA_URL``).
DEFAULT_DATA_URL = DATA_URL_TEMPLATE.format(ref=UPSTREAM_REF_MASTER)
#: Environment variables: local data directory, download base URL.
DATA_DIR_ENV = "AVAR_DATA_DIR"
DATA_URL_ENV = "AVAR_DATA_URL"
#: Seconds before a download gives up.
DOWNLOAD_TIMEOUT = 60.0

#: SHA-256 of the files of R avar 0.1.3.
SHA256 = {
    "adis_av": "000a7533f73e1f848346dd4de91caded998ace37eff161900c6e3dd0fff7cbc1",
    "imar_av": "dd64f49f11ef4669f769d21f2e5754bb1b2526a97ea228143b116f77d997864b",
    "kvh1750_av": "66181ec8841f9974e3f4c2e2dafcbd15fd75af39169609ebcba01c4a66a3d9b7",
    "ln200_av": "8fa8457abcd0a41ec0ab2b9ca36b9d300d33e5eb79802b6f9f2d622cb8b56381",
    "navchip_av": "ea92f1187cc7defc400c7de3b2a430527f9143a81f63031e4667b52df85546d0",
}

_CALGARY = "Department of Geomatics Engineering, University of Calgary"
_EPFL = "Geodetic Engineering Laboratory (TOPO), Swiss Federal Institute of Technology Lausanne (EPFL)"
#: Description and source of every data set (from the R manual).
CATALOG = {
    "adis_av": ("Allan variance of gyroscope and accelerometer data from an ADIS 16405 sensor", _CALGARY),
    "imar_av": ("Allan variance of IMAR gyroscope data", _EPFL),
    "kvh1750_av": ("Allan variance of gyroscope and accelerometer data from a KVH1750 sensor", _CALGARY),
    "ln200_av": ("Allan variance of LN200 gyroscope and accelerometer data", _EPFL),
    "navchip_av": ("Allan variance of gyroscope and accelerometer data from a NavChip sensor", _EPFL),
}
NAMES = tuple(CATALOG)


class ChecksumError(ValueError):
    """A data file whose SHA-256 digest is not the expected one."""


def _check_name(name: Any) -> str:
    if not isinstance(name, str):
        raise TypeError(f"data set name must be a string, got {type(name).__name__}")
    if name not in CATALOG:
        raise ValueError(f"unknown data set {name!r}; available: {', '.join(NAMES)}")
    return name


def cache_dir() -> Path:
    """The per-user cache directory of downloaded data files."""
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"]) / "avar"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "avar"


def _verify(content: bytes, name: str, origin: str) -> None:
    digest = hashlib.sha256(content).hexdigest()
    if digest != SHA256[name]:
        raise ChecksumError(
            f"{origin} has SHA-256 {digest}, expected {SHA256[name]} for data set {name!r}; "
            "the file is corrupt or not the R avar 0.1.3 version"
        )


def _download(name: str, target: Path) -> bytes:
    """Fetch ``<name>.rda``, check its digest, then atomically write it to ``target``."""
    url = os.environ.get(DATA_URL_ENV) or DEFAULT_DATA_URL
    url = url.rstrip("/") + f"/{name}.rda"
    try:
        with urllib.request.urlopen(url, timeout=DOWNLOAD_TIMEOUT) as response:
            content = response.read()
    except (urllib.error.URLError, OSError) as error:
        raise OSError(
            f"could not download data set {name!r} from {url}: {error}. Set {DATA_DIR_ENV} to a "
            f"directory holding {name}.rda, or {DATA_URL_ENV} to another source"
        ) from error
    _verify(content, name, f"the download {url}")
    target.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=target.parent, prefix=f".{name}-", suffix=".part")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(content)
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return content


def fetch(name: str) -> bytes:
    """The verified bytes of ``<name>.rda`` (see the module notes for where from).

    Raises
    ------
    ValueError
        Unknown data set name.
    FileNotFoundError
        ``AVAR_DATA_DIR`` is set but holds no such file.
    ChecksumError
        The file's SHA-256 digest is wrong (a bad download is not kept).
    OSError
        The download failed.
    """
    name = _check_name(name)
    local = os.environ.get(DATA_DIR_ENV)
    if local:
        path = Path(local).expanduser() / f"{name}.rda"
        if not path.is_file():
            raise FileNotFoundError(f"{DATA_DIR_ENV}={local!r} has no file {name}.rda")
        content = path.read_bytes()
        _verify(content, name, str(path))
        return content
    path = cache_dir() / f"{name}.rda"
    if path.is_file():
        content = path.read_bytes()
        try:
            _verify(content, name, str(path))
            return content
        except ChecksumError:
            path.unlink(missing_ok=True)  # a stale or corrupt cache entry: fetch it again
    return _download(name, path)


def _scalar(value: Any) -> Any:
    return np.asarray(value).reshape(-1)[0]


def _channel(record: dict, name: str, freq: float, n: int) -> AllanVariance:
    """One channel's stored Allan variance; missing per-channel freq or n come from the top level."""
    levels = np.asarray(record["levels"], dtype=np.float64)
    channel_freq = float(_scalar(record["freq"])) if "freq" in record else freq
    channel_n = int(_scalar(record["n"])) if "n" in record else n
    if channel_freq != freq or channel_n != n:
        raise ValueError(f"channel {name!r} has freq {channel_freq} / n {channel_n}, the data set {freq} / {n}")
    kind = check_type(str(_scalar(record["type"])) if "type" in record else "mo")
    factors = np.round(levels * freq).astype(np.int64)
    return AllanVariance(
        levels=levels,
        averaging_factors=factors,
        allan=np.asarray(record["allan"], dtype=np.float64),
        errors=np.asarray(record["errors"], dtype=np.float64),
        n_differences=n_differences(n, factors, kind),
        type=kind,
        freq=freq,
        n=n,
        name=name,
    )


def _convert(obj: dict) -> ImuAllanVariance:
    freq = float(_scalar(obj["freq"]))
    n = int(_scalar(obj["n"]))
    channels = {str(key): _channel(record, str(key), freq, n) for key, record in obj["avar"].items()}
    return ImuAllanVariance(
        sensor=str(_scalar(obj["sensor"])),
        freq=freq,
        n=n,
        channels=channels,
        sensor_types=tuple(str(v) for v in np.asarray(obj["type"]).reshape(-1)),
        axes=tuple(str(v) for v in np.asarray(obj["axis"]).reshape(-1)),
    )


def load(name: str) -> ImuAllanVariance:
    """Load one of the IMU Allan variance data sets of R ``avar`` 0.1.3.

    Parameters
    ----------
    name : {"adis_av", "imar_av", "kvh1750_av", "ln200_av", "navchip_av"}

    Returns
    -------
    ImuAllanVariance
        R's fields: sensor name, freq (Hz), n, the sensor type and axis of
        every channel, and per channel (named "Gyro. X", ..., "Accel. Z") the
        stored levels (tau, s), allan and errors. ``averaging_factors`` are
        round(levels * freq); adev, lci and uci derive from allan and errors
        exactly as R stores them.

    Notes
    -----
    The stored values are those computed by R ``avar`` 0.1.3, whose "mo"
    estimator drops the last difference of each level (see
    :func:`avar.avar`); they are kept as published.

    Examples
    --------
    >>> from avar import datasets
    >>> nav = datasets.load("navchip_av")
    >>> nav.sensor, nav.freq, nav.n
    ('NAVCHIP_FLT', 250.0, 3105250)
    >>> nav["Gyro. X"].levels[:3]
    array([0.008, 0.016, 0.032])
    """
    import rdata

    name = _check_name(name)
    content = fetch(name)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Missing constructor", category=UserWarning)
        parsed = rdata.read_rda(io.BytesIO(content))
    return _convert(parsed[name])


def list() -> pd.DataFrame:  # noqa: A001 - the public name mirrors R's data() listing
    """The available data sets: name, description and source.

    Returns
    -------
    pandas.DataFrame
        Columns ``name``, ``description``, ``source``; one row per data set.

    Examples
    --------
    >>> from avar import datasets
    >>> datasets.list()["name"].tolist()
    ['adis_av', 'imar_av', 'kvh1750_av', 'ln200_av', 'navchip_av']
    """
    return pd.DataFrame(
        [(name, description, source) for name, (description, source) in CATALOG.items()],
        columns=["name", "description", "source"],
    )
