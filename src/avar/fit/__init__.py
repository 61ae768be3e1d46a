"""Estimating latent noise models from an Allan variance.

* :mod:`avar.fit.slopes`: the fixed-slope log-log fit shared by every estimator;
* :mod:`avar.fit.avlr`: :func:`avlr` for series and IMU sensor types alike;
* :mod:`avar.fit.bootstrap`: its parametric bootstrap;
* :mod:`avar.fit.results`: :class:`AvlrResult`, :class:`ImuAvlrResult`;
* :mod:`avar.fit.noise_fit`: the joint weighted fit of the IEEE 952 terms;
* :mod:`avar.fit.auto_scales`: where each process dominates (:func:`auto_scales`);
* :mod:`avar.fit.noise_terms`: IEEE 952 term names, SI and customary units;
* :mod:`avar.fit.noise_report`: :func:`noise_report`, whose result is
  :class:`~avar.fit.report_result.NoiseReport`; :mod:`avar.fit.kalibr`: Kalibr ``imu.yaml``.
* :mod:`avar.fit.gmwm`: :func:`gmwm`, the joint estimator (GMWM), with its model
  (``gmwm_model``), implied AV (``gmwm_implied``), objective (``gmwm_objective``),
  bootstraps (``gmwm_bootstrap``) and results (``gmwm_results``);
* :mod:`avar.fit.model_selection`: :func:`select_model`.
"""

from avar.fit.avlr import avlr
from avar.fit.results import AvlrResult, ImuAvlrResult

__all__ = ["AvlrResult", "ImuAvlrResult", "avlr"]
