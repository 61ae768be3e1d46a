"""Phase and frequency conversions and Stable32's drift models: :func:`phase_to_frequency`,
:func:`frequency_to_phase`, :func:`remove_drift`.

Phase x_i is the time error in seconds, fractional frequency y_i is
dimensionless, tau0 = 1 / rate. Definitions as NIST SP 1065 (Riley 2008)
sections 5.1 and 6.4 and Stable32's Drift function.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from avar._frozen import frozen_array
from avar._validation import check_freq, short_repr
from avar.stability.shared.inputs import finite_vector

#: Drift models by data type (Stable32's Drift function, NIST SP 1065 section 6.4).
DRIFT_MODELS = {
    "freq": ("linear", "bisection", "log", "diffusion"),
    "phase": ("quadratic", "avg2diff", "3point", "linear"),
}


def phase_to_frequency(phase: Any, rate: float = 1.0) -> np.ndarray:
    """Fractional frequency from phase: y_i = (x_{i+1} - x_i) / tau0 (N phase points give N - 1 values).

    Parameters
    ----------
    phase : array_like
        Phase (time error) x in seconds, 1-D, finite, at least 2 points.
    rate : float
        Sampling rate in Hz (tau0 = 1 / rate).

    Returns
    -------
    ndarray of float64
        Dimensionless fractional frequency, as ``allantools.phase2frequency``.

    Examples
    --------
    >>> import avar
    >>> avar.phase_to_frequency([0.0, 1e-9, 3e-9], rate=10.0).round(15).tolist()
    [1e-08, 2e-08]
    """
    rate = check_freq(rate, "rate")
    return np.diff(finite_vector(phase, "phase", 2)) * rate


def frequency_to_phase(frequency: Any, rate: float = 1.0, remove_mean: bool = False) -> np.ndarray:
    """Phase from fractional frequency: x_0 = 0, x_{i+1} = x_i + y_i tau0 (N values give N + 1 points).

    The inverse of :func:`phase_to_frequency` (up to the phase origin).
    ``remove_mean=True`` integrates y - mean(y), as ``allantools.frequency2phase``
    and the deviation functions do (a frequency offset is no noise; it only
    costs precision).

    Parameters
    ----------
    frequency : array_like
        Fractional frequency y, 1-D, finite.
    rate : float
        Sampling rate in Hz (tau0 = 1 / rate).
    remove_mean : bool
        Integrate y - mean(y) instead of y.

    Returns
    -------
    ndarray of float64, the phase in seconds.

    Examples
    --------
    >>> import avar
    >>> avar.frequency_to_phase([1.0, 2.0, 3.0], rate=2.0).tolist()
    [0.0, 0.5, 1.5, 3.0]
    >>> avar.frequency_to_phase([1.0, 2.0, 3.0], remove_mean=True).tolist()
    [0.0, -1.0, -1.0, 0.0]
    """
    rate = check_freq(rate, "rate")
    if not isinstance(remove_mean, (bool, np.bool_)):
        raise TypeError(f"remove_mean must be True or False, got {short_repr(remove_mean)}")
    y = finite_vector(frequency, "frequency", 1)
    if remove_mean:
        y = y - y.mean()
    return np.concatenate(([0.0], np.cumsum(y))) / rate


@dataclass(frozen=True, eq=False)
class Drift:
    """A drift model fitted to phase or frequency data, and the residuals.

    Attributes
    ----------
    residual : ndarray
        The data less the fitted model (same units and length as the data).
    fit : ndarray
        The fitted model at every sample.
    model : str
        The model's name (:data:`DRIFT_MODELS`).
    data_type : {"phase", "freq"}
    coefficients : dict
        The model's coefficients (see :func:`remove_drift`).
    drift : float
        Linear frequency drift in fractional frequency per second (the
        slope of y; for "log" and "diffusion" the slope of the fit at the end
        of the data).
    """

    residual: np.ndarray
    fit: np.ndarray
    model: str
    data_type: str
    coefficients: dict
    drift: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "residual", frozen_array(self.residual))
        object.__setattr__(self, "fit", frozen_array(self.fit))
        object.__setattr__(self, "coefficients", dict(self.coefficients))


def remove_drift(data: Any, model: str = "linear", data_type: str = "freq", rate: float = 1.0) -> Drift:
    """Fit a drift model to phase or frequency data and remove it (Stable32's Drift function).

    With t_i = i tau0 (tau0 = 1 / rate, i = 0 .. N - 1):

    Frequency data y (``data_type="freq"``):

    * ``"linear"``: least-squares line y = a + b t; drift b.
    * ``"bisection"``: b = (mean of the second half - mean of the first
      half) / (N tau0 / 2), a such that the fit has the data's mean.
    * ``"log"``: y = a ln(b t + 1) + c (MIL-PRF-55310's aging model), nonlinear
      least squares (b > 0); drift a b / (b t_end + 1).
    * ``"diffusion"``: y = a + b sqrt(t + c) (c >= 0), nonlinear least squares;
      drift b / (2 sqrt(t_end + c)).

    Phase data x (``data_type="phase"``), a quadratic x = a + b t + c t**2 with
    frequency drift 2c:

    * ``"quadratic"``: least squares.
    * ``"avg2diff"``: c from the mean of the second differences,
      2c = mean(x_{i+2} - 2 x_{i+1} + x_i) / tau0**2; a, b by least squares.
    * ``"3point"``: the parabola through the first, middle and last points.
    * ``"linear"``: c = 0 (a frequency offset only), least squares.

    Parameters
    ----------
    data : array_like
        Phase (s) or fractional frequency, 1-D, finite.
    model : str
        One of ``DRIFT_MODELS[data_type]``.
    data_type : {"freq", "phase"}
    rate : float
        Sampling rate in Hz.

    Returns
    -------
    Drift
        ``residual``, ``fit``, ``coefficients`` (a, b and c), ``drift`` (1/s).

    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 6.4; Stable32 User Manual, "Drift".

    Examples
    --------
    >>> import numpy as np, avar
    >>> y = 1e-12 + 2e-15 * np.arange(100.0)
    >>> res = avar.remove_drift(y, "linear", rate=1.0)
    >>> round(res.drift / 1e-15, 6), float(np.abs(res.residual).max()) < 1e-25
    (2.0, True)
    >>> x = 0.5 * 4e-15 * np.arange(50.0) ** 2
    >>> round(avar.remove_drift(x, "3point", data_type="phase").drift / 1e-15, 6)
    4.0
    """
    if not isinstance(data_type, str) or data_type not in DRIFT_MODELS:
        raise ValueError(f"data_type must be 'freq' or 'phase', got {short_repr(data_type)}")
    if not isinstance(model, str) or model not in DRIFT_MODELS[data_type]:
        raise ValueError(f"model must be one of {DRIFT_MODELS[data_type]} for {data_type} data, "
                         f"got {short_repr(model)}")
    rate = check_freq(rate, "rate")
    needed = {"log": 4, "diffusion": 4, "3point": 3, "avg2diff": 3, "quadratic": 3}.get(model, 2)
    values = finite_vector(data, "data", needed)
    t = np.arange(values.size, dtype=np.float64) / rate
    if data_type == "phase":
        coefficients = _phase_fit(values, t, model, rate)
        fit = coefficients["a"] + coefficients["b"] * t + coefficients["c"] * t**2
        drift = 2.0 * coefficients["c"]
    else:
        coefficients, fit, drift = _frequency_fit(values, t, model)
    return Drift(residual=values - fit, fit=fit, model=model, data_type=data_type,
                 coefficients=coefficients, drift=float(drift))


def _line_given_curvature(x: np.ndarray, t: np.ndarray, c: float) -> dict:
    rest = x - c * t**2
    b, a = np.polyfit(t - t.mean(), rest, 1)
    return {"a": float(a - b * t.mean()), "b": float(b), "c": float(c)}


def _phase_fit(x: np.ndarray, t: np.ndarray, model: str, rate: float) -> dict:
    if model == "quadratic":
        c, b, a = np.polyfit(t - t.mean(), x, 2)  # centred for conditioning, then shifted back
        s = t.mean()
        return {"a": float(a - b * s + c * s * s), "b": float(b - 2 * c * s), "c": float(c)}
    if model == "avg2diff":
        return _line_given_curvature(x, t, float(np.mean(np.diff(x, 2))) * rate**2 / 2.0)
    if model == "3point":
        k = (x.size - 1) // 2
        points = np.array([0, k, x.size - 1])
        c, b, a = np.polyfit(t[points], x[points], 2)
        return {"a": float(a), "b": float(b), "c": float(c)}
    return _line_given_curvature(x, t, 0.0)


def _frequency_fit(y: np.ndarray, t: np.ndarray, model: str) -> tuple[dict, np.ndarray, float]:
    if model == "linear":
        b, a = np.polyfit(t - t.mean(), y, 1)
        coefficients = {"a": float(a - b * t.mean()), "b": float(b)}
        return coefficients, coefficients["a"] + b * t, float(b)
    if model == "bisection":
        half = y.size // 2
        b = (y[y.size - half :].mean() - y[:half].mean()) / (t[y.size - half] - t[0])
        a = y.mean() - b * t.mean()
        return {"a": float(a), "b": float(b)}, a + b * t, float(b)
    from scipy.optimize import least_squares

    span = t[-1] if t[-1] > 0 else 1.0
    scale = float(np.std(y)) or 1.0
    if model == "log":
        def curve(p):
            return p[0] * np.log1p(p[1] * t) + p[2]

        fits = [least_squares(lambda p: (curve(p) - y) / scale,
                              [(y[-1] - y[0]) / np.log1p(g * span) if np.log1p(g * span) else 1.0, g, y[0]],
                              bounds=([-np.inf, 1e-12 / span, -np.inf], np.inf))
                for g in (1.0 / span, 10.0 / span, 100.0 / span)]
        p = min(fits, key=lambda r: r.cost).x
        return ({"a": float(p[0]), "b": float(p[1]), "c": float(p[2])}, curve(p),
                float(p[0] * p[1] / (p[1] * t[-1] + 1.0)))

    def root_curve(p):
        return p[0] + p[1] * np.sqrt(t + p[2])

    fits = [least_squares(lambda p: (root_curve(p) - y) / scale,
                          [y[0], (y[-1] - y[0]) / (np.sqrt(span + c) - np.sqrt(c)), c],
                          bounds=([-np.inf, -np.inf, 0.0], np.inf))
            for c in (0.0, 0.1 * span, span)]
    p = min(fits, key=lambda r: r.cost).x
    return ({"a": float(p[0]), "b": float(p[1]), "c": float(p[2])}, root_curve(p),
            float(p[1] / (2.0 * np.sqrt(t[-1] + p[2])) if t[-1] + p[2] > 0 else np.nan))
