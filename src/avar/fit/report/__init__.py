"""The IMU noise report: :func:`noise_report`, from a log of a real sensor to its datasheet figures.

* :mod:`avar.fit.report.noise_report`: :func:`noise_report`, per channel from the samples to the rows;
* :mod:`avar.fit.report.sensor_fit`, :mod:`~avar.fit.report.sensor_terms`: the noise model chosen by the data;
* :mod:`avar.fit.report.rows`, :mod:`~avar.fit.report.noise_terms`: terms in SI and customary units;
* :mod:`avar.fit.report.checks`: the fit check and the warnings;
* :mod:`avar.fit.report.result`: :class:`NoiseReport`; :mod:`avar.fit.report.exports`: the Kalibr ``imu.yaml`` and every estimator's IMU file.
"""
