"""Exports by name: :func:`export` (text, and a file when a path is given), the default file names.

=============  ==========================  =================================================
name           default file                read by
=============  ==========================  =================================================
``kalibr``     ``imu.yaml``                Kalibr (PyYAML), allan_variance_ros
``openvins``   ``kalibr_imu_chain.yaml``   OpenVINS ov_core::YamlParser (cv::FileStorage)
``vins``       ``vins_imu.yaml``           VINS-Mono / VINS-Fusion parameters.cpp (cv::FileStorage)
``orbslam3``   ``orbslam3_imu.yaml``       ORB-SLAM3 Settings::readIMU (cv::FileStorage)
``basalt``     ``basalt_calib.json``       Basalt calibration (cereal JSON)
``matlab``     ``imu_params.m``            MATLAB gyroparams / accelparams / imuSensor
=============  ==========================  =================================================
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from avar.fit.report.exports import basalt, matlab, openvins, orbslam3, vins
from avar.fit.report.exports.files import write_text
from avar.fit.report.exports.kalibr import kalibr_text
from avar.fit.report.exports.values import check_axis, check_inflate, imu_values

__all__ = ["EXPORTS", "DEFAULT_FILES", "export", "export_notes", "export_text"]

_MODULES = {module.NAME: module for module in (openvins, vins, orbslam3, basalt, matlab)}
#: Every export's name, in the order the docs list them.
EXPORTS = ("kalibr", "openvins", "vins", "orbslam3", "basalt", "matlab")
#: The file each export writes when no path is given.
DEFAULT_FILES = {"kalibr": "imu.yaml", **{name: module.DEFAULT_FILE for name, module in _MODULES.items()}}


def _check_name(name: Any) -> str:
    if name not in EXPORTS:
        raise ValueError(f"name must be one of {list(EXPORTS)}, got {name!r}")
    return name


def export_text(report: Any, name: str, axis: str = "max", inflate: float = 1.0) -> str:
    """The text of export ``name`` (see the table above): N and K times ``inflate``, aggregated by ``axis``."""
    _check_name(name)
    check_axis(axis)
    inflate = check_inflate(inflate)
    if name == "kalibr":
        return kalibr_text(report, axis=axis, inflate=inflate)
    module = _MODULES[name]
    values = imu_values(report, axis=axis, inflate=inflate, need=module.NEED, export=f"the {name} export")
    return module.text(values)


def export_notes(report: Any, name: str, axis: str = "max", inflate: float = 1.0) -> list[str]:
    """The comments a format cannot hold (JSON: ``basalt``), one line each; empty for the others."""
    _check_name(name)
    if name != "basalt":
        return []
    values = imu_values(report, axis=axis, inflate=inflate, need=basalt.NEED, export="the basalt export")
    return basalt.notes(values)


def export(report: Any, name: str, path: Any = None, axis: str = "max", inflate: float = 1.0,
           force: bool = False) -> str:
    """The text of an estimator's IMU file; written to ``path`` too when given (``True``: the default name).

    Parameters
    ----------
    report : NoiseReport
        The report whose IEEE 952 terms are written (N, K and B of each sensor type, SI).
    name : str
        ``"kalibr"``, ``"openvins"``, ``"vins"``, ``"orbslam3"``, ``"basalt"`` or ``"matlab"``.
    path : str or Path, optional
        The file to write (refused if it exists, unless ``force``; never the input, a link or a device).
    axis : {"max", "mean"}
        One value per sensor type: the largest over its axes (default) or their mean.
    inflate : float
        Factor (> 0) on the noise densities and random walks written (not on B, not on the table).

    Returns
    -------
    str
        The file's text.

    Examples
    --------
    >>> import avar
    >>> x = (avar.WN(sigma2=4e-6) + avar.RW(gamma2=1e-12)).simulate(100_000, seed=3)
    >>> text = avar.noise_report(x, gyro_units="rad/s", rate=200.0).export("matlab", inflate=10)
    >>> [line for line in text.splitlines() if line.startswith("gyro.")][0][:24]
    'gyro.NoiseDensity = 0.00'
    """
    text = export_text(report, name, axis=axis, inflate=inflate)
    if path is not None:
        target = Path(DEFAULT_FILES[name]) if path is True else Path(path)
        write_text(text, target, force=force, source=getattr(report, "source", None), what=f"{name} export")
    return text

