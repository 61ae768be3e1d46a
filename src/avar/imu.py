"""Inertial measurement unit records: :class:`IMU` and its Allan variance.

An :class:`IMU` holds the samples of several gyroscope and accelerometer
channels recorded at one rate, with the sensor type and axis of every
channel. :func:`imu_avar` (reached through :func:`avar.avar`) computes the
Allan variance of all channels in one pass of the kernels.
"""

from __future__ import annotations

import numbers
import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pandas loads only for frames and Series
    import pandas as pd

from avar._escape import terminal
from avar._time_steps import rate_from_index
from avar._validation import (
    EXACT_INTEGER_LIMIT,
    as_array,
    check_finite,
    check_length,
    check_numeric_dtype,
    integer_range,
)
from avar._vocabulary import check_rate, renamed

GYROSCOPE = "Gyroscope"
ACCELEROMETER = "Accelerometer"
SENSOR_TYPES = (GYROSCOPE, ACCELEROMETER)
#: Channel name prefixes of the R data sets ("Gyro. X", "Accel. Z").
CHANNEL_PREFIX = {GYROSCOPE: "Gyro.", ACCELEROMETER: "Accel."}
DEFAULT_AXES = ("X", "Y", "Z")
DEFAULT_NAME = "IMU"
#: Accepted spellings of the sensor types (keys of ``units``), lower case.
TYPE_ALIASES = {
    "gyroscope": GYROSCOPE,
    "gyro": GYROSCOPE,
    "accelerometer": ACCELEROMETER,
    "accel": ACCELEROMETER,
    "acc": ACCELEROMETER,
}


def _frozen_matrix(values: np.ndarray) -> np.ndarray:
    """A read-only copy in column-major order (each channel contiguous).

    float64, except for integers beyond 2**53, which float64 cannot hold
    exactly: they are kept as they are (int64 or uint64), and the Allan
    variance converts each channel without loss (see
    :func:`avar._validation.as_float64`).
    """
    bounds = integer_range(np.asarray(values))
    lossy = bounds is not None and max(abs(bounds.minimum), abs(bounds.maximum)) > EXACT_INTEGER_LIMIT
    matrix = np.array(values, dtype=np.asarray(values).dtype if lossy else np.float64, order="F", copy=True)
    matrix.flags.writeable = False
    return matrix


def _selection(selector: Any, columns: tuple[str, ...], role: str) -> list[int]:
    """Column positions named by ``selector`` (names, indices, or one of them)."""
    if selector is None:
        return []
    if isinstance(selector, (str, numbers.Integral)) and not isinstance(selector, (bool, np.bool_)):
        items = [selector]
    elif isinstance(selector, Iterable) and not isinstance(selector, (bytes, Mapping)):
        items = list(selector)
    else:
        raise TypeError(f"{role} must be a column name, a column index or a list of them, got {selector!r}")
    positions = []
    for item in items:
        if isinstance(item, (bool, np.bool_)):
            raise TypeError(f"{role} must name columns by name or integer index, got {item!r}")
        if isinstance(item, numbers.Integral):
            if not 0 <= item < len(columns):
                raise ValueError(
                    f"{role} column index {item} is out of range: the data have "
                    f"{len(columns)} columns (0..{len(columns) - 1})"
                )
            positions.append(int(item))
        elif isinstance(item, str):
            if item not in columns:
                raise ValueError(f"{role} column {item!r} is not a column of the data; the columns are {list(columns)}")
            positions.append(columns.index(item))
        else:
            raise TypeError(f"{role} must name columns by name or integer index, got {item!r}")
    repeated = {columns[p] for p in positions if positions.count(p) > 1}
    if repeated:
        raise ValueError(f"{role} names column(s) {sorted(repeated)} more than once")
    return positions


def _infer_types(columns: tuple[str, ...]) -> tuple[list[int], list[int]]:
    """Gyro and accel positions from names starting with "gyro" / "acc"."""
    gyro = [j for j, c in enumerate(columns) if c.lower().startswith("gyro")]
    accel = [j for j, c in enumerate(columns) if c.lower().startswith("acc")]
    return gyro, accel


