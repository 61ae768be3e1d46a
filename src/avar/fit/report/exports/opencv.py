"""The OpenCV ``FileStorage`` YAML that OpenVINS, VINS-Mono/VINS-Fusion and ORB-SLAM3 read.

OpenCV's reader wants ``%YAML:1.0`` on the first line, a mapping at the top, real numbers that
look real (a ``.`` or an exponent: ORB-SLAM3 checks ``isReal()``) and strings in double quotes.
Comments (``#``) stay on one line whatever names from the data hold (:func:`avar._escape.yaml_comment`).
"""

from __future__ import annotations

from typing import Any

from avar._escape import yaml_comment
from avar.fit.report.exports.values import number

__all__ = ["HEADER", "comment", "entry", "quoted"]

HEADER = "%YAML:1.0"


def quoted(text: str, key: str) -> str:
    """A double-quoted OpenCV string (``\\`` and ``"`` escaped); a control character is refused.

    >>> quoted('/imu0', 'rostopic')
    '"/imu0"'
    """
    if not isinstance(text, str) or not text or not text.isprintable():
        raise ValueError(f"{key} {text!r} cannot be written in an OpenCV yaml (empty, or a control or format "
                         "character); give another topic")
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def entry(key: str, value: Any, indent: str = "") -> str:
    """``key: value`` with a float written so that it reads back to the same double."""
    if isinstance(value, str):
        return f"{indent}{key}: {quoted(value, key)}"
    if isinstance(value, bool) or isinstance(value, int):
        return f"{indent}{key}: {int(value)}"
    return f"{indent}{key}: {number(value)}"


def comment(text: str, indent: str = "") -> str:
    """One comment line (names from the data escaped)."""
    return indent + yaml_comment(text)
