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
They ship inside the package, as ``avar/io/data/<name>.npz`` (plain NumPy
arrays, no pickles), converted once from the R package's ``.rda`` files by
``tools/convert_datasets.py`` in the repository. Nothing is downloaded and no
R format is read at run time.
"""

from __future__ import annotations

from importlib import resources
from typing import Any

import numpy as np
import pandas as pd

from avar.stability.allan.results import AllanVariance, ImuAllanVariance
from avar.stability.shared.grids import check_type
from avar.stability.shared.term_counts import n_differences

#: Directory of the ``<name>.npz`` files, inside the package ``avar.io``.
DATA_DIRECTORY = "data"

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


def _check_name(name: Any) -> str:
    if not isinstance(name, str):
        raise TypeError(f"data set name must be a string, got {type(name).__name__}")
    if name not in CATALOG:
        raise ValueError(f"unknown data set {name!r}; available: {', '.join(NAMES)}")
    return name


def data_file(name: str):
    """The shipped file ``<name>.npz`` (a :class:`importlib.resources` traversable)."""
    return resources.files("avar.io") / DATA_DIRECTORY / f"{_check_name(name)}.npz"


def _channel(arrays, i: int, name: str, freq: float, n: int) -> AllanVariance:
    levels = arrays[f"levels_{i}"]
    kind = check_type(str(arrays[f"avtype_{i}"]))
    factors = np.round(levels * freq).astype(np.int64)
    return AllanVariance(
        levels=levels,
        averaging_factors=factors,
        allan=arrays[f"allan_{i}"],
        errors=arrays[f"errors_{i}"],
        n_differences=n_differences(n, factors, kind),
        type=kind,
        freq=freq,
        n=n,
        name=name,
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
    >>> from avar.io import datasets
    >>> nav = datasets.load("navchip_av")
    >>> nav.sensor, nav.freq, nav.n
    ('NAVCHIP_FLT', 250.0, 3105250)
    >>> nav["Gyro. X"].levels[:3]
    array([0.008, 0.016, 0.032])
    """
    with data_file(name).open("rb") as stream, np.load(stream, allow_pickle=False) as arrays:
        freq = float(arrays["freq"])
        n = int(arrays["n"])
        names = [str(channel) for channel in arrays["channels"]]
        return ImuAllanVariance(
            sensor=str(arrays["sensor"]),
            freq=freq,
            n=n,
            channels={name: _channel(arrays, i, name, freq, n) for i, name in enumerate(names)},
            sensor_types=tuple(str(v) for v in arrays["type"]),
            axes=tuple(str(v) for v in arrays["axis"]),
        )


def list() -> pd.DataFrame:  # noqa: A001 - the public name mirrors R's data() listing
    """The available data sets: name, description and source.

    Returns
    -------
    pandas.DataFrame
        Columns ``name``, ``description``, ``source``; one row per data set.

    Examples
    --------
    >>> from avar.io import datasets
    >>> datasets.list()["name"].tolist()
    ['adis_av', 'imar_av', 'kvh1750_av', 'ln200_av', 'navchip_av']
    """
    return pd.DataFrame(
        [(name, description, source) for name, (description, source) in CATALOG.items()],
        columns=["name", "description", "source"],
    )