def _check_axes(axis: Any, needed: int) -> tuple[str, ...]:
    """Axis labels, one per channel of the most numerous sensor type."""
    if axis is None:
        labels = DEFAULT_AXES
    elif isinstance(axis, str):
        labels = (axis,)
    else:
        labels = tuple(axis)
    if not all(isinstance(label, str) and label for label in labels):
        raise TypeError(f"axis must be a list of non-empty strings, got {axis!r}")
    if len(set(labels)) != len(labels):
        raise ValueError(f"axis labels must be distinct, got {list(labels)}")
    if len(labels) < needed:
        raise ValueError(
            f"{needed} channels of one sensor type need {needed} axis labels; "
            f"got {list(labels)} (pass axis=[...] with one label per channel of a sensor type)"
        )
    return labels


def _check_units(units: Any) -> dict[str, str]:
    """Units keyed by sensor type ("Gyroscope", "Accelerometer"; "gyro"/"accel" accepted)."""
    if units is None:
        return {}
    if not isinstance(units, Mapping):
        raise TypeError(f"units must be a mapping such as {{'gyro': 'rad/s', 'accel': 'm/s^2'}}, got {units!r}")
    checked = {}
    for key, unit in units.items():
        kind = TYPE_ALIASES.get(str(key).lower())
        if kind is None:
            raise ValueError(f"units key {key!r} is not a sensor type; use 'gyro' or 'accel'")
        if not isinstance(unit, str):
            raise TypeError(f"the unit of {kind} must be a string, got {unit!r}")
        checked[kind] = unit
    return checked


