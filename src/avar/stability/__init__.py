"""Empirical estimators of frequency stability.

* :mod:`avar.stability.shared.grids`: estimator names, tau grids, term counts;
* :mod:`avar.stability.allan.columns`: the Allan variance of every column of a table
  (the one estimation path of series and IMU channels);
* :mod:`avar.stability.allan.estimator`: :func:`avar` (R-compatible "mo"/"to");
* :mod:`avar.stability.allan.intervals`: confidence intervals (R's, chi-squared);
* :mod:`avar.stability.uncertainty.edf`: Greenhall's EDF, chi-squared bounds;
* :mod:`avar.stability.uncertainty.noise_id`: power-law noise identification;
* :mod:`avar.stability.robust.estimator`: outliers and the robust Allan variance;
* :mod:`avar.stability.allan.results`: :class:`AllanVariance`, :class:`ImuAllanVariance`.
"""

from avar.stability.allan.estimator import avar
from avar.stability.allan.results import AllanVariance, ImuAllanVariance

__all__ = ["AllanVariance", "ImuAllanVariance", "avar"]
