"""Latent noise processes and their theoretical Allan variance.

* :mod:`avar.models.base`: what every process is (a model, its sums, simulation, its description as a
  term of a fitted model: variance scale, shape, AV per unit, IEEE 952 slope and coefficient);
* :mod:`avar.models.processes`: WN, QN, RW, DR, AR1;
* :mod:`avar.models.flicker`: flicker (bias instability) noise FN, exact simulation and AV;
* :mod:`avar.models.sinusoid`: a random-phase sinusoid SIN (IEEE 952's sinusoidal term);
* :mod:`avar.models.theory`: closed-form Allan variances (Zhang 2008);
* :mod:`avar.models.nonstationary`: moav/noav of any covariance matrix (Xu et al. 2017);
* :mod:`avar.models.covariance`: the covariance builders of Xu et al. (2017).
"""

from avar.models.base import CompositeModel, NoiseModel, Process
from avar.models.covariance import covmat_ar1blocks, covmat_bi, covmat_nswn
from avar.models.flicker import FN
from avar.models.nonstationary import moav, noav
from avar.models.processes import AR1, DR, QN, RW, WN
from avar.models.sinusoid import SIN
from avar.models.theory import av_ar1, av_dr, av_qn, av_rw, av_wn

__all__ = [
    "AR1", "DR", "FN", "QN", "RW", "SIN", "WN", "CompositeModel", "NoiseModel", "Process",
    "av_ar1", "av_dr", "av_qn", "av_rw", "av_wn",
    "covmat_ar1blocks", "covmat_bi", "covmat_nswn", "moav", "noav",
]
