"""Outliers and the robust Allan variance: ``estimator`` (``count_outliers``, ``robust_avar``) and ``results``.

Loops: :mod:`avar._kernels.robust`.
"""
