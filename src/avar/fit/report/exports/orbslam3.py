"""ORB-SLAM3 IMU keys: ``IMU.NoiseGyro``, ``IMU.NoiseAcc``, ``IMU.GyroWalk``, ``IMU.AccWalk``, ``IMU.Frequency``.

ORB-SLAM3 reads its settings with OpenCV ``cv::FileStorage`` (``%YAML:1.0``). ``src/Settings.cc``
``Settings::readIMU`` (settings files with ``File.version: "1.0"``) reads each key as a float
that must be a real number (``isReal()``, so ``200.0``, never ``200``); ``Tracking.cc`` then
builds ``IMU::Calib(Tbc, Ng*sf, Na*sf, Ngw/sf, Naw/sf)`` with ``sf = sqrt(IMU.Frequency)``: the
keys are continuous-time densities and ORB-SLAM3 applies sigma_d = sigma_c sqrt(rate) and
sigma_bd = sigma_b / sqrt(rate) itself. (A settings file without ``File.version`` goes through
``Tracking::ParseIMUParamFile``, which wants ``IMU.Frequency`` as an integer.)
"""

from __future__ import annotations

from avar.fit.report.exports.opencv import HEADER, comment, entry
from avar.fit.report.exports.values import ImuValues, bias_lines, header_lines
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["NAME", "DEFAULT_FILE", "NEED", "KEYS", "text"]

NAME = "orbslam3"
DEFAULT_FILE = "orbslam3_imu.yaml"
NEED = (GYRO, ACCEL)
WHITE = "continuous-time white noise; ORB-SLAM3 uses sigma_d = sigma_c * sqrt(IMU.Frequency)"
WALK = "continuous-time bias random walk; ORB-SLAM3 uses sigma_bd = sigma_b / sqrt(IMU.Frequency)"
KEYS = {
    "IMU.NoiseGyro": (GYRO, "WN", f"rad/s/sqrt(Hz), {WHITE}"),
    "IMU.NoiseAcc": (ACCEL, "WN", f"m/s^2/sqrt(Hz), {WHITE}"),
    "IMU.GyroWalk": (GYRO, "RW", f"rad/s^2/sqrt(Hz), {WALK}"),
    "IMU.AccWalk": (ACCEL, "RW", f"m/s^3/sqrt(Hz), {WALK}"),
}


def text(values: ImuValues) -> str:
    """The ORB-SLAM3 IMU keys (OpenCV YAML): merge them into the settings file."""
    lines = [HEADER] + [comment(line) for line in header_lines(values, "ORB-SLAM3")]
    lines.append(comment("read by ORB-SLAM3 Settings::readIMU (cv::FileStorage, floats); merge these keys into your "
                         "settings file, which also holds IMU.T_b_c1 and the camera keys"))
    for key, (kind, process, unit) in KEYS.items():
        sensor = values.sensors[kind]
        lines.append(comment(unit))
        lines.append(comment(sensor.notes[process]))
        lines.append(entry(key, sensor.noise if process == "WN" else sensor.walk))
    lines.append(comment("Hz, the nominal sampling rate (a real number, as Settings::readIMU requires)"))
    lines.append(entry("IMU.Frequency", float(values.rate)))
    lines += [comment(line) for line in bias_lines(values, "ORB-SLAM3")]
    return "\n".join(lines) + "\n"
