"""avar: the Allan variance of time series and latent noise model estimation.

The public API is re-exported here lazily (PEP 562): ``import avar`` loads
only this file, and each name imports its module (and NumPy, numba, pandas or
matplotlib) on first use. See ``docs/architecture.md`` for the layers.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

#: Public name -> module that defines it.
_EXPORTS = {
    "IMU": "avar.imu",
    "Recording": "avar.recording",
    "read": "avar.io.read",
    "AR1": "avar.models.processes",
    "DR": "avar.models.processes",
    "QN": "avar.models.processes",
    "RW": "avar.models.processes",
    "WN": "avar.models.processes",
    "FN": "avar.models.flicker",
    "SIN": "avar.models.sinusoid",
    "CompositeModel": "avar.models.processes",
    "NoiseModel": "avar.models.processes",
    "av_ar1": "avar.models.theory",
    "av_dr": "avar.models.theory",
    "av_qn": "avar.models.theory",
    "av_rw": "avar.models.theory",
    "av_wn": "avar.models.theory",
    "moav": "avar.models.nonstationary",
    "noav": "avar.models.nonstationary",
    "covmat_ar1blocks": "avar.models.covariance",
    "covmat_bi": "avar.models.covariance",
    "covmat_nswn": "avar.models.covariance",
    "avar": "avar.stability.allan",
    "AllanVariance": "avar.stability.results",
    "ImuAllanVariance": "avar.stability.results",
    "robust_avar": "avar.stability.robust",
    "count_outliers": "avar.stability.robust",
    "RobustAllanVariance": "avar.stability.robust_results",
    "Outliers": "avar.stability.robust_results",
    "adev": "avar.stability.deviations",
    "oadev": "avar.stability.deviations",
    "mdev": "avar.stability.deviations",
    "tdev": "avar.stability.deviations",
    "hdev": "avar.stability.deviations",
    "ohdev": "avar.stability.deviations",
    "totdev": "avar.stability.deviations",
    "mtotdev": "avar.stability.total",
    "ttotdev": "avar.stability.total",
    "htotdev": "avar.stability.total",
    "theo1": "avar.stability.total",
    "theoh": "avar.stability.theo",
    "Deviation": "avar.stability.deviation_results",
    "mtie": "avar.stability.time_error",
    "tierms": "avar.stability.time_error",
    "pdev": "avar.stability.time_error",
    "phase_to_frequency": "avar.stability.conversions",
    "frequency_to_phase": "avar.stability.conversions",
    "remove_drift": "avar.stability.conversions",
    "Drift": "avar.stability.conversions",
    "three_cornered_hat": "avar.stability.clock_pairs",
    "ThreeCorneredHat": "avar.stability.clock_pairs",
    "gcodev": "avar.stability.clock_pairs",
    "Stream": "avar.stability.stream",
    "psd": "avar.stability.spectrum",
    "psd_to_deviation": "avar.stability.spectrum",
    "PowerSpectrum": "avar.stability.spectrum",
    "avlr": "avar.fit.avlr",
    "AvlrResult": "avar.fit.results",
    "ImuAvlrResult": "avar.fit.results",
    "noise_report": "avar.fit.report.noise_report",
    "NoiseReport": "avar.fit.report.result",
    "auto_scales": "avar.fit.auto_scales",
    "AutoScales": "avar.fit.auto_scales",
    "gmwm": "avar.fit.gmwm",
    "GmwmResult": "avar.fit.gmwm.results",
    "ImuGmwmResult": "avar.fit.gmwm.results",
    "select_model": "avar.fit.gmwm.selection",
    "plot_compare": "avar.plotting.compare",
}

#: Public submodules reached as attributes (``avar.datasets.load(...)``).
_SUBMODULES = {"datasets": "avar.io.datasets", "noise": "avar.models.noise"}

__all__ = sorted([*_EXPORTS, *_SUBMODULES])


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(_SUBMODULES[name])
    else:
        raise AttributeError(f"module 'avar' has no attribute {name!r}")
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
