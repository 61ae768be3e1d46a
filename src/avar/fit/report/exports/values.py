r"""The values every estimator export writes, picked once from a :class:`~avar.fit.report.result.NoiseReport`.

Only the IEEE Std 952 terms are read (the rows whose ``Process`` is ``WN``, ``FN``
or ``RW``; Gauss-Markov and sinusoid rows are never exported), in SI units, per
sensor type (gyroscope: rad/s, accelerometer: m/s^2):

* N, the white-noise density (``WN``, u/sqrt(Hz)), continuous time;
* K, the random-walk density (``RW``, u/s/sqrt(Hz)), continuous time;
* B, the bias instability (``FN``, u; AD = 0.664 B on the flat part), with the tau
  of the channel's Allan-deviation minimum (row ``MIN``).

**Axis aggregation**: every estimator takes one value per sensor type; ``axis="max"``
(default, conservative: the noisiest axis) or ``"mean"``.

**Bounds**: on an axis where the data do not resolve a term, its *one-sided 97.5 %
upper bound* (the upper end of the report's 95 % interval; other confidences are
worded alike by :func:`avar.fit.report.rows.bound_words`, the one wording of the table,
the printout and every export) stands in, and the export says so.

**Inflation**: ``inflate`` (K > 0, default 1) multiplies N and K in the exports only;
B and the table keep their measured values.

**Bias instability as a filter state** (:func:`gauss_markov`): a first-order
Gauss-Markov bias of standard deviation sigma and correlation time T has an Allan
deviation that peaks at tau = 1.8926 T with AD = 0.61736 sigma (IEEE Std 952-1997,
Annex C, C.6: sigma^2(tau) = (q T)^2 / tau [1 - T/(2 tau) (3 - 4 e^(-tau/T) + e^(-2 tau/T))],
q^2 = 2 sigma^2 / T). Matching that peak to the flat bias-instability floor
0.66428 B at the tau of the AD minimum gives

    T = tau_min / 1.8926,   sigma = (0.66428 / 0.61736) B = 1.0760 B,

and the Gauss-Markov driving noise q = sigma sqrt(2 / T) (u/s/sqrt(Hz)), the random walk a
filter without a Gauss-Markov state sees over times t << T. :func:`equivalent_random_walk`
gives the random walk that spreads by sigma over a stated horizon: K_h = sigma / sqrt(h).
References: IEEE Std 952-1997 Annex C; El-Sheimy, Hou & Niu (2008), *Analysis and modeling
of inertial sensors using Allan variance*, IEEE Trans. Instrum. Meas. 57(1), 140-149.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from avar.fit.report.noise_terms import ACCEL, GYRO
from avar.fit.report.rows import SENSOR_FILTERING, bound_words

__all__ = ["AGGREGATIONS", "AxisValue", "GaussMarkov", "Picked", "SensorValues", "ImuValues", "axis_values",
           "bias_lines", "check_axis", "check_inflate", "describe", "equivalent_random_walk", "gauss_markov",
           "header_lines", "imu_values", "nominal_rate", "note", "number", "pick", "DEFAULT_TOPIC", "SI_UNITS"]

AGGREGATIONS = ("max", "mean")
#: Topic written when the data did not come from a bag (Kalibr's example).
DEFAULT_TOPIC = "/imu0"
#: SI units of N, K and B per sensor type, as the exports write them.
SI_UNITS = {
    GYRO: {"WN": "rad/s/sqrt(Hz)", "RW": "rad/s^2/sqrt(Hz)", "FN": "rad/s"},
    ACCEL: {"WN": "m/s^2/sqrt(Hz)", "RW": "m/s^3/sqrt(Hz)", "FN": "m/s^2"},
}
#: The AD of a first-order Gauss-Markov process peaks at tau = PEAK_TAU * T with AD = PEAK_AD * sigma.
PEAK_TAU = 1.8926177
PEAK_AD = 0.61736428
#: The flat AD of a bias instability B: sqrt(2 ln 2 / pi) B (IEEE 952).
FLOOR_AD = math.sqrt(2.0 * math.log(2.0) / math.pi)


class AxisValue(NamedTuple):
    """One term on one axis: its channel, value (SI) and status (``present``, or ``bound`` for an upper bound)."""

    channel: str
    value: float
    status: str


class Picked(NamedTuple):
    """One term of one sensor type: the aggregated ``value`` (SI, not inflated), the axes it came from,
    the aggregation, and for a bias instability the tau (s) of the AD minimum (else None)."""

    kind: str
    process: str
    value: float
    axes: tuple[AxisValue, ...]
    axis: str
    tau: float | None = None


class GaussMarkov(NamedTuple):
    """A first-order Gauss-Markov bias: ``sigma`` (u), ``correlation_time`` T (s), ``driving`` q (u/s/sqrt(Hz))."""

    sigma: float
    correlation_time: float
    driving: float


class SensorValues(NamedTuple):
    """What the exports write for one sensor type: ``noise`` N and ``walk`` K (both times ``inflate``),
    the measured ``bias`` B with its Gauss-Markov equivalent, and a comment line per term."""

    kind: str
    noise: float
    walk: float
    bias: float | None
    markov: GaussMarkov | None
    notes: dict[str, str]


class ImuValues(NamedTuple):
    """The picked values of a report: per sensor type present, the nominal rate (Hz), topic, axis, inflate."""

    sensors: dict[str, SensorValues]
    rate: float
    topic: str
    axis: str
    inflate: float
    source: str
    confidence: float


def check_axis(axis: Any) -> str:
    """``axis`` if it is ``"max"`` or ``"mean"``, else a ValueError naming it."""
    if axis not in AGGREGATIONS:
        raise ValueError(f"axis must be 'max' (the noisiest axis) or 'mean', got {axis!r}")
    return axis


def check_inflate(inflate: Any) -> float:
    """``inflate`` as a float if it is a finite number > 0, else a ValueError naming it.

    >>> check_inflate(10)
    10.0
    """
    try:
        value = float(inflate)
    except (TypeError, ValueError):
        raise ValueError(f"inflate must be a number > 0 (a factor on densities and random walks), "
                         f"got {inflate!r}") from None
    if isinstance(inflate, bool) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"inflate must be a finite number > 0 (a factor on densities and random walks), "
                         f"got {inflate!r}")
    return value


def number(value: float) -> str:
    """A float as the shortest text that reads back to the same double, always with a ``.``.

    OpenCV's ``FileStorage`` (and ORB-SLAM3's ``isReal`` check) need a real number to look like one.

    >>> number(200.0), number(1e-05), number(0.00012345)
    ('200.0', '1.0e-05', '0.00012345')
    """
    text = repr(float(value))
    if "." not in text and "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}.0e{exponent}"
    return text


def nominal_rate(rate: float) -> float:
    """The rate a datasheet states: 199.9999999957 -> 200.0 (kept when not within 1e-6 of a whole number)."""
    whole = round(rate)
    return float(whole) if whole > 0 and abs(rate - whole) <= 1e-6 * rate else float(rate)


def axis_values(report: Any, kind: str, process: str) -> list[AxisValue]:
    """One term on every axis of a sensor type: the value, or the upper bound of a term the data do not
    resolve (status ``bound``); axes where it is absent are left out."""
    table = report.terms
    rows = table[(table["Sensor"] == kind) & (table["Process"] == process)]
    if "Group" in rows.columns:  # only IEEE 952 terms, never the sensor's own filtering
        rows = rows[rows["Group"] != SENSOR_FILTERING]
    out = []
    for _, row in rows.iterrows():
        name = str(row.get("Channel", kind))
        if row["Status"] == "present":
            out.append(AxisValue(name, float(row["Value"]), "present"))
        elif row["Status"] == "bound":
            out.append(AxisValue(name, float(row["Upper"]), "bound"))
    return out


def _minimum_taus(report: Any, kind: str) -> dict[str, float]:
    """The tau (s) of the Allan-deviation minimum of every channel of a sensor type (rows ``MIN``)."""
    import pandas as pd

    table = report.terms
    rows = table[(table["Sensor"] == kind) & (table["Process"] == "MIN")]
    return {str(row["Channel"]): float(row["Tau (s)"]) for _, row in rows.iterrows() if not pd.isna(row["Tau (s)"])}


def pick(report: Any, kind: str, process: str, axis: str = "max") -> Picked | None:
    """One term of one sensor type aggregated over its axes (None when no axis has a value or a bound).

    With ``axis="max"`` the bias instability's tau is that of the axis giving the largest B; with
    ``"mean"`` the mean tau of the axes.
    """
    check_axis(axis)
    values = tuple(axis_values(report, kind, process))
    if not values:
        return None
    numbers = [v.value for v in values]
    if axis == "max":
        at = int(np.argmax(numbers))
        value = numbers[at]
    else:
        value = float(np.mean(numbers))
    tau = None
    if process == "FN":
        taus = _minimum_taus(report, kind)
        if axis == "max":
            tau = taus.get(values[at].channel)
        elif all(v.channel in taus for v in values):
            tau = float(np.mean([taus[v.channel] for v in values]))
    return Picked(kind, process, float(value), values, axis, tau)


def note(picked: Picked, confidence: float) -> str:
    """The comment of one exported value: every axis, the aggregation, and which axes give only a bound."""
    words = bound_words(confidence)
    parts = ", ".join(f"{v.channel} {v.value:.4g}" + (f" ({words})" if v.status == "bound" else "")
                      for v in picked.axes)
    text = f"{'largest' if picked.axis == 'max' else 'mean'} over the axes: {parts}"
    bounded = [v.channel for v in picked.axes if v.status == "bound"]
    if bounded:
        text += f"; not resolved on {', '.join(bounded)}: an upper bound, not a measurement"
    return text


def gauss_markov(bias_instability: float, tau_min: float) -> GaussMarkov:
    r"""The first-order Gauss-Markov bias whose Allan-deviation peak sits on a bias-instability floor.

    Parameters
    ----------
    bias_instability : float
        B (u), IEEE 952's bias instability (AD = 0.66428 B on the flat part).
    tau_min : float
        The tau (s) of the Allan-deviation minimum, where the floor is read.

    Returns
    -------
    GaussMarkov
        ``sigma = 0.66428 B / 0.61736`` (u), ``correlation_time = tau_min / 1.8926`` (s) and the driving
        noise ``q = sigma sqrt(2 / T)`` (u/s/sqrt(Hz)): the AD of this process peaks at tau_min with
        the value 0.66428 B (IEEE Std 952-1997, Annex C.6).

    Examples
    --------
    >>> gm = gauss_markov(1e-5, 100.0)
    >>> round(gm.sigma / 1e-5, 4), round(gm.correlation_time, 3)
    (1.076, 52.837)
    """
    if not (math.isfinite(bias_instability) and bias_instability >= 0):
        raise ValueError(f"bias_instability must be a finite number >= 0, got {bias_instability!r}")
    if not (math.isfinite(tau_min) and tau_min > 0):
        raise ValueError(f"tau_min must be a finite tau > 0 (s), got {tau_min!r}")
    sigma = FLOOR_AD / PEAK_AD * bias_instability
    time = tau_min / PEAK_TAU
    return GaussMarkov(sigma, time, sigma * math.sqrt(2.0 / time))


def equivalent_random_walk(sigma: float, horizon: float) -> float:
    """The random walk K (u/s/sqrt(Hz)) that spreads by ``sigma`` (u) over ``horizon`` (s): sigma / sqrt(horizon).

    >>> equivalent_random_walk(2e-5, 400.0)
    1e-06
    """
    if not (math.isfinite(horizon) and horizon > 0):
        raise ValueError(f"horizon must be a finite time > 0 (s), got {horizon!r}")
    return sigma / math.sqrt(horizon)


def imu_values(report: Any, axis: str = "max", inflate: float = 1.0, need: tuple[str, ...] = (),
               export: str = "the export") -> ImuValues:
    """N, K (times ``inflate``) and B of every sensor type of the report, with their comments.

    ``need``: the sensor types the estimator cannot do without (a ValueError names ``export`` and
    the missing type). A term with no value and no bound on any axis is a ValueError too.
    """
    check_axis(axis)
    inflate = check_inflate(inflate)
    present = [kind for kind in (GYRO, ACCEL) if kind in set(report.sensor_types)]
    if not present:
        raise ValueError(f"{export}: the report has no gyroscope or accelerometer channel; name them "
                         "(gyro_units=..., gyro=[...], accel=[...])")
    missing = [kind.lower() for kind in need if kind not in present]
    if missing:
        raise ValueError(f"{export} needs gyroscope and accelerometer terms; the report has no "
                         f"{' or '.join(missing)} channel (name it: accel=[...], gyro=[...], or the *_units)")
    confidence = float(getattr(report, "confidence", 0.95))
    sensors = {}
    for kind in present:
        picked = {process: pick(report, kind, process, axis) for process in ("WN", "RW", "FN")}
        for process in ("WN", "RW"):
            if picked[process] is None:
                raise ValueError(f"{export}: no {kind.lower()} axis has a value or a bound for its "
                                 f"{'white noise' if process == 'WN' else 'random walk'}")
        bad = [p for p in ("WN", "RW") if not (math.isfinite(picked[p].value) and picked[p].value >= 0)]
        if bad:
            raise ValueError(f"{export}: the {kind.lower()} {bad} values are not finite numbers >= 0")
        bias = picked["FN"]
        markov = None
        if bias is not None and bias.tau is not None and math.isfinite(bias.value) and bias.tau > 0:
            markov = gauss_markov(bias.value, bias.tau)
        notes = {process: note(p, confidence) for process, p in picked.items() if p is not None}
        sensors[kind] = SensorValues(kind, picked["WN"].value * inflate, picked["RW"].value * inflate,
                                     None if bias is None else bias.value, markov, notes)
    topic = getattr(report, "topic", None) or DEFAULT_TOPIC
    source = getattr(report, "name", None) or "a noise report"
    return ImuValues(sensors, nominal_rate(float(report.rate)), topic, axis, inflate, source, confidence)


def header_lines(values: ImuValues, estimator: str) -> list[str]:
    """The comment lines every export starts with: source, aggregation, bounds, inflation (plain text)."""
    return describe(values.source, values.axis, values.inflate, values.confidence, estimator)


def describe(source: str, axis: str, inflate: float, confidence: float, estimator: str) -> list[str]:
    """The header lines of an export from its parts (see :func:`header_lines`)."""
    lines = [f"IMU noise model for {estimator}, written by avar from {source}",
             f"one value per sensor type: the {'largest' if axis == 'max' else 'mean'} over its axes "
             f"(axis={axis!r}); a term the data do not resolve gives its {bound_words(confidence)}"]
    if inflate != 1.0:
        lines.append(f"noise densities and random walks multiplied by inflate = {inflate:g} (the report's "
                     "table keeps the measured values): static Allan-variance values understate the noise of a "
                     "moving platform (vibration, temperature, unmodelled scale and misalignment)")
    else:
        lines.append("inflate = 1: the measured static values (a moving platform usually needs more; see inflate)")
    return lines


def bias_lines(values: ImuValues, reader: str) -> list[str]:
    """Informational lines on the bias instability and its Gauss-Markov equivalent (read by no key here)."""
    lines = []
    for kind, sensor in values.sensors.items():
        if sensor.bias is None:
            continue
        unit = SI_UNITS[kind]["FN"]
        text = (f"{kind.lower()} bias instability B = {sensor.bias:.6g} {unit} (not inflated; {reader} reads no "
                f"such key; {sensor.notes.get('FN', '')})")
        lines.append(text)
        if sensor.markov is not None:
            gm = sensor.markov
            lines.append(f"  as a first-order Gauss-Markov bias (AD peak on the floor at the AD minimum): sigma = "
                         f"{gm.sigma:.6g} {unit}, T = {gm.correlation_time:.6g} s, driving noise "
                         f"{gm.driving:.6g} {SI_UNITS[kind]['RW']}")
    return lines
