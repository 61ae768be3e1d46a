"""How sure a deviation is: power-law noise identification, equivalent degrees of freedom, chi-squared bounds.

``noise_id`` (lag-1 autocorrelation, B1 ratio, R(n)), ``edf`` (Greenhall and Riley's EDF and the
simple laws), ``total_edf`` (the total and Theo statistics' EDF laws and bias factors) and
``chi2`` (chi-squared bounds and Stable32's quantiles). Loops: :mod:`avar._kernels.uncertainty`.
"""
