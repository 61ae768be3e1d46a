"""Estimating latent noise models from an Allan variance.

* :mod:`avar.fit.slopes`: the fixed-slope log-log fit shared by every estimator;
* :mod:`avar.fit.avlr`: :func:`avlr` for series and IMU sensor types alike;
* :mod:`avar.fit.bootstrap`: its parametric bootstrap;
* :mod:`avar.fit.results`: :class:`AvlrResult`, :class:`ImuAvlrResult`;
* :mod:`avar.fit.terms`: a fitted model's terms, each a process class of :mod:`avar.models` with values;
* :mod:`avar.fit.covariance`: the covariance of maximal-overlap Allan variance estimates under a model;
* :mod:`avar.fit.noise_fit`: the joint weighted fit of the IEEE 952 terms;
* :mod:`avar.fit.auto_scales`: where each process dominates (:func:`auto_scales`);
* :mod:`avar.fit.report`: the IMU noise report, :func:`noise_report` (the noise model a real
  sensor's data support, its check, the terms in SI and customary units, warnings, Kalibr);
* :mod:`avar.fit.gmwm`: :func:`gmwm`, the joint estimator (GMWM): its model, implied AV,
  objective, covariance, bootstraps, results and model selection (:func:`select_model`).
"""

from avar.fit.avlr import avlr
from avar.fit.results import AvlrResult, ImuAvlrResult

__all__ = ["AvlrResult", "ImuAvlrResult", "avlr"]
