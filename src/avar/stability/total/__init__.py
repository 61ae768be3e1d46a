"""The total and Theo statistics: MTOTDEV, TTOTDEV, HTOTDEV, Theo1, ThêoH and TheoBR.

``deviations`` (``mtotdev``, ``ttotdev``, ``htotdev``, ``theo1``), ``mhtot`` (``mhtotdev``), ``theoh`` (Stable32's hybrid of
OADEV and bias-removed Theo1) and ``theobr`` (the bias-removal factor). Their EDF laws and bias
factors live in :mod:`avar.stability.uncertainty.total_edf`; loops in :mod:`avar._kernels.total`, and
their NumPy twins for a first call while those are cold in ``small`` (MTOT/TTOT/HTOT, Theo1),
``small_theobr`` (ThêoH's kf) and ``small_mhtot`` (MHTOTDEV).
"""
