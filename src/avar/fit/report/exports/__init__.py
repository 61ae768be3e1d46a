"""Each visual-inertial estimator's own IMU file from a :class:`~avar.fit.report.result.NoiseReport`.

* :mod:`~avar.fit.report.exports.values`: the values every export writes (IEEE 952 N, K, B per
  sensor type, max or mean over the axes, bounds marked, ``inflate``, B as a Gauss-Markov bias);
* one module per estimator: :mod:`~avar.fit.report.exports.kalibr` (``imu.yaml``),
  :mod:`~avar.fit.report.exports.openvins` (``kalibr_imu_chain.yaml``), :mod:`~avar.fit.report.exports.vins`,
  :mod:`~avar.fit.report.exports.orbslam3`, :mod:`~avar.fit.report.exports.basalt` (JSON),
  :mod:`~avar.fit.report.exports.matlab` (``.m``); :mod:`~avar.fit.report.exports.opencv` the
  OpenCV YAML they share, :mod:`~avar.fit.report.exports.files` the writing;
* :mod:`~avar.fit.report.exports.registry`: :func:`~avar.fit.report.exports.registry.export` by name.
"""
