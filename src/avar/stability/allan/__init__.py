"""The Allan variance of ``avar()``: R-compatible "mo"/"to" estimates of every column of a table.

``estimator`` (validation and ``avar()``), ``columns`` (the one path of a series and of IMU
channels), ``gaps`` (``nan_policy="omit"``), ``dask`` (Dask arrays and larger-than-memory logs),
``intervals`` (R's errors and the chi-squared band) and ``results`` (``AllanVariance``,
``ImuAllanVariance``). Its compiled loops live in :mod:`avar._kernels.allan`.
"""
