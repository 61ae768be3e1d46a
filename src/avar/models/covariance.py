"""Covariance matrices of the constant-mean processes of Xu et al. (2017).

Each builder returns the exact matrix of R ``avar`` 0.1.3's function of the same
name and argument order (``covmat_bi``'s squared-variance defect aside), so that R
code ported line by line gets the same matrices, ready for
:func:`avar.moav` and :func:`avar.noav`.

References
----------
H. Xu, S. Guerrier, R. Molinari, Y. Zhang, "A study of the Allan variance for
constant-mean non-stationary processes", IEEE Signal Processing Letters
24(8):1257-1260, 2017. doi:10.1109/LSP.2017.2722222
"""

from __future__ import annotations

from typing import Any

import numpy as np

from avar.models.arguments import as_nonnegative, as_phi, as_whole

__all__ = ["covmat_ar1blocks", "covmat_bi", "covmat_nswn"]


# --------------------------------------------------------------------------- covmats
def _check_sizes(**sizes: Any) -> list[int]:
    out = []
    for name, val in sizes.items():
        if np.ndim(val) != 0:
            raise ValueError(f"{name} must be a single whole number, got shape {np.shape(val)}")
        out.append(int(as_whole(val, name)))
    if len(out) == 2 and out[1] > out[0]:
        raise ValueError(f"n_block must be <= n_total, got n_block={out[1]} > n_total={out[0]}")
    return out


def _scalar(x: np.ndarray, name: str) -> float:
    if x.ndim != 0:
        raise ValueError(f"{name} must be a single number, got shape {x.shape}")
    return float(x)


def covmat_ar1blocks(n_total: Any, n_block: Any, phi: Any, sigma2: Any) -> np.ndarray:
    r"""Covariance matrix of an AR(1)-blocks process (block-diagonal).

    The series is cut into ``K = floor(n_total / n_block)`` blocks of ``n_block``
    samples, each an independent stationary AR(1) with coefficient ``phi`` and
    innovation variance ``sigma2``: within a block
    :math:`C_{ij} = \sigma^2 \phi^{|i-j|} / (1 - \phi^2)`, across blocks 0.

    As in R ``avar::covmat_ar1blocks`` (a Kronecker product with a K x K identity),
    the matrix is ``K * n_block`` square: when ``n_total`` is not a multiple of
    ``n_block``, the trailing ``n_total - K * n_block`` samples are left out.

    Parameters
    ----------
    n_total, n_block : int
        Length of the process and of each block (samples), 1 <= n_block <= n_total.
    phi : float
        AR(1) coefficient, ``|phi| < 1``.
    sigma2 : float
        Innovation variance per sample (>= 0).

    Returns
    -------
    numpy.ndarray, shape (K * n_block, K * n_block)

    References
    ----------
    Xu et al. (2017), IEEE Signal Processing Letters 24(8):1257-1260.

    Examples
    --------
    >>> covmat_ar1blocks(4, 2, 0.5, 0.75)
    array([[1. , 0.5, 0. , 0. ],
           [0.5, 1. , 0. , 0. ],
           [0. , 0. , 1. , 0.5],
           [0. , 0. , 0.5, 1. ]])
    """
    nt, nb = _check_sizes(n_total=n_total, n_block=n_block)
    p = _scalar(as_phi(phi), "phi")
    s2 = _scalar(as_nonnegative(sigma2, "sigma2"), "sigma2")
    lag = np.abs(np.subtract.outer(np.arange(nb), np.arange(nb))).astype(np.float64)
    return np.kron(np.eye(nt // nb), s2 / (1.0 - p * p) * p**lag)


def covmat_bi(sigma2: Any, n_total: Any, n_block: Any) -> np.ndarray:
    r"""Covariance matrix of a bias-instability process (block-diagonal, constant blocks).

    The series is cut into ``K = floor(n_total / n_block)`` blocks of ``n_block``
    samples; in each block the process is one level drawn with variance ``sigma2``,
    independently across blocks: the diagonal blocks are filled with ``sigma2``, the
    rest is 0. As in R, the matrix is ``K * n_block`` square (trailing samples that do
    not fill a block are left out).

    R ``avar`` 0.1.3 fills the blocks with ``sigma2^2`` instead of ``sigma2`` (its
    Kronecker product multiplies ``diag(sigma2)`` by ``matrix(sigma2)``); that defect is
    not reproduced (the two agree only for ``sigma2`` in {0, 1}).

    Parameters
    ----------
    sigma2 : float
        Variance of the per-block level (>= 0).
    n_total, n_block : int
        Length of the process and of each block (samples), 1 <= n_block <= n_total.

    Returns
    -------
    numpy.ndarray, shape (K * n_block, K * n_block)

    References
    ----------
    Xu et al. (2017), IEEE Signal Processing Letters 24(8):1257-1260.

    Examples
    --------
    >>> covmat_bi(2.0, 4, 2)
    array([[2., 2., 0., 0.],
           [2., 2., 0., 0.],
           [0., 0., 2., 2.],
           [0., 0., 2., 2.]])
    """
    s2 = _scalar(as_nonnegative(sigma2, "sigma2"), "sigma2")
    nt, nb = _check_sizes(n_total=n_total, n_block=n_block)
    return np.kron(np.eye(nt // nb), np.full((nb, nb), s2))


def covmat_nswn(sigma2: Any, n_total: Any) -> np.ndarray:
    r"""Covariance matrix of a white noise with given per-sample variances (diagonal).

    As R ``avar`` 0.1.3's ``diag(sigma2, n_total, n_total)``: for a scalar
    ``sigma2`` the stationary white noise :math:`C = \sigma^2 I`; for a vector of
    length ``n_total``, :math:`C = \operatorname{diag}(\sigma^2_t)` (per-sample
    variances). The non-stationary white noise of Xu et al. (2017), whose variance
    grows linearly in time, is the vector case ``sigma2 * t`` for t = 1..n_total
    (its MOAV is the white-noise AV of the average variance,
    :math:`\sigma^2 (T + 1) / (2n)`).

    Parameters
    ----------
    sigma2 : float or array_like
        Variance of every sample (>= 0), or the ``n_total`` per-sample variances.
    n_total : int
        Length of the process (samples), >= 1.

    Returns
    -------
    numpy.ndarray, shape (n_total, n_total)

    References
    ----------
    Xu et al. (2017), IEEE Signal Processing Letters 24(8):1257-1260.

    Examples
    --------
    >>> covmat_nswn(0.5, 3)
    array([[0.5, 0. , 0. ],
           [0. , 0.5, 0. ],
           [0. , 0. , 0.5]])
    >>> import numpy as np
    >>> covmat_nswn(0.5 * np.arange(1, 4), 3)    # variance growing linearly in time
    array([[0.5, 0. , 0. ],
           [0. , 1. , 0. ],
           [0. , 0. , 1.5]])
    """
    s2 = as_nonnegative(sigma2, "sigma2")
    (nt,) = _check_sizes(n_total=n_total)
    if s2.ndim == 0:
        return float(s2) * np.eye(nt)
    if s2.shape != (nt,):
        raise ValueError(f"sigma2 must be a scalar or have length n_total = {nt}, "
                         f"got shape {s2.shape}")
    return np.diag(s2)
