"""Reading logs and the shipped data sets.

* :mod:`avar.io.read`: :func:`read`, a log file as a Recording or an IMU;
* :mod:`avar.io.text`, :mod:`avar.io.npy`, :mod:`avar.io.bags`: the file formats;
* :mod:`avar.io.timecols`: time columns, their units, and the rate, jitter and gaps they give;
* :mod:`avar.io.datasets`: the five IMU data sets of the R package, shipped as ``.npz``.
"""
