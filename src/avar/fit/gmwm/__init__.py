"""The joint estimator: :func:`gmwm`, a sum of processes fitted to the Allan variance at all scales.

* :mod:`avar.fit.gmwm.estimator`: :func:`gmwm` and the fit of one Allan variance;
* :mod:`avar.fit.gmwm.model`: which processes, their parameters and transforms;
* :mod:`avar.fit.gmwm.objective`, :mod:`~avar.fit.gmwm.implied`: objective, weights, optimizer, implied AV;
* :mod:`~avar.fit.gmwm.bootstrap`: bootstraps (the exact covariance of the AV estimates of ``weights="efficient"``
  is :mod:`avar.fit.covariance.exact`);
* :mod:`avar.fit.gmwm.results`: :class:`GmwmResult`, :class:`ImuGmwmResult`;
* :mod:`avar.fit.gmwm.selection`: :func:`select_model`.
"""

from avar.fit.gmwm.estimator import empirical_allan_variance, fit_allan_variance, gmwm
from avar.stability.shared.grids import octave_factors

__all__ = ["gmwm", "octave_factors", "empirical_allan_variance", "fit_allan_variance"]
