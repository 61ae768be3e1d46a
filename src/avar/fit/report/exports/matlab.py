"""A MATLAB script building ``gyroparams`` / ``accelparams`` and an ``imuSensor`` (Navigation / Sensor Fusion toolboxes).

MATLAB's ``gyroparams`` and ``accelparams`` take continuous-time terms, the same as IEEE 952's:
``NoiseDensity`` ((rad/s)/sqrt(Hz), (m/s^2)/sqrt(Hz)) is N, ``RandomWalk`` ((rad/s)*sqrt(Hz),
(m/s^2)*sqrt(Hz), i.e. rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz)) is K, and ``BiasInstability`` (rad/s,
m/s^2) is B, the level whose flat Allan deviation is 0.664 B, as MathWorks' example *Inertial
Sensor Noise Analysis Using Allan Variance* reads it. ``imuSensor`` discretizes them itself with
its ``SampleRate``. ``inflate`` multiplies NoiseDensity and RandomWalk, never BiasInstability.
"""

from __future__ import annotations

from avar._escape import terminal
from avar.fit.report.exports.values import ImuValues, header_lines, number
from avar.fit.report.noise_terms import ACCEL, GYRO

__all__ = ["NAME", "DEFAULT_FILE", "NEED", "PROPERTIES", "text"]

NAME = "matlab"
DEFAULT_FILE = "imu_params.m"
NEED = ()
#: Variable, constructor, and per property (report field, unit) of each sensor type.
PROPERTIES = {
    GYRO: ("gyro", "gyroparams", {"NoiseDensity": ("noise", "(rad/s)/sqrt(Hz), continuous time (N)"),
                                  "RandomWalk": ("walk", "(rad/s)*sqrt(Hz), continuous time (K)"),
                                  "BiasInstability": ("bias", "rad/s (B, AD = 0.664 B; not inflated)")}),
    ACCEL: ("accel", "accelparams", {"NoiseDensity": ("noise", "(m/s^2)/sqrt(Hz), continuous time (N)"),
                                     "RandomWalk": ("walk", "(m/s^2)*sqrt(Hz), continuous time (K)"),
                                     "BiasInstability": ("bias", "m/s^2 (B, AD = 0.664 B; not inflated)")}),
}
PROCESS = {"noise": "WN", "walk": "RW", "bias": "FN"}


def _comment(text: str) -> str:
    return "% " + terminal(text)


def text(values: ImuValues) -> str:
    """The ``.m`` script: one ``gyroparams``/``accelparams`` per sensor type present, then an ``imuSensor``."""
    lines = [_comment(line) for line in header_lines(values, "MATLAB imuSensor (gyroparams / accelparams)")]
    lines.append(_comment("imuSensor discretizes these continuous-time terms with its SampleRate"))
    made = []
    for kind, (variable, constructor, properties) in PROPERTIES.items():
        sensor = values.sensors.get(kind)
        if sensor is None:
            continue
        lines.append("")
        lines.append(f"{variable} = {constructor}();")
        for prop, (field, unit) in properties.items():
            value = getattr(sensor, field)
            if value is None:
                lines.append(_comment(f"{prop}: the report has no value for it (left at MATLAB's default)"))
                continue
            note = sensor.notes.get(PROCESS[field], "")
            lines.append(_comment(f"{prop}: {unit}; {note}"))
            lines.append(f"{variable}.{prop} = {number(value)};")
        made.append((variable, kind))
    if len(made) < 2:
        lines.append("")
        lines.append(_comment("the report has one sensor type: the other keeps imuSensor's ideal default"))
    arguments = ["'accel-gyro'", f"'SampleRate', {number(values.rate)}"]
    arguments += [f"'{'Gyroscope' if kind == GYRO else 'Accelerometer'}', {variable}" for variable, kind in made]
    lines.append("")
    lines.append(f"imu = imuSensor({', '.join(arguments)});")
    return "\n".join(lines) + "\n"
