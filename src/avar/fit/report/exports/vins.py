"""VINS-Mono / VINS-Fusion IMU block: ``acc_n``, ``gyr_n``, ``acc_w``, ``gyr_w``, ``g_norm``, ``imu_topic``.

Both read their config with OpenCV ``cv::FileStorage`` (``%YAML:1.0``):
VINS-Fusion ``vins_estimator/src/estimator/parameters.cpp`` ``readParameters`` takes ``imu``
(1: use the IMU), ``imu_topic``, ``acc_n``, ``acc_w``, ``gyr_n``, ``gyr_w`` and ``g_norm``;
VINS-Mono's ``parameters.cpp`` the same without ``imu``.

VINS applies no rate conversion: ``integration_base.h`` puts ``acc_n^2``, ``gyr_n^2`` in the
noise covariance of each IMU *sample* (its midpoint propagation weighs them by dt / 2) and
``acc_w^2``, ``gyr_w^2`` in that of each step of the bias, weighed by dt (``V.block(9, 12) = I dt``),
so the bias variance added per step is ``acc_w^2 dt^2``. The values that give VINS the
covariance of the continuous-time model (white noise sigma_c^2 / dt per sample, bias random
walk sigma_b^2 dt per step) are therefore the *discrete-time* ones

    acc_n = N sqrt(rate),   acc_w = K sqrt(rate)   (rate = 1 / dt, Hz),

which this export writes (a comment gives the continuous-time N and K too). (The midpoint
scheme counts each sample's noise in two steps as two independent halves, so its velocity
increments get half the variance of the continuous model even then: ``inflate`` covers it.) The white-noise
rule is the one VINS users are given (HKUST-Aerial-Robotics/VINS-Mono issues #102 and #280:
the parameters are discrete; divide N by sqrt(dt)); the random-walk rule follows from the code above.
"""

from __future__ import annotations

import math

from avar.fit.report.exports.opencv import HEADER, comment, entry
from avar.fit.report.exports.values import ImuValues, bias_lines, header_lines
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["NAME", "DEFAULT_FILE", "NEED", "KEYS", "STANDARD_GRAVITY", "discrete", "text"]

NAME = "vins"
DEFAULT_FILE = "vins_imu.yaml"
NEED = (GYRO, ACCEL)
STANDARD_GRAVITY = 9.80665
WHITE = ("discrete-time std of one sample's white noise: N * sqrt(rate) (integration_base.h uses its square per "
         "sample, no rate conversion)")
WALK = ("discrete-time bias random walk: K * sqrt(rate) (integration_base.h adds its square times dt^2 per step, "
        "so that the bias variance grows by K^2 dt per step, no rate conversion)")
KEYS = {
    "acc_n": (ACCEL, "WN", f"m/s^2, {WHITE}", "m/s^2/sqrt(Hz)"),
    "gyr_n": (GYRO, "WN", f"rad/s, {WHITE}", "rad/s/sqrt(Hz)"),
    "acc_w": (ACCEL, "RW", f"m/s^3 (m/s^3/sqrt(Hz) * sqrt(Hz)), {WALK}", "m/s^3/sqrt(Hz)"),
    "gyr_w": (GYRO, "RW", f"rad/s^2 (rad/s^2/sqrt(Hz) * sqrt(Hz)), {WALK}", "rad/s^2/sqrt(Hz)"),
}


def discrete(density: float, rate: float) -> float:
    """The VINS value of a continuous-time density (N or K) at ``rate`` Hz: density * sqrt(rate).

    >>> discrete(1e-3, 400.0)
    0.02
    """
    return density * math.sqrt(rate)


def text(values: ImuValues) -> str:
    """The VINS IMU block (OpenCV YAML): merge it into the estimator's config file."""
    lines = [HEADER] + [comment(line) for line in header_lines(values, "VINS-Mono / VINS-Fusion")]
    lines.append(comment("read by vins_estimator parameters.cpp readParameters (cv::FileStorage); merge these keys "
                         "into your config, which also holds the camera keys"))
    lines.append(comment("1: use the IMU (VINS-Fusion; VINS-Mono ignores the key)"))
    lines.append(entry("imu", 1))
    lines.append(entry("imu_topic", values.topic))
    for key, (kind, process, unit, density_unit) in KEYS.items():
        sensor = values.sensors[kind]
        density = sensor.noise if process == "WN" else sensor.walk
        lines.append(comment(unit))
        lines.append(comment(f"continuous-time value {density:.9g} {density_unit} (Kalibr's) at rate "
                             f"{values.rate:g} Hz; {sensor.notes[process]}"))
        lines.append(entry(key, discrete(density, values.rate)))
    lines.append(comment("m/s^2, gravity magnitude: standard gravity 9.80665 (not measured here; put your local value)"))
    lines.append(entry("g_norm", STANDARD_GRAVITY))
    lines += [comment(line) for line in bias_lines(values, "VINS")]
    return "\n".join(lines) + "\n"
