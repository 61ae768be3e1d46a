"""The total and Theo statistics: MTOTDEV, TTOTDEV, HTOTDEV, Theo1, ThêoH and TheoBR.

``deviations`` (``mtotdev``, ``ttotdev``, ``htotdev``, ``theo1``), ``mhtot`` (``mhtotdev``), ``theoh`` (Stable32's hybrid of
OADEV and bias-removed Theo1) and ``theobr`` (the bias-removal factor). Their EDF laws and bias
factors live in :mod:`avar.stability.uncertainty.total_edf`; loops in :mod:`avar._kernels.total`.
"""
