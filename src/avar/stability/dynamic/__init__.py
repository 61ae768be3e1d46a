"""Dynamic deviations (Stable32's DAVAR): a classic statistic in every window of a sliding window.

``estimator`` (``dynamic``, ``dadev``, ``dhdev``: validation, the windows' levels, noise, EDF and
bounds) and ``results`` (``DynamicDeviation``). Loops: :mod:`avar._kernels.dynamic`.
"""
