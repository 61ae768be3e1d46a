"""Bias versus temperature: the slope of each channel's mean on a temperature column, and the drift warning.

A static log is cut into W consecutive windows of L samples (W = min(100, N // 16),
the tail of fewer than L samples dropped); in window w the channel's mean y_w and the
temperature's mean T_w are taken, and the bias-versus-temperature slope is the least
squares line

    y_w = a + b T_w,   b = S_Ty / S_TT,   SE(b)^2 = s^2 / S_TT * (1 + rho) / (1 - rho)

with S_TT = sum (T_w - mean T)^2, s^2 the residual variance (W - 2 degrees of freedom)
and rho the lag-1 autocorrelation of the residuals, clipped to [0, 0.95]: the variance
inflation of a slope on a slowly drifting regressor under AR(1) errors. When the
channel's fitted noise model is given (its white noise sigma^2 and random walk
gamma^2 per sample), the window means' covariance under that model,

    Cov(y_j, y_k) = sigma^2 / L [j = k] + gamma^2 (a_j + (L + 1) / 2)        (j < k, a_j = j L)
    Var(y_k)      = sigma^2 / L + gamma^2 (a_k + (L + 1)(2 L + 1) / (6 L)),

gives the sandwich variance c' Cov c / S_TT^2 (c = T_w - mean T), and the larger
of the two errors is kept: a random-walk bias wanders, and one log cannot tell
the part of its wander that follows a monotonic temperature from a thermal
slope (a spurious regression); the sandwich error says how large that part can
be. :func:`avar.noise_reports` takes, per channel, the largest white noise and random
walk of every log's fit and of the pooled fit (a log whose warming makes its own fit
choose a ramp would otherwise lose its random walk; the largest is the cautious choice). The slope's unit is the channel's
data unit per degC.

The drift warning fires when the range of the window means of the temperature
exceeds :data:`DRIFT_LIMIT` = 1 degC. A MEMS gyroscope's bias moves by typically
0.01 to 0.1 deg/s per degC (datasheet temperature coefficients), 10 to 100 times
its bias instability: one degree of drift during a static log is enough for the
long-tau terms (bias instability, rate random walk, ramp) to measure the thermal
drift instead of the sensor's noise (IEEE Std 952-1997, C.1: the test is run at
a constant temperature).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

__all__ = ["DRIFT_LIMIT", "TEMPERATURE_COLUMNS", "TemperatureFit", "is_temperature_name", "temperature_fit"]

#: Temperature range (degC, of the window means) above which a static log is warned about.
DRIFT_LIMIT = 1.0
#: Most windows of the slope.
MAX_WINDOWS = 100
#: Columns of :attr:`TemperatureFit.slopes`.
TEMPERATURE_COLUMNS = ["Channel", "Slope", "SE", "Unit", "Windows"]
_NAME = re.compile(r"^(temp|temperature|tmp)(\b|_|$)|celsius|degc|deg_c|^t(\s*[\[(]\s*c\s*[\])])?$", re.I)


def is_temperature_name(name: str) -> bool:
    """A column named like a temperature in degC: ``temp``, ``temperature``, ``temp_c``, ``imu_degC``, ``T``.

    >>> [is_temperature_name(n) for n in ("temp", "Temperature", "temp_c", "T [C]", "gx", "t_s", "time")]
    [True, True, True, True, False, False, False]
    """
    text = str(name).strip()
    if text == "t" or text.lower().startswith("time"):
        return False  # ``t`` is time (lower case); ``T`` is a temperature
    return bool(_NAME.search(text))


class TemperatureFit(NamedTuple):
    """The temperature of one log and the slope of every channel's bias on it.

    Attributes
    ----------
    column : str
        The temperature column.
    low, high : float
        Smallest and largest window mean of the temperature (degC).
    slopes : DataFrame
        ``Channel, Slope, SE, Unit, Windows``: the slope (data unit per degC), its standard error, the unit.
    warning : str or None
        The drift warning (range of the window means > :data:`DRIFT_LIMIT`).
    means : ndarray
        The temperature's window means (degC); ``length``: samples per window.
    """

    column: str
    low: float
    high: float
    slopes: pd.DataFrame
    warning: str | None
    means: np.ndarray = np.zeros(0)
    length: int = 1

    def with_noise(self, noise: Mapping[str, Mapping[str, float]]) -> TemperatureFit:
        """The same slopes, each error the larger of its own and the sandwich under ``noise`` (per channel,
        white noise ``"WN"`` and random walk ``"RW"`` per-sample variances; see the module)."""
        centred = self.means - self.means.mean()
        s_tt = float(centred @ centred)
        slopes = self.slopes.copy()
        if not s_tt > 0:
            return self
        for at, channel in enumerate(slopes["Channel"]):
            if channel in noise:
                model = np.sqrt(_model_variance(centred, self.length, noise[channel])) / s_tt
                slopes.loc[at, "SE"] = max(float(slopes.loc[at, "SE"]), model)
        return self._replace(slopes=slopes)

    @property
    def range(self) -> float:
        """Range of the temperature's window means (degC)."""
        return self.high - self.low


