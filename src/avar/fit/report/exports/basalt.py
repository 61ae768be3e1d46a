"""Basalt calibration JSON: ``value0`` with ``imu_update_rate`` and the four 3-vectors of noise.

Basalt serializes ``basalt::Calibration`` with cereal (``basalt-headers``
``include/basalt/serialization/headers_serialization.h``): a JSON object whose ``value0``
holds ``T_imu_cam``, ``intrinsics``, ``resolution``, ``calib_accel_bias``, ``calib_gyro_bias``,
``imu_update_rate`` (Hz), ``accel_noise_std``, ``gyro_noise_std``, ``accel_bias_std``,
``gyro_bias_std`` (3-vectors, one value per axis), ``cam_time_offset_ns`` and ``vignette``.
``include/basalt/calibration/calibration.hpp`` states "All noise parameters are continous time":
``*_noise_std`` are white-noise densities (u/sqrt(Hz)) that Basalt converts with
``dicrete_time_*_noise_std() = noise_std * sqrt(imu_update_rate)``, and ``*_bias_std`` are bias
random-walk densities (u/s/sqrt(Hz)). This export writes the IMU keys only (merge them into the
calibration from ``basalt_calibrate``, which holds the camera keys); each 3-vector repeats the
aggregated value. JSON holds no comments: :func:`notes` gives them (the CLI prints them on stderr).
"""

from __future__ import annotations

import json

from avar.fit.report.exports.values import ImuValues, bias_lines, header_lines
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["NAME", "DEFAULT_FILE", "NEED", "KEYS", "notes", "text"]

NAME = "basalt"
DEFAULT_FILE = "basalt_calib.json"
NEED = (GYRO, ACCEL)
WHITE = "continuous-time white noise; Basalt uses sigma_d = sigma_c * sqrt(imu_update_rate)"
WALK = "continuous-time bias random walk (Basalt: all noise parameters are continuous time)"
KEYS = {
    "accel_noise_std": (ACCEL, "WN", f"m/s^2/sqrt(Hz), {WHITE}"),
    "gyro_noise_std": (GYRO, "WN", f"rad/s/sqrt(Hz), {WHITE}"),
    "accel_bias_std": (ACCEL, "RW", f"m/s^3/sqrt(Hz), {WALK}"),
    "gyro_bias_std": (GYRO, "RW", f"rad/s^2/sqrt(Hz), {WALK}"),
}


def text(values: ImuValues) -> str:
    """The JSON text ``{"value0": {...}}`` (floats written so that they read back exactly)."""
    body: dict[str, object] = {"imu_update_rate": float(values.rate)}
    for key, (kind, process, _) in KEYS.items():
        sensor = values.sensors[kind]
        body[key] = [sensor.noise if process == "WN" else sensor.walk] * 3
    return json.dumps({"value0": body}, indent=4) + "\n"


def notes(values: ImuValues) -> list[str]:
    """What the comments of a YAML export would say, one line each: for stderr and the docs."""
    lines = header_lines(values, "Basalt (calibration JSON, value0)")
    lines.append(f"imu_update_rate: Hz, the nominal sampling rate ({values.rate:g})")
    for key, (kind, process, unit) in KEYS.items():
        lines.append(f"{key}: {unit}; {values.sensors[kind].notes[process]}")
    lines += bias_lines(values, "Basalt")
    return lines