@dataclass(frozen=True, init=False, eq=False)
class IMU:
    """A multi-channel inertial sensor record (gyroscopes and accelerometers).

    Parameters
    ----------
    data : array_like of shape (N, C) or pandas.DataFrame
        Samples (rows) of every channel (columns), any real dtype; stored as a
        read-only float64 copy (integers beyond 2**53 keep their integer dtype). A DataFrame keeps its column names as channel
        names.
    rate : float
        Sampling rate in Hz (> 0). See :meth:`from_dataframe` to take it
        from a regular time index.
    freq : float
        R's name of ``rate`` (keyword only), kept so that R code ports line by line;
        give one of them.
    gyro, accel : str, int or list of them, optional
        The gyroscope and accelerometer columns, by name or 0-based index.
        Every column must be in exactly one of them. When both are omitted,
        column names starting with "Gyro" and "Acc" (any case) are used.
    axis : list of str, optional
        Axis labels, default ``["X", "Y", "Z"]``: the k-th column listed in
        ``gyro`` (and the k-th in ``accel``) is on axis ``axis[k]``.
    name : str, optional
        Sensor name (default "IMU").
    units : mapping, optional
        Data units per sensor type, e.g. ``{"gyro": "rad/s", "accel": "m/s^2"}``.

    Attributes
    ----------
    data : ndarray, shape (N, C)
        Read-only float64 samples (column-major, each channel contiguous); int64
        or uint64 for integers beyond 2**53, which float64 cannot hold exactly.
    rate : float
        Sampling rate in Hz; ``freq`` is the same value under R's name.
    n_samples : int
        Samples per channel (``n`` is the same).
    channels : tuple of str
        Channel names: the DataFrame column names, or for an array
        ``"Gyro. X"``, ``"Accel. Y"``, ... as in the R data sets.
    sensor_types : tuple of str
        ``"Gyroscope"`` or ``"Accelerometer"`` per channel.
    axes : tuple of str
        Axis label per channel.
    name : str
        Sensor name.
    units : Mapping[str, str]
        Units keyed by ``"Gyroscope"`` / ``"Accelerometer"``.

    Raises
    ------
    TypeError
        Non-numeric data, a selector that is neither a name nor an index.
    ValueError
        Data that are not 2-D, fewer than 4 samples, a NaN or infinity (the
        message names the channel), duplicate column names, a column that is
        neither gyro nor accel or that is both, an unknown column, rate <= 0.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.random.default_rng(1).standard_normal((1000, 6))
    >>> imu = IMU(x, rate=100, gyro=[0, 1, 2], accel=[3, 4, 5], name="demo")
    >>> imu.channels
    ('Gyro. X', 'Gyro. Y', 'Gyro. Z', 'Accel. X', 'Accel. Y', 'Accel. Z')
    >>> imu
    <IMU demo: 6 channels (3 Gyroscope, 3 Accelerometer), N = 1000, freq = 100 Hz>
    >>> imu["Accel. Y"].shape
    (1000,)
    """

    data: np.ndarray
    freq: float
    channels: tuple[str, ...]
    sensor_types: tuple[str, ...]
    axes: tuple[str, ...]
    name: str
    units: Mapping[str, str]

    def __init__(
        self,
        data: Any,
        rate: Any = None,
        gyro: Any = None,
        accel: Any = None,
        axis: Any = None,
        name: str | None = None,
        units: Mapping[str, str] | None = None,
        *,
        freq: Any = None,
    ) -> None:
        rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=False)
        if rate is None:
            raise TypeError("IMU() needs the sampling rate: IMU(data, rate=HZ, ...) (R's freq= is accepted too)")
        pd = sys.modules.get("pandas")  # not loaded: data cannot be a pandas object
        if pd is not None and isinstance(data, pd.DataFrame):
            columns = tuple(str(c) for c in data.columns)
            if len(set(columns)) != len(columns):
                repeated = sorted({c for c in columns if columns.count(c) > 1})
                raise ValueError(f"duplicate column names {repeated}; every channel needs its own name")
            bad = [c for c, dt in zip(columns, data.dtypes) if not pd.api.types.is_numeric_dtype(dt)]
            if bad:
                raise TypeError(f"column(s) {bad} of data are not numeric; an IMU needs numeric channels only")
            complex_ = [c for c, dt in zip(columns, data.dtypes) if pd.api.types.is_complex_dtype(dt)]
            if complex_:
                raise TypeError(f"column(s) {complex_} of data are complex; the Allan variance needs real data")
            integers = all(pd.api.types.is_integer_dtype(dt) and dt.kind in "iu" for dt in data.dtypes)
            array = data.to_numpy() if integers else data.to_numpy(dtype=np.float64, na_value=np.nan)
        else:
            if pd is not None and isinstance(data, pd.Series):
                raise ValueError("data is a single Series; use avar.avar(series) for one channel, or give a DataFrame")
            columns = None
            array = as_array(data, "data")
        check_numeric_dtype(array, "data")
        if array.ndim != 2:
            raise ValueError(
                f"IMU data must be 2-D (samples x channels), got shape {array.shape}; "
                "for a single series use avar.avar(x), or reshape it with x[:, None]"
            )
        n, n_columns = array.shape
        if n_columns == 0:
            raise ValueError("IMU data has no channels (0 columns)")
        check_length(n, "IMU data")
        rate = check_rate(rate, rate_name)

        positional = columns is None
        names = columns if columns is not None else tuple(str(j) for j in range(n_columns))
        if gyro is None and accel is None:
            if positional:
                raise ValueError(
                    "name the gyroscope and accelerometer columns with gyro=[...] and accel=[...] "
                    "(by 0-based index for an array)"
                )
            gyro_at, accel_at = _infer_types(names)
        else:
            gyro_at = _selection(gyro, names, "gyro")
            accel_at = _selection(accel, names, "accel")
        both = sorted(set(gyro_at) & set(accel_at))
        if both:
            raise ValueError(f"column(s) {[names[j] for j in both]} are listed both as gyro and as accel")
        neither = [names[j] for j in range(n_columns) if j not in gyro_at and j not in accel_at]
        if neither:
            raise ValueError(
                f"column(s) {neither} are neither gyro nor accel channels; "
                "list every column in gyro= or accel=, or drop it"
            )
        labels = _check_axes(axis, max(len(gyro_at), len(accel_at)))
        kinds = [""] * n_columns
        axes = [""] * n_columns
        for kind, positions in ((GYROSCOPE, gyro_at), (ACCELEROMETER, accel_at)):
            for k, j in enumerate(positions):
                kinds[j], axes[j] = kind, labels[k]
        if positional:
            names = tuple(f"{CHANNEL_PREFIX[kind]} {label}" for kind, label in zip(kinds, axes))

        values = _frozen_matrix(array)
        finite = np.isfinite(values).all(axis=0)
        for j in np.flatnonzero(~finite):
            check_finite(values[:, j], f"channel {names[j]!r}")

        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a string, got {name!r}")
        set_field = object.__setattr__
        set_field(self, "data", values)
        set_field(self, "freq", rate)
        set_field(self, "channels", names)
        set_field(self, "sensor_types", tuple(kinds))
        set_field(self, "axes", tuple(axes))
        set_field(self, "name", name if name is not None else DEFAULT_NAME)
        set_field(self, "units", MappingProxyType(_check_units(units)))

    @classmethod
    def from_dataframe(cls, df: pd.DataFrame, rate: Any = None, gyro: Any = None, accel: Any = None,
                       axis: Any = None, name: str | None = None, units: Mapping[str, str] | None = None,
                       *, freq: Any = None) -> IMU:
        """An IMU from a DataFrame, taking the rate from its time index.

        Parameters
        ----------
        df : pandas.DataFrame
            One column per channel. With ``rate`` omitted, its index must be a
            regular ``DatetimeIndex`` or ``TimedeltaIndex``: rate = 1 / step.
        rate, gyro, accel, axis, name, units
            As for :class:`IMU`.
        freq : float, optional
            R's name of ``rate``, as for :class:`IMU`.

        Examples
        --------
        >>> import numpy as np, pandas as pd
        >>> t = pd.timedelta_range(0, periods=500, freq="10ms")
        >>> x = np.random.default_rng(2).standard_normal((500, 2))
        >>> df = pd.DataFrame(x, index=t, columns=["gyro_x", "acc_x"])
        >>> imu = IMU.from_dataframe(df, name="demo")
        >>> imu.freq, imu.sensor_types
        (100.0, ('Gyroscope', 'Accelerometer'))
        """
        import pandas as pd

        if not isinstance(df, pd.DataFrame):
            raise TypeError(f"df must be a pandas DataFrame, got {type(df).__name__}")
        rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=False)
        if rate is None:
            rate = rate_from_index(df.index, "df")
            if rate is None:
                raise ValueError(
                    "df has no regular DatetimeIndex or TimedeltaIndex to take the rate from; pass rate (Hz)"
                )
        elif rate_name == "freq":
            return cls(df, gyro=gyro, accel=accel, axis=axis, name=name, units=units, freq=rate)
        return cls(df, rate, gyro=gyro, accel=accel, axis=axis, name=name, units=units)

    @property
    def rate(self) -> float:
        """Sampling rate in Hz (``freq`` under R's name)."""
        return self.freq

    @property
    def n_samples(self) -> int:
        """Samples per channel."""
        return self.data.shape[0]

    @property
    def n(self) -> int:
        """Samples per channel (the same as :attr:`n_samples`)."""
        return self.data.shape[0]

    def __len__(self) -> int:
        return self.data.shape[0]

    def __getitem__(self, channel: str) -> np.ndarray:
        """The read-only samples of one channel."""
        if channel not in self.channels:
            raise KeyError(f"no channel {channel!r}; the channels are {list(self.channels)}")
        return self.data[:, self.channels.index(channel)]

    def to_dataframe(self) -> pd.DataFrame:
        """The samples as a DataFrame with the channel names, indexed by time in seconds."""
        import pandas as pd

        index = pd.Index(np.arange(self.n) / self.rate, name="Time")
        return pd.DataFrame(np.array(self.data), index=index, columns=list(self.channels))

    def describe(self) -> str:
        counts = ", ".join(
            f"{self.sensor_types.count(kind)} {kind}" for kind in SENSOR_TYPES if kind in self.sensor_types
        )
        return f"{terminal(self.name)}: {len(self.channels)} channels ({counts}), N = {self.n}, freq = {self.freq:g} Hz"

    def __repr__(self) -> str:
        return f"<IMU {self.describe()}>"
