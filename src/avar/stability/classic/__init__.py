"""The classic deviations of NIST SP 1065: ADEV, OADEV, MDEV, TDEV, HDEV, OHDEV, TOTDEV, MHDEV, HTDEV.

``deviations`` (the public functions: validation, noise identification, EDF, bounds) and ``core``
(their variances and term counts, one core for all). Loops: :mod:`avar._kernels.classic`.
"""
