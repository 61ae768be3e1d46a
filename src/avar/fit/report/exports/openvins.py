"""OpenVINS ``kalibr_imu_chain.yaml``: Kalibr's keys under ``imu0``, read by OpenCV ``FileStorage``.

OpenVINS (``ov_msckf``) reads its IMU file through ``ov_core::YamlParser`` (OpenCV
``cv::FileStorage``, so the file starts with ``%YAML:1.0``): ``VioManagerOptions.h``
``print_and_load_noise`` takes ``imu0/gyroscope_noise_density``, ``gyroscope_random_walk``,
``accelerometer_noise_density``, ``accelerometer_random_walk`` as continuous-time densities
(``NoiseManager``), ``StateOptions.h`` reads ``imu0/model`` (``kalibr``, ``calibrated`` or
``rpng``), and ``print_and_load_state`` reads the IMU intrinsics ``Tw``, ``Ta``, ``R_IMUtoACC``,
``R_IMUtoGYRO`` (identity) and ``Tg`` (zero): a missing key fails the parse, so all are written.
The propagator discretizes with the sample interval dt: a white-noise variance sigma^2 / dt
(sigma_d = sigma_c sqrt(rate)) and a bias random-walk variance sigma_b^2 dt (sigma_bd = sigma_b / sqrt(rate)).
"""

from __future__ import annotations

from avar.fit.report.exports.opencv import HEADER, comment, entry
from avar.fit.report.exports.values import ImuValues, bias_lines, header_lines
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["NAME", "DEFAULT_FILE", "NEED", "KEYS", "text"]

NAME = "openvins"
DEFAULT_FILE = "kalibr_imu_chain.yaml"
NEED = (GYRO, ACCEL)
WHITE = "continuous-time white noise; OpenVINS discretizes sigma_d = sigma_c * sqrt(rate) (variance sigma^2/dt)"
WALK = "continuous-time bias random walk; OpenVINS discretizes sigma_bd = sigma_b / sqrt(rate) (variance sigma^2*dt)"
#: Key -> (sensor type, process, unit and convention).
KEYS = {
    "accelerometer_noise_density": (ACCEL, "WN", f"m/s^2/sqrt(Hz), {WHITE}"),
    "accelerometer_random_walk": (ACCEL, "RW", f"m/s^3/sqrt(Hz), {WALK}"),
    "gyroscope_noise_density": (GYRO, "WN", f"rad/s/sqrt(Hz), {WHITE}"),
    "gyroscope_random_walk": (GYRO, "RW", f"rad/s^2/sqrt(Hz), {WALK}"),
}
IDENTITY = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
ZERO = ([0.0, 0.0, 0.0],) * 3
IDENTITY4 = ([1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0])


def _matrix(key: str, rows, note: str) -> list[str]:
    lines = [comment(note, "  "), f"  {key}:"]
    lines += ["    - [" + ", ".join(f"{v:.1f}" for v in row) + "]" for row in rows]
    return lines


def text(values: ImuValues) -> str:
    """The ``kalibr_imu_chain.yaml`` text (OpenCV YAML, ``imu0`` node)."""
    lines = [HEADER] + [comment(line) for line in header_lines(values, "OpenVINS (kalibr_imu_chain.yaml)")]
    lines += [comment("read by ov_msckf VioManagerOptions.h / StateOptions.h through ov_core::YamlParser "
                      "(cv::FileStorage)"), "imu0:"]
    lines += _matrix("T_i_b", IDENTITY4, "IMU to body transform (Kalibr's key; identity)")
    for key, (kind, process, unit) in KEYS.items():
        sensor = values.sensors[kind]
        lines.append(comment(unit, "  "))
        lines.append(comment(sensor.notes[process], "  "))
        lines.append(entry(key, sensor.noise if process == "WN" else sensor.walk, "  "))
    lines.append(entry("rostopic", values.topic, "  "))
    lines.append(comment("s, IMU clock minus the estimator's clock (none measured here)", "  "))
    lines.append(entry("time_offset", 0.0, "  "))
    lines.append(comment("Hz, the nominal sampling rate of the log", "  "))
    lines.append(entry("update_rate", values.rate, "  "))
    lines.append(comment("kalibr: the IMU intrinsics below are Kalibr's (none estimated here: identity, zero)", "  "))
    lines.append(entry("model", "kalibr", "  "))
    lines += _matrix("Tw", IDENTITY, "gyroscope intrinsics (identity: none estimated)")
    lines += _matrix("R_IMUtoGYRO", IDENTITY, "rotation IMU to gyroscope frame (identity)")
    lines += _matrix("Ta", IDENTITY, "accelerometer intrinsics (identity: none estimated)")
    lines += _matrix("R_IMUtoACC", IDENTITY, "rotation IMU to accelerometer frame (identity)")
    lines += _matrix("Tg", ZERO, "gyroscope gravity sensitivity (zero: none estimated)")
    lines += [comment(line) for line in bias_lines(values, "OpenVINS")]
    return "\n".join(lines) + "\n"