def _window_means(values: np.ndarray, windows: int, length: int) -> np.ndarray:
    return np.asarray(values[: windows * length], dtype=np.float64).reshape(windows, length).mean(axis=1)


def _model_variance(centred: np.ndarray, length: int, noise: Mapping[str, float]) -> float:
    """c' Cov c of the window means under white noise and a random walk (per-sample variances, see the module)."""
    windows = centred.size
    white, walk = float(noise.get("WN", 0.0)), float(noise.get("RW", 0.0))
    start = np.arange(windows, dtype=np.float64) * length
    low = np.minimum.outer(start, start) + (length + 1) / 2.0
    np.fill_diagonal(low, start + (length + 1) * (2 * length + 1) / (6.0 * length))
    return float(white / length * (centred @ centred) + walk * (centred @ low @ centred))


def _slope(temps: np.ndarray, means: np.ndarray, length: int = 1,
           noise: Mapping[str, float] | None = None) -> tuple[float, float]:
    """Least squares slope of ``means`` on ``temps`` and its standard error (AR(1)-inflated, or the noise
    model's sandwich when larger: see the module)."""
    centred = temps - temps.mean()
    s_tt = float(centred @ centred)
    if not s_tt > 0:
        return float("nan"), float("nan")
    slope = float(centred @ (means - means.mean())) / s_tt
    residuals = means - means.mean() - slope * centred
    dof = max(means.size - 2, 1)
    variance = float(residuals @ residuals) / dof
    rho = 0.0
    if residuals.size > 3 and residuals @ residuals > 0:
        rho = float(np.clip((residuals[1:] @ residuals[:-1]) / (residuals @ residuals), 0.0, 0.95))
    error2 = variance / s_tt * (1.0 + rho) / (1.0 - rho)
    if noise:
        error2 = max(error2, _model_variance(centred, length, noise) / s_tt**2)
    return slope, float(np.sqrt(error2))


def temperature_fit(channels: Mapping[str, Any], temperature: Any, column: str = "temperature",
                    units: Mapping[str, str | None] | None = None, log: str = "the log",
                    noise: Mapping[str, Mapping[str, float]] | None = None) -> TemperatureFit:
    """The bias-versus-temperature slope of every channel (least squares of window means, see the module).

    Parameters
    ----------
    channels : Mapping[str, array_like]
        The channels' samples, by name (one length).
    temperature : array_like
        The temperature (degC) at every sample.
    column : str
        Name of the temperature column (for the warning).
    units : Mapping[str, str or None], optional
        Data unit of every channel; the slope is in unit/degC (``u/degC`` when unknown).
    log : str
        Name of the log (for the warning).
    noise : Mapping[str, Mapping[str, float]], optional
        Per channel, the fitted per-sample variances of its white noise ``"WN"`` and random walk
        ``"RW"`` (data units squared), for the sandwich error of the module.

    Returns
    -------
    TemperatureFit

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(1)
    >>> temp = np.linspace(20.0, 25.0, 50_000)
    >>> gx = 0.002 * temp + rng.normal(0.0, 0.01, temp.size)
    >>> fit = temperature_fit({"gx": gx}, temp, "temp", {"gx": "rad/s"})
    >>> row = fit.slopes.iloc[0]
    >>> bool(abs(row["Slope"] - 0.002) < 3 * row["SE"]), row["Unit"], round(fit.range, 2)
    (True, 'rad/s/degC', 4.95)
    >>> fit.warning.split(":")[0]
    'the log'
    """
    temps = np.asarray(temperature, dtype=np.float64).reshape(-1)
    n = temps.size
    if n < 48:
        raise ValueError(f"temperature_fit: the temperature column {column!r} has {n} samples; at least 48 "
                         "(3 windows of 16) are needed")
    if not np.all(np.isfinite(temps)):
        raise ValueError(f"temperature_fit: the temperature column {column!r} holds NaN or infinite values")
    windows = int(min(MAX_WINDOWS, n // 16))
    length = n // windows
    temp_means = _window_means(temps, windows, length)
    rows = []
    for name, values in channels.items():
        values = np.asarray(values, dtype=np.float64).reshape(-1)
        if values.size != n:
            raise ValueError(f"temperature_fit: channel {name!r} has {values.size} samples, the temperature {n}")
        slope, error = _slope(temp_means, _window_means(values, windows, length), length, (noise or {}).get(name))
        unit = (units or {}).get(name) or "u"
        rows.append({"Channel": str(name), "Slope": slope, "SE": error, "Unit": f"{unit}/degC", "Windows": windows})
    low, high = float(temp_means.min()), float(temp_means.max())
    warning = None
    if high - low > DRIFT_LIMIT:
        warning = (f"{log}: the temperature ({column}) drifts by {high - low:.3g} degC during the log "
                   f"(> {DRIFT_LIMIT:g} degC): the long-tau terms (bias instability, random walk, ramp) then "
                   "include the thermal drift of the bias; see the bias-versus-temperature slopes")
    return TemperatureFit(str(column), low, high, pd.DataFrame(rows, columns=TEMPERATURE_COLUMNS), warning,
                          temp_means, length)
