"""Matplotlib figures of every result; reached through the results' ``.plot()``
methods, :func:`avar.plot_compare` and the command line.

* :mod:`avar.plotting.base`: argument checks, colours, log axes, bands, fit lines;
* :mod:`avar.plotting.single`: one Allan variance (:func:`plot_avar`) and its
  AVLR fit (:func:`plot_avlr`);
* :mod:`avar.plotting.imu`: the grids of IMU results;
* :mod:`avar.plotting.compare`: several Allan variances on one axes;
* :mod:`avar.plotting.report`: the noise-report figure (``NoiseReport.plot()``).
* :mod:`avar.plotting.gmwm`: GMWM fits (:func:`plot_gmwm`, :func:`plot_imu_gmwm`).
* :mod:`avar.plotting.deviation`: the deviation family (:func:`plot_deviation`, ``Deviation.plot()``).
* :mod:`avar.plotting.dynamic`: a dynamic deviation (:func:`plot_dynamic`, ``DynamicDeviation.plot()``).
* :mod:`avar.plotting.masks`: an MTIE or TDEV under an ITU-T mask (:func:`plot_mask_check`, ``MaskCheck.plot()``).

Every figure draws on the ``ax`` (or ``fig``) given or on a new :class:`matplotlib.figure.Figure`
not registered with pyplot (headless, no global state), and returns the Figure.
"""

from avar.plotting.compare import plot_compare
from avar.plotting.deviation import plot_deviation
from avar.plotting.dynamic import plot_dynamic
from avar.plotting.gmwm import plot_gmwm, plot_imu_gmwm
from avar.plotting.imu import plot_imu_avar, plot_imu_avlr
from avar.plotting.masks import plot_mask_check
from avar.plotting.report import plot_report
from avar.plotting.single import plot_avar, plot_avlr

__all__ = ["plot_avar", "plot_avlr", "plot_compare", "plot_deviation", "plot_dynamic", "plot_gmwm", "plot_imu_avar", "plot_imu_avlr", "plot_imu_gmwm",
           "plot_mask_check", "plot_report"]
