"""IEEE Std 952 noise terms: names, SI and customary units, conversions.

Every term is a coefficient theta of an Allan deviation AD(tau) = c theta tau^b
(tau in seconds), in the data unit u of the channel:

* QN, quantization Q: AD = sqrt(3) Q / tau, Q in u s;
* WN, angle random walk N: AD = N / sqrt(tau), N in u s^1/2 = u / sqrt(Hz);
* FN, bias instability B: AD = 0.664 B (flat), B in u;
* RW, rate random walk K: AD = K sqrt(tau / 3), K in u s^-1/2 = u / s / sqrt(Hz);
* DR, rate ramp R: AD = R tau / sqrt(2), R in u / s.

For an accelerometer the names are velocity random walk, bias instability,
acceleration random walk. SI units take u = rad/s (gyroscopes) or m/s^2
(accelerometers); customary units (DESIGN "Noise terms"): angle random walk
deg/sqrt(h) = N[deg/s] * 60, bias instability deg/h = B[deg/s] * 3600, rate
random walk deg/h/sqrt(h) = K[deg/s/sqrt(s)] * 3600 * 60; velocity random walk
m/s/sqrt(h) = N[m/s^2] * 60, bias instability ug = B / (9.80665e-6 m/s^2),
acceleration random walk m/s^2/sqrt(h) = K * 60. N in u/sqrt(Hz) and K in
u/s/sqrt(Hz) are Kalibr's ``*_noise_density`` and ``*_random_walk``.

A coefficient's unit follows from its definition: AD(tau) = c theta tau^b in u with
tau in s makes theta u s^-b (b = the term's slope: QN -1, WN -1/2, FN 0, RW 1/2,
DR 1), written with Hz = 1/s as above.

References
----------
IEEE Std 952-1997, Annex C; IEEE Std 1554-2005.
"""

from __future__ import annotations

import math
from typing import NamedTuple

__all__ = ["GYRO_UNITS", "ACCEL_UNITS", "UNIT_SPELLINGS", "TERM_NAMES", "SI_UNITS", "CUSTOMARY", "check_unit", "to_si",
           "Customary", "customary", "unit_of"]

G0 = 9.80665
DEG = math.pi / 180.0
#: Data units of gyroscopes and their value in rad/s.
GYRO_UNITS = {"rad/s": 1.0, "deg/s": DEG, "deg/h": DEG / 3600.0}
#: Data units of accelerometers and their value in m/s^2.
ACCEL_UNITS = {"m/s^2": 1.0, "g": G0, "mg": G0 * 1e-3}
_ALIASES = {"rad/sec": "rad/s", "dps": "deg/s", "deg/sec": "deg/s", "deg/hr": "deg/h", "m/s2": "m/s^2",
            "m/s/s": "m/s^2", "m/s**2": "m/s^2", "milli-g": "mg"}

GYRO, ACCEL = "Gyroscope", "Accelerometer"

#: Every accepted spelling of a data unit per sensor type (any case): the canonical unit, then its aliases.
#: Python (``gyro_units=``, ``accel_units=``) and every subcommand (``--gyro-units``, ``--accel-units``) take these.
UNIT_SPELLINGS = {
    kind: tuple(table) + tuple(alias for alias, unit in _ALIASES.items() if unit in table)
    for kind, table in ((GYRO, GYRO_UNITS), (ACCEL, ACCEL_UNITS))
}

