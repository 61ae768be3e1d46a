"""What every statistic of the family shares: its inputs, grids, registry and result.

``inputs`` (data, rate, data type, confidence, NaN policy: validated once), ``grids`` and
``deviation_grids`` (tau grids and term counts), ``registry`` (one record per public statistic),
``noise_types`` (a fixed noise exponent ``alpha=``) and ``deviation`` (the ``Deviation`` result).
Nothing here imports another folder of :mod:`avar.stability`.
"""
