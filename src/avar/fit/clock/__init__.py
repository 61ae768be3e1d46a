"""A clock's noise model, as the noise report gives a sensor's: the power-law coefficients h_alpha
and the diffusion coefficients q of the Kalman clock models, fitted jointly over all taus.

``coefficients`` (the exact conversions between the per-sample processes GMWM fits and h_alpha, q)
and ``report`` (:func:`clock_report` and its :class:`ClockReport`).
"""

from avar.fit.clock.report import ClockReport, clock_report

__all__ = ["ClockReport", "clock_report"]