#: Display names of the terms per sensor type (None: a series of unknown type).
TERM_NAMES = {
    GYRO: {"QN": "Quantization", "WN": "Angle random walk", "FN": "Bias instability",
           "RW": "Rate random walk", "DR": "Rate ramp"},
    ACCEL: {"QN": "Quantization", "WN": "Velocity random walk", "FN": "Bias instability",
            "RW": "Acceleration random walk", "DR": "Acceleration ramp"},
    None: {"QN": "Quantization", "WN": "White noise", "FN": "Bias instability (flicker)",
           "RW": "Random walk", "DR": "Ramp"},
}
#: Coefficient units with u the data unit (s: seconds; u s^-b for a term of slope b, sqrt(Hz) = s^-1/2).
GENERIC_UNITS = {"QN": "{u} s", "WN": "{u}/sqrt(Hz)", "FN": "{u}", "RW": "{u}/s/sqrt(Hz)", "DR": "{u}/s"}
#: SI coefficient units.
SI_UNITS = {
    GYRO: {"QN": "rad", "WN": "rad/s/sqrt(Hz)", "FN": "rad/s", "RW": "rad/s^2/sqrt(Hz)", "DR": "rad/s^2"},
    ACCEL: {"QN": "m/s", "WN": "m/s^2/sqrt(Hz)", "FN": "m/s^2", "RW": "m/s^3/sqrt(Hz)", "DR": "m/s^3"},
}
#: Customary unit and factor from the SI coefficient.
CUSTOMARY = {
    GYRO: {"QN": ("deg", 1 / DEG), "WN": ("deg/sqrt(h)", 60 / DEG), "FN": ("deg/h", 3600 / DEG),
           "RW": ("deg/h/sqrt(h)", 3600 * 60 / DEG), "DR": ("deg/h^2", 3600**2 / DEG)},
    ACCEL: {"QN": ("m/s", 1.0), "WN": ("m/s/sqrt(h)", 60.0), "FN": ("ug", 1 / (G0 * 1e-6)),
            "RW": ("m/s^2/sqrt(h)", 60.0), "DR": ("m/s^2/h", 3600.0)},
}


def check_unit(unit: object, sensor_type: str, argument: str) -> str:
    """The canonical spelling of a data unit of ``sensor_type``, or a ValueError naming ``argument``.

    >>> check_unit("dps", "Gyroscope", "gyro_units"), check_unit("g", "Accelerometer", "accel_units")
    ('deg/s', 'g')
    """
    table = GYRO_UNITS if sensor_type == GYRO else ACCEL_UNITS
    if not isinstance(unit, str):
        raise TypeError(f"{argument} must be a string among {list(table)}, got {unit!r}")
    key = _ALIASES.get(unit.strip().lower(), unit.strip())
    key = {k.lower(): k for k in table}.get(key.lower(), key)
    if key not in table:
        raise ValueError(f"{argument}={unit!r} is not a {sensor_type.lower()} unit; use one of {list(table)}")
    return key


def to_si(value: float, sensor_type: str | None, unit: str | None) -> float:
    """A coefficient in data units times the unit's SI value (unchanged for an unknown type).

    >>> round(to_si(1.0, "Gyroscope", "deg/s"), 8)
    0.01745329
    """
    if sensor_type is None or unit is None:
        return value
    table = GYRO_UNITS if sensor_type == GYRO else ACCEL_UNITS
    return value * table[unit]


class Customary(NamedTuple):
    """A coefficient in customary units: its ``value`` and ``unit``."""

    value: float
    unit: str


def customary(term: str, si_value: float, sensor_type: str | None) -> Customary | None:
    """The customary value and unit of an SI coefficient, or None for an unknown sensor type.

    >>> value, unit = customary("WN", 1e-4 * math.pi / 180, "Gyroscope")  # 1e-4 deg/s/sqrt(Hz)
    >>> round(value, 6), unit
    (0.006, 'deg/sqrt(h)')
    """
    if sensor_type not in CUSTOMARY:
        return None
    unit, factor = CUSTOMARY[sensor_type][term]
    return Customary(si_value * factor, unit)


def unit_of(term: str, sensor_type: str | None, data_unit: str | None) -> str:
    """The unit of a coefficient: SI when the sensor type and unit are known, else in data units ``u``.

    >>> unit_of("RW", "Gyroscope", "deg/s"), unit_of("WN", None, None)
    ('rad/s^2/sqrt(Hz)', 'u/sqrt(Hz)')
    """
    if sensor_type in SI_UNITS and data_unit is not None:
        return SI_UNITS[sensor_type][term]
    return GENERIC_UNITS[term].format(u=data_unit or "u")
