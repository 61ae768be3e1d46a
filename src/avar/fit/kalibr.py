"""Kalibr ``imu.yaml`` from a :class:`~avar.fit.report_result.NoiseReport`.

Kalibr (and ``allan_variance_ros``) describe an IMU by four continuous-time
densities in SI units, each the mean over the axes of a sensor type:

=================================  ===========================================
``gyroscope_noise_density``        angle random walk N, rad/s/sqrt(Hz)
``gyroscope_random_walk``          rate random walk K, rad/s^2/sqrt(Hz)
``accelerometer_noise_density``    velocity random walk N, m/s^2/sqrt(Hz)
``accelerometer_random_walk``      acceleration random walk K, m/s^3/sqrt(Hz)
=================================  ===========================================

plus ``rostopic`` (the bag topic the data came from) and ``update_rate`` (Hz).
N is the Allan deviation of the white noise at tau = 1 s and K that of the
random walk at tau = 3 s (AD = K sqrt(tau / 3)), as Kalibr defines them.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from avar.fit.noise_terms import ACCEL, GYRO

__all__ = ["kalibr_fields", "write_kalibr", "DEFAULT_TOPIC"]

#: Topic written when the data did not come from a bag (Kalibr's example).
DEFAULT_TOPIC = "/imu0"
FIELDS = {
    (GYRO, "WN"): "gyroscope_noise_density",
    (GYRO, "RW"): "gyroscope_random_walk",
    (ACCEL, "WN"): "accelerometer_noise_density",
    (ACCEL, "RW"): "accelerometer_random_walk",
}


def _mean_over_axes(report: Any, kind: str, process: str) -> float | None:
    table = report.terms
    rows = table[(table["Sensor"] == kind) & (table["Process"] == process) & (table["Status"] == "present")]
    return float(np.mean(rows["Value"].to_numpy(dtype=np.float64))) if len(rows) else None


def kalibr_fields(report: Any, rostopic: str | None = None, update_rate: float | None = None,
                  **densities: float) -> dict[str, Any]:
    """The ``imu.yaml`` fields of a report, in Kalibr's order.

    Each density is the mean over the axes of its sensor type on which the
    term is present. ``rostopic`` defaults to the report's topic (the bag
    topic), else ``"/imu0"``; ``update_rate`` to the report's rate. Any field
    may be given explicitly (``gyroscope_random_walk=4e-5``), e.g. when the
    record is too short to show a random walk: a density absent on every axis
    is otherwise an error, never a silent 0 or NaN.

    Examples
    --------
    >>> import avar
    >>> x = (avar.WN(sigma2=4e-6) + avar.RW(gamma2=1e-12)).simulate(400_000, seed=3)
    >>> fields = avar.noise_report(x, gyro_units="rad/s", freq=200.0).kalibr()
    >>> list(fields)
    ['gyroscope_noise_density', 'gyroscope_random_walk', 'rostopic', 'update_rate']
    >>> round(fields["gyroscope_noise_density"], 6), fields["update_rate"]
    (0.000141, 200.0)
    """
    unknown = set(densities) - set(FIELDS.values())
    if unknown:
        raise TypeError(f"unknown Kalibr field(s) {sorted(unknown)}; give {list(FIELDS.values())}, rostopic, update_rate")
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
                value = _mean_over_axes(report, kind, process)
            if value is None:
                raise ValueError(
                    f"{key}: the {kind.lower()} {'white noise' if process == 'WN' else 'random walk'} is absent "
                    f"on every axis (the record is too short or too quiet to show it); give {key}=... explicitly"
                )
            fields[key] = float(value)
    fields = dict(sorted(fields.items(), key=lambda kv: list(FIELDS.values()).index(kv[0])))
    topic = rostopic if rostopic is not None else (report.topic or DEFAULT_TOPIC)
    if not isinstance(topic, str) or not topic:
        raise TypeError(f"rostopic must be a non-empty string, got {topic!r}")
    rate = float(report.freq if update_rate is None else update_rate)
    if not np.isfinite(rate) or rate <= 0:
        raise ValueError(f"update_rate must be a finite rate > 0 (Hz), got {update_rate!r}")
    fields["rostopic"] = topic
    fields["update_rate"] = rate
    return fields


def write_kalibr(report: Any, path: Any, force: bool = False, **overrides: Any) -> Path:
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

    import yaml

    fields = kalibr_fields(report, **overrides)
    bad = [key for key, value in fields.items() if isinstance(value, float) and not np.isfinite(value)]
    if bad:
        raise ValueError(f"the Kalibr field(s) {bad} are not finite numbers; give them explicitly (e.g. {bad[0]}=...)")
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
    text = yaml.safe_dump(fields, sort_keys=False, default_flow_style=False).encode("utf-8")
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
