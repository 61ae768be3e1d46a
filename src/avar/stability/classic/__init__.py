"""The classic deviations of NIST SP 1065: ADEV, OADEV, MDEV, TDEV, HDEV, OHDEV, TOTDEV.

``deviations`` (the public functions: validation, noise identification, EDF, bounds) and ``core``
(their variances and term counts, one core for all seven). Loops: :mod:`avar._kernels.classic`.
"""
