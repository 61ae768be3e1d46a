"""Empirical estimators of frequency stability.

* :mod:`avar.stability.grids`: estimator names, tau grids, term counts;
* :mod:`avar.stability.columns`: the Allan variance of every column of a table
  (the one estimation path of series and IMU channels);
* :mod:`avar.stability.allan`: :func:`avar` (R-compatible "mo"/"to");
* :mod:`avar.stability.intervals`: confidence intervals (R's, chi-squared);
* :mod:`avar.stability.edf`: Greenhall's EDF, chi-squared bounds;
* :mod:`avar.stability.noise_id`: power-law noise identification;
* :mod:`avar.stability.robust`: outliers and the robust Allan variance;
* :mod:`avar.stability.results`: :class:`AllanVariance`, :class:`ImuAllanVariance`.
"""

from avar.stability.allan import avar
from avar.stability.results import AllanVariance, ImuAllanVariance

__all__ = ["AllanVariance", "ImuAllanVariance", "avar"]
