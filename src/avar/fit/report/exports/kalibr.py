"""Kalibr ``imu.yaml`` from a :class:`~avar.fit.report.result.NoiseReport`.

Kalibr (and ``allan_variance_ros``) describe an IMU by four continuous-time
densities in SI units, each aggregated over the axes of a sensor type:

=================================  ===========================================
``gyroscope_noise_density``        angle random walk N, rad/s/sqrt(Hz)
``gyroscope_random_walk``          rate random walk K, rad/s^2/sqrt(Hz)
``accelerometer_noise_density``    velocity random walk N, m/s^2/sqrt(Hz)
``accelerometer_random_walk``      acceleration random walk K, m/s^3/sqrt(Hz)
=================================  ===========================================

plus ``rostopic`` (the bag topic the data came from) and ``update_rate`` (the
nominal rate, Hz). Kalibr discretizes them with the sample interval dt = 1 /
update_rate: sigma_d = sigma_c / sqrt(dt) for the white noise and sigma_bd =
sigma_b sqrt(dt) for the bias random walk (Kalibr wiki, *IMU Noise Model*).
Each density is the largest over the axes (or their mean); a term the data do
not resolve contributes its one-sided 97.5 % upper bound, and a comment above
every density gives the axes' values and says so. N is the Allan deviation of
the white noise at tau = 1 s and K that of the random walk at tau = 3 s
(AD = K sqrt(tau / 3)), as Kalibr defines them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from avar._escape import yaml_comment, yaml_entry
from avar.fit.report.exports.files import write_text
from avar.fit.report.exports.values import (
    DEFAULT_TOPIC,
    axis_values,
    bias_lines,
    check_axis,
    check_inflate,
    describe,
    imu_values,
    nominal_rate,
    note,
    pick,
)
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["kalibr_fields", "kalibr_notes", "kalibr_text", "write_kalibr", "axis_values", "nominal_rate",
           "DEFAULT_TOPIC", "FIELDS", "UNITS"]

FIELDS = {
    (GYRO, "WN"): "gyroscope_noise_density",
    (GYRO, "RW"): "gyroscope_random_walk",
    (ACCEL, "WN"): "accelerometer_noise_density",
    (ACCEL, "RW"): "accelerometer_random_walk",
}
#: Unit, time convention and the discretization Kalibr applies, per key.
UNITS = {
    "gyroscope_noise_density": "rad/s/sqrt(Hz), continuous-time white noise; Kalibr uses sigma_d = sigma_c * sqrt(rate)",
    "gyroscope_random_walk": "rad/s^2/sqrt(Hz), continuous-time bias random walk; Kalibr uses sigma_bd = sigma_b / sqrt(rate)",
    "accelerometer_noise_density": "m/s^2/sqrt(Hz), continuous-time white noise; Kalibr uses sigma_d = sigma_c * sqrt(rate)",
    "accelerometer_random_walk": "m/s^3/sqrt(Hz), continuous-time bias random walk; Kalibr uses sigma_bd = sigma_b / sqrt(rate)",
}


def kalibr_fields(report: Any, rostopic: str | None = None, update_rate: float | None = None,
                  axis: str = "max", inflate: float = 1.0, **densities: float) -> dict[str, Any]:
    """The ``imu.yaml`` fields of a report, in Kalibr's order.

    Each density aggregates the axes of its sensor type: ``axis="max"``
    (default, conservative: the noisiest axis) or ``"mean"``. On an axis where
    the data do not resolve a term (a random walk too small for the record),
    its one-sided 97.5 % upper bound stands in; :func:`kalibr_notes` says so. A value is
    written for every key of the sensor types present, times ``inflate`` (densities given
    explicitly are written as given). ``rostopic`` defaults to the report's topic (the bag
    topic), else ``"/imu0"``; ``update_rate`` to the report's nominal rate. Any field may be
    given explicitly (``gyroscope_random_walk=4e-5``).

    Examples
    --------
    >>> import avar
    >>> x = (avar.WN(sigma2=4e-6) + avar.RW(gamma2=1e-12)).simulate(400_000, seed=3)
    >>> fields = avar.noise_report(x, gyro_units="rad/s", rate=200.0).kalibr()
    >>> list(fields)
    ['gyroscope_noise_density', 'gyroscope_random_walk', 'rostopic', 'update_rate']
    >>> round(fields["gyroscope_noise_density"], 6), fields["update_rate"]
    (0.000141, 200.0)
    """
    unknown = set(densities) - set(FIELDS.values())
    if unknown:
        raise TypeError(f"unknown Kalibr field(s) {sorted(unknown)}; give {list(FIELDS.values())}, rostopic, update_rate")
    check_axis(axis)
    inflate = check_inflate(inflate)
    present = set(report.sensor_types) & {GYRO, ACCEL}
    if not present:
        raise ValueError("the report has no gyroscope or accelerometer channel; name them (gyro_units=..., "
                         "gyro=[...], accel=[...]) to write a Kalibr imu.yaml")
    fields: dict[str, Any] = {}
    for kind in (GYRO, ACCEL):
        if kind not in present:
            continue
        for process in ("WN", "RW"):
            key = FIELDS[kind, process]
            value = densities.get(key)
            if value is None:
                picked = pick(report, kind, process, axis)
                if picked is None:
                    raise ValueError(f"{key}: no {kind.lower()} axis has a value or a bound for it; "
                                     f"give {key}=... explicitly")
                value = picked.value * inflate
            fields[key] = float(value)
    bad = [key for key, value in fields.items() if not np.isfinite(value) or value < 0]
    if bad:
        raise ValueError(f"the Kalibr field(s) {bad} are not finite numbers >= 0; give them explicitly "
                         f"(e.g. {bad[0]}=...)")
    topic = rostopic if rostopic is not None else (report.topic or DEFAULT_TOPIC)
    if not isinstance(topic, str) or not topic:
        raise TypeError(f"rostopic must be a non-empty string, got {topic!r}")
    rate = nominal_rate(float(report.rate)) if update_rate is None else float(update_rate)
    if not np.isfinite(rate) or rate <= 0:
        raise ValueError(f"update_rate must be a finite rate > 0 (Hz), got {update_rate!r}")
    fields["rostopic"] = topic
    fields["update_rate"] = rate
    return fields


def kalibr_notes(report: Any, axis: str = "max", **given: float) -> dict[str, str]:
    """A yaml comment per density: the value of every axis, the aggregation, and which axes give only a bound."""
    confidence = float(getattr(report, "confidence", 0.95))
    notes = {}
    for (kind, process), key in FIELDS.items():
        if kind not in report.sensor_types:
            continue
        if key in given:
            notes[key] = "given explicitly"
            continue
        picked = pick(report, kind, process, axis)
        notes[key] = note(picked, confidence) if picked is not None else "no axis has a value"
    return notes


def kalibr_text(report: Any, axis: str = "max", inflate: float = 1.0, **overrides: Any) -> str:
    """The ``imu.yaml`` text: every field on its line, each density with its unit, time convention and axes.

    Names from the data (the report's name, channels, the topic) go through the YAML escapes of
    :mod:`avar._escape`: a comment stays one line, a value is quoted, so the file holds these keys
    and no other whatever the names hold."""
    fields = kalibr_fields(report, axis=axis, inflate=inflate, **overrides)
    notes = kalibr_notes(report, axis=axis, **{k: v for k, v in overrides.items() if k in FIELDS.values()})
    source = getattr(report, "name", None) or "a noise report"
    confidence = float(getattr(report, "confidence", 0.95))
    lines = [yaml_comment(line) for line in describe(source, axis, check_inflate(inflate), confidence,
                                                     "Kalibr (imu.yaml): continuous-time densities, SI")]
    for key, value in fields.items():
        if key in UNITS:
            lines.append(yaml_comment(UNITS[key]))
        if key in notes:
            lines.append(yaml_comment(notes[key]))
        lines.append(yaml_entry(key, value))
    try:
        values = imu_values(report, axis=axis, inflate=inflate, export="Kalibr imu.yaml")
    except ValueError:  # a term given explicitly that the data lack: no bias line to add
        values = None
    if values is not None:
        lines += [yaml_comment(line) for line in bias_lines(values, "Kalibr")]
    return "\n".join(lines) + "\n"


def write_kalibr(report: Any, path: Any, force: bool = False, axis: str = "max", inflate: float = 1.0,
                 **overrides: Any) -> Path:
    """Write :func:`kalibr_text` to ``path`` (read back with PyYAML); returns the path.

    The file is written to a temporary file in the same directory and renamed,
    so a failure never leaves a half-written ``imu.yaml``; its mode follows the
    umask (0o666 & ~umask, as any file the user creates). An existing file is
    refused unless ``force=True``, and only a regular file is ever replaced (a
    directory, FIFO, device or symbolic link is refused). A density that is not
    a finite number is refused (Kalibr cannot use ``.nan``). Errors name
    ``path``, never the temporary file.
    """
    text = kalibr_text(report, axis=axis, inflate=inflate, **overrides)  # densities checked finite there
    return write_text(text, path, force=force, source=report.source, what="Kalibr yaml")
