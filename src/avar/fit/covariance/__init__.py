"""The covariance of maximal-overlap Allan variance estimates under a Gaussian noise model: its one home.

For a series x_1..x_N whose first differences d_t = x_t - x_{t-1} are
stationary (every term of :mod:`avar.models` but the sinusoid qualifies), the
maximal-overlap AV at averaging factor m is a quadratic form in d, and for
Gaussian d (Isserlis) the covariance of two estimates is exactly::

    Cov(nu_hat_j, nu_hat_k) = 1 / (M_j M_k) sum_h c_jk(h) [2 gamma_jk(h)^2 + 4 mu_j mu_k gamma_jk(h)],

M_j = N - 2 m_j + 1 the number of terms, c_jk(h) the number of pairs at lag h,
mu the means a ramp gives and gamma_jk the cross-covariance of the
Allan-filtered series (:mod:`~avar.fit.covariance.formula`, the pieces both
algorithms share). Two algorithms evaluate it, on the same model description
(a sum of processes or the components of :func:`avar.fit.terms.components_of`):

* :mod:`avar.fit.covariance.exact`: :func:`~avar.fit.covariance.exact.exact_covariance`,
  gamma_jk by FFT from the increments' autocovariance, every lag summed: WN, QN,
  RW, DR and AR1 (the GMWM's ``weights="efficient"``, and the plain twin of the other);
* :mod:`avar.fit.covariance.structure`: :func:`~avar.fit.covariance.structure.structure_covariance`,
  gamma_jk from the model's structure function and its second cumulative sums,
  the lags summed sparsely (to :data:`~avar.fit.covariance.structure.ACCURACY`) at any N,
  flicker included (the noise report's sandwich intervals), a Gauss-Markov term's second sums
  from :mod:`avar.fit.covariance.markov` (a short table, then closed form).

References
----------
D. B. Percival, A. T. Walden, Wavelet Methods for Time Series Analysis, 2000, ch. 8.
"""
