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
nominal rate, Hz). Each density is the largest over the axes (or their mean);
a term the data do not resolve contributes its 95 % upper bound, and a
comment above every density gives the axes' values and says so.
N is the Allan deviation of the white noise at tau = 1 s and K that of the
random walk at tau = 3 s (AD = K sqrt(tau / 3)), as Kalibr defines them.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from avar._escape import yaml_comment, yaml_entry
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["kalibr_fields", "kalibr_notes", "kalibr_text", "write_kalibr", "axis_values", "nominal_rate",
           "DEFAULT_TOPIC"]

#: Topic written when the data did not come from a bag (Kalibr's example).
DEFAULT_TOPIC = "/imu0"
FIELDS = {
    (GYRO, "WN"): "gyroscope_noise_density",
    (GYRO, "RW"): "gyroscope_random_walk",
    (ACCEL, "WN"): "accelerometer_noise_density",
    (ACCEL, "RW"): "accelerometer_random_walk",
}


AGGREGATIONS = ("max", "mean")


def axis_values(report: Any, kind: str, process: str) -> list[tuple[str, float, str]]:
    """(channel, value in SI, status) of one term on every axis of a sensor type: the value, or the upper
    bound of a term the data do not resolve (status ``bound``); axes where it is absent are left out."""
    table = report.terms
    rows = table[(table["Sensor"] == kind) & (table["Process"] == process)]
    out = []
    for _, row in rows.iterrows():
        name = str(row.get("Channel", kind))
        if row["Status"] == "present":
            out.append((name, float(row["Value"]), "present"))
        elif row["Status"] == "bound":
            out.append((name, float(row["Upper"]), "bound"))
    return out


def nominal_rate(rate: float) -> float:
    """The rate a datasheet states: 199.9999999957 -> 200.0 (kept when not within 1e-6 of a whole number)."""
    whole = round(rate)
    return float(whole) if whole > 0 and abs(rate - whole) <= 1e-6 * rate else float(rate)


def kalibr_fields(report: Any, rostopic: str | None = None, update_rate: float | None = None,
                  axis: str = "max", **densities: float) -> dict[str, Any]:
    """The ``imu.yaml`` fields of a report, in Kalibr's order.

    Each density aggregates the axes of its sensor type: ``axis="max"``
    (default, conservative: the noisiest axis) or ``"mean"``. On an axis where
    the data do not resolve a term (a random walk too small for the record),
    its 95 % upper bound stands in; :func:`kalibr_notes` says so. A value is
    written for every key of the sensor types present. ``rostopic`` defaults
    to the report's topic (the bag topic), else ``"/imu0"``; ``update_rate`` to
    the report's nominal rate. Any field may be given explicitly
    (``gyroscope_random_walk=4e-5``).

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
    if axis not in AGGREGATIONS:
        raise ValueError(f"axis must be 'max' (the noisiest axis) or 'mean', got {axis!r}")
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
                values = [v for _, v, _ in axis_values(report, kind, process)]
                if not values:
                    raise ValueError(f"{key}: no {kind.lower()} axis has a value or a bound for it; "
                                     f"give {key}=... explicitly")
                value = max(values) if axis == "max" else float(np.mean(values))
            fields[key] = float(value)
    bad = [key for key, value in fields.items() if not np.isfinite(value) or value < 0]
    if bad:
        raise ValueError(f"the Kalibr field(s) {bad} are not finite numbers >= 0; give them explicitly "
                         f"(e.g. {bad[0]}=...)")
    fields = dict(sorted(fields.items(), key=lambda kv: list(FIELDS.values()).index(kv[0])))
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
    notes = {}
    for (kind, process), key in FIELDS.items():
        if kind not in report.sensor_types:
            continue
        if key in given:
            notes[key] = "given explicitly"
            continue
        values = axis_values(report, kind, process)
        parts = ", ".join(f"{name} {value:.4g}" + (" (95 % upper bound)" if status == "bound" else "")
                          for name, value, status in values)
        text = f"{'largest' if axis == 'max' else 'mean'} over the axes: {parts}"
        bounded = [name for name, _, status in values if status == "bound"]
        if bounded:
            text += f"; not resolved on {', '.join(bounded)}: an upper bound, not a measurement"
        notes[key] = text
    return notes


def kalibr_text(report: Any, axis: str = "max", **overrides: Any) -> str:
    """The ``imu.yaml`` text: every field on its line, each density with its comment.

    Names from the data (the report's name, channels, the topic) go through the YAML escapes of
    :mod:`avar._escape`: a comment stays one line, a value is quoted, so the file holds these keys
    and no other whatever the names hold."""
    fields = kalibr_fields(report, axis=axis, **overrides)
    notes = kalibr_notes(report, axis=axis, **{k: v for k, v in overrides.items() if k in FIELDS.values()})
    source = getattr(report, "name", None) or "a noise report"
    lines = [yaml_comment(f"IMU noise model written by avar from {source}: Kalibr's continuous-time densities (SI)")]
    for key, value in fields.items():
        if key in notes:
            lines.append(yaml_comment(notes[key]))
        lines.append(yaml_entry(key, value))
    return "\n".join(lines) + "\n"


def write_kalibr(report: Any, path: Any, force: bool = False, axis: str = "max", **overrides: Any) -> Path:
    """Write :func:`kalibr_fields` to ``path`` as YAML (PyYAML); returns the path.

    The file is written to a temporary file in the same directory and renamed,
    so a failure never leaves a half-written ``imu.yaml``; its mode follows the
    umask (0o666 & ~umask, as any file the user creates). An existing file is
    refused unless ``force=True``, and only a regular file is ever replaced (a
    directory, FIFO, device or symbolic link is refused). A density that is not
    a finite number is refused (Kalibr cannot use ``.nan``). Errors name
    ``path``, never the temporary file.
    """
    import stat

    text = kalibr_text(report, axis=axis, **overrides).encode("utf-8")  # densities checked finite there
    target = Path(path)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        info = None
    if info is not None and not stat.S_ISREG(info.st_mode):
        raise ValueError(f"path {str(target)!r} exists and is not a regular file (a directory, link, FIFO or "
                         "device); give a file name")
    if info is not None and not force:
        raise FileExistsError(f"{target} exists; pass force=True to overwrite it")
    if report.source is not None and target.resolve() == Path(report.source).resolve():
        raise ValueError(f"{target} is the input file; choose another path")
    umask = os.umask(0)
    os.umask(umask)
    temporary = None
    try:
        handle, temporary = tempfile.mkstemp(dir=target.parent if str(target.parent) else ".", prefix=".imu.",
                                             suffix=".yaml.part")
        with os.fdopen(handle, "wb") as out:
            out.write(text)
        os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, target)
    except OSError as error:
        raise OSError(error.errno, f"{target}: cannot write the Kalibr yaml ({error.strerror})") from None
    finally:
        if temporary is not None and os.path.exists(temporary):
            os.unlink(temporary)
    return target
