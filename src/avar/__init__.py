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
    "read_clock_log": "avar.io.clocks.detect",
    "ClockLog": "avar.io.clocks.result",
    "AR1": "avar.models.processes",
    "DR": "avar.models.processes",
    "QN": "avar.models.processes",
    "RW": "avar.models.processes",
    "WN": "avar.models.processes",
    "FN": "avar.models.flicker",
    "SIN": "avar.models.sinusoid",
    "CompositeModel": "avar.models.base",
    "NoiseModel": "avar.models.base",
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
    "avar": "avar.stability.allan.estimator",
    "AllanVariance": "avar.stability.allan.results",
    "ImuAllanVariance": "avar.stability.allan.results",
    "robust_avar": "avar.stability.robust.estimator",
    "count_outliers": "avar.stability.robust.estimator",
    "RobustAllanVariance": "avar.stability.robust.results",
    "Outliers": "avar.stability.robust.results",
    "adev": "avar.stability.classic.deviations",
    "oadev": "avar.stability.classic.deviations",
    "mdev": "avar.stability.classic.deviations",
    "tdev": "avar.stability.classic.deviations",
    "hdev": "avar.stability.classic.deviations",
    "ohdev": "avar.stability.classic.deviations",
    "totdev": "avar.stability.classic.deviations",
    "mhdev": "avar.stability.classic.deviations",
    "htdev": "avar.stability.classic.deviations",
    "mtotdev": "avar.stability.total.deviations",
    "ttotdev": "avar.stability.total.deviations",
    "htotdev": "avar.stability.total.deviations",
    "theo1": "avar.stability.total.deviations",
    "theoh": "avar.stability.total.theoh",
    "mhtotdev": "avar.stability.total.mhtot",
    "dynamic": "avar.stability.dynamic.estimator",
    "dadev": "avar.stability.dynamic.estimator",
    "dhdev": "avar.stability.dynamic.estimator",
    "DynamicDeviation": "avar.stability.dynamic.results",
    "Deviation": "avar.stability.shared.deviation",
    "mtie": "avar.stability.time_error.deviations",
    "tierms": "avar.stability.time_error.deviations",
    "pdev": "avar.stability.time_error.deviations",
    "mask_check": "avar.stability.time_error.masks",
    "MaskCheck": "avar.stability.time_error.masks",
    "Mask": "avar.stability.time_error.masks",
    "MASKS": "avar.stability.time_error.masks",
    "bias_b2": "avar.stability.uncertainty.bias",
    "bias_b3": "avar.stability.uncertainty.bias",
    "dead_time_correction": "avar.stability.uncertainty.bias",
    "phase_to_frequency": "avar.stability.conditioning.conversions",
    "frequency_to_phase": "avar.stability.conditioning.conversions",
    "remove_drift": "avar.stability.conditioning.conversions",
    "Drift": "avar.stability.conditioning.conversions",
    "check": "avar.stability.conditioning.check",
    "CheckReport": "avar.stability.conditioning.check",
    "fill_gaps": "avar.stability.conditioning.resample",
    "average": "avar.stability.conditioning.resample",
    "three_cornered_hat": "avar.stability.time_error.clock_pairs",
    "ThreeCorneredHat": "avar.stability.time_error.clock_pairs",
    "gcodev": "avar.stability.time_error.clock_pairs",
    "Stream": "avar.stability.stream",
    "psd": "avar.stability.spectral.spectrum",
    "psd_to_deviation": "avar.stability.spectral.spectrum",
    "PowerSpectrum": "avar.stability.spectral.spectrum",
    "phase_noise": "avar.stability.spectral.phase_noise",
    "PhaseNoise": "avar.stability.spectral.phase_noise",
    "power_law_adev": "avar.stability.spectral.phase_noise",
    "ssb_to_phase_psd": "avar.stability.spectral.phase_noise",
    "phase_psd_to_ssb": "avar.stability.spectral.phase_noise",
    "phase_psd_to_frequency_psd": "avar.stability.spectral.phase_noise",
    "avlr": "avar.fit.avlr",
    "AvlrResult": "avar.fit.results",
    "ImuAvlrResult": "avar.fit.results",
    "noise_report": "avar.fit.report.noise_report",
    "NoiseReport": "avar.fit.report.result",
    "simulate_log": "avar.fit.report.simulate",
    "recheck": "avar.fit.report.recheck",
    "Recheck": "avar.fit.report.recheck",
    "noise_reports": "avar.fit.report.sessions.several_logs",
    "NoiseReports": "avar.fit.report.sessions.result",
    "auto_scales": "avar.fit.auto_scales",
    "AutoScales": "avar.fit.auto_scales",
    "gmwm": "avar.fit.gmwm",
    "GmwmResult": "avar.fit.gmwm.results",
    "ImuGmwmResult": "avar.fit.gmwm.results",
    "select_model": "avar.fit.gmwm.selection",
    "clock_report": "avar.fit.clock.report",
    "ClockReport": "avar.fit.clock.report",
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
