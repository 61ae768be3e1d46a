"""Theoretical Allan variance of constant-mean (possibly non-stationary) processes.

For a zero-mean process x_1..x_T with covariance matrix C, the theoretical AV at
averaging factor n is half the variance of the difference of two adjacent n-means,
averaged over the windows of the estimator (Xu et al. 2017): ``moav`` uses the
W = T - 2n + 1 windows starting at 0, 1, ..., T - 2n; ``noav`` the M = floor(T / (2n))
disjoint pairs of blocks (window starts 0, 2n, 4n, ...). With w = (-1 x n, +1 x n)
and C_s the 2n x 2n diagonal block at s, the window variance is w' C_s w / n^2.

Algorithm. R ``avar`` 0.1.3 sums n x n sub-blocks per window: O(T n^2) per scale.
Here the entries of C are grouped by diagonal, c_d(i) = C[i, i + d]:

    sum_{s<W} w' C_s w = sum_{d<2n} mult_d sum_{m<2n-d} u_d(m) sum_{s<W} c_d(s + m)

(mult_0 = 1, else 2; u_d(m) = w_m w_(m+d)). The inner sum is the whole diagonal, D_d,
less a head of m and a tail of 2n-1-d-m entries, so with rho_d = sum_m u_d(m) (2n - 3d
for d < n, d - 2n after) the total is sum_d mult_d [rho_d D_d - sum_{i<2n-1-d} a_d(i)
(c_d(i) + c_d(T-d-1-i))], where a_d(i) = sum_{m>i} u_d(m) is a tent made of three
ramps, (2n-1-d-i)_+ - 2 (n-1-i)_+ + 2 (n-1-d-i)_+. Only the diagonal sums and the two
corners (top-left, plus bottom-right folded onto it) enter, the corners through the
second-order prefix sums H[x, d] = sum_{i<x} (x - i) F[i, d] of the folded entries F;
summed along anti-diagonals and rows, H gives three numbers per scale. One pass over C
(numba, ``avar._kernels.covariance_pass``) checks the matrix (finite, symmetric) and
gathers D_d and these corner sums for all scales: it reads the T^2 entries once, works
O(T max(n)), and each scale then costs O(n). NOAV sums, in the same pass, the upper
triangles of its disjoint blocks row by row (two or three segment sums per row).

Accuracy. Each diagonal is centred on its middle element beta_d before any sum, and
the centring is added back exactly (a constant diagonal contributes
mult_d rho_d beta_d W): a Toeplitz (stationary) matrix gives the closed form up to
rounding of that last sum. Relative errors against exact arithmetic are ~1e-13 on a
random-walk covariance (T = 2000, octave scales; 1e-12 at the largest n; a 2-D
summed-area table gives 4e-8 there) and <= 3e-13 on random PSD matrices, the largest
near n = T/2 where one window remains.

Also here: the covariance matrices of the processes of Xu et al. (2017).

References
----------
H. Xu, S. Guerrier, R. Molinari, Y. Zhang, "A study of the Allan variance for
constant-mean non-stationary processes", IEEE Signal Processing Letters
24(8):1257-1260, 2017. doi:10.1109/LSP.2017.2722222
N. F. Zhang, "Allan variance of time series models for measurement data",
Metrologia 45(5):549-561, 2008.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from avar import _kernels
from avar.theory import _as_nonnegative, _as_phi, _as_whole

__all__ = ["moav", "noav", "covmat_ar1blocks", "covmat_bi", "covmat_nswn"]

# Relative tolerance of the symmetry check, scaled by max |covmat|.
_SYM_RTOL = 1e-10

_NO_SCALES = np.zeros(0, dtype=np.int64)


# --------------------------------------------------------------------------- helpers
def _as_covmat(covmat: Any) -> np.ndarray:
    """A square real matrix (at least 2 x 2) as C-contiguous float64; values unchecked."""
    if covmat is None or isinstance(covmat, (str, bytes)):
        raise TypeError(f"covmat must be a square numeric matrix, got {type(covmat).__name__}")
    c = np.asarray(covmat)
    if c.dtype.kind not in "iuf":
        raise TypeError(f"covmat must be a square numeric matrix (int or float), "
                        f"got dtype {c.dtype}")
    if c.ndim != 2 or c.shape[0] != c.shape[1]:
        raise ValueError(f"covmat must be a square T x T matrix, got shape {c.shape}")
    if c.shape[0] < 2:
        raise ValueError(f"covmat must be at least 2 x 2 (T >= 2n with n >= 1), "
                         f"got shape {c.shape}")
    return np.ascontiguousarray(c, dtype=np.float64)


def _pass(c: np.ndarray, width: int = 0, noav_ns: np.ndarray = _NO_SCALES) -> tuple:
    """Run the one-pass kernel (check + MOAV sums up to ``width`` = 2 max(n) + NOAV
    block sums of ``noav_ns``); raise if covmat is not finite or not symmetric."""
    noav_width = 2 * int(noav_ns.max()) if noav_ns.size else 0
    # many NOAV scales: one prefix scan per row beats per-scale segment sums
    scan = bool(2 * int(noav_ns.sum()) > _kernels.NOAV_SCAN_RATIO * noav_width)
    asym, top, *sums = _kernels.covariance_pass(c, width, noav_ns, scan, noav_width)
    amax = float(np.int64(top).view(np.float64))  # max |covmat|, inf/NaN if not finite
    if not np.isfinite(amax):
        raise ValueError("covmat must be finite (no NaN or inf)")
    if asym > 0 and not asym <= _SYM_RTOL * amax:
        raise ValueError(f"covmat must be symmetric: max |covmat - covmat.T| = {asym:.3g} "
                         f"(tolerance {_SYM_RTOL:g} * max |covmat|)")
    return tuple(sums)


def _check_covmat(covmat: Any) -> np.ndarray:
    """Validate a finite, square, symmetric real matrix; return it as C-contiguous float64."""
    c = _as_covmat(covmat)
    _pass(c)
    return c


def _prepare(n: Any, covmat: Any, kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(c, m, ks)``: covmat (shape-checked), the scales as given, the distinct scales."""
    c = _as_covmat(covmat)
    try:
        m = _as_whole(n, "n")
        big = 2 * m > c.shape[0]
        if big.any():
            raise ValueError(f"n must satisfy 1 <= n <= T/2 = {c.shape[0] // 2} for {kind} "
                             f"(T = {c.shape[0]} is the size of covmat), "
                             f"got {int(m[big].flat[0])}")
    except (TypeError, ValueError):
        _pass(c)  # a bad covmat is reported first
        raise
    return c, m, np.unique(m).astype(np.int64)


def _result(ks: np.ndarray, values: np.ndarray, m: np.ndarray) -> float | np.ndarray:
    out = values[np.searchsorted(ks, m)]
    return float(out) if m.ndim == 0 else out.astype(np.float64)


# --------------------------------------------------------------------------- AV
def moav(n: Any, covmat: Any) -> float | np.ndarray:
    r"""Theoretical maximal-overlap Allan variance for a given covariance matrix.

    .. math::

        \mathrm{MOAV}(n) = \frac{1}{2 (T-2n+1)} \sum_{s=0}^{T-2n}
        \operatorname{Var}\!\left(\bar x_{s+n}(n) - \bar x_s(n)\right),\qquad
        \operatorname{Var}(\cdot) = \frac{1}{n^2}\left(\Sigma_{AA} + \Sigma_{BB}
        - 2\Sigma_{AB}\right)

    where :math:`\bar x_s(n)` is the mean of the n samples starting at s and
    :math:`\Sigma_{AB}` the sum of ``covmat`` over the rows of block A = [s, s+n) and
    the columns of block B = [s+n, s+2n) (Xu et al. 2017; R ``avar::MOAV``).

    Parameters
    ----------
    n : int or array_like of int
        Averaging factor(s) in samples, whole numbers with 1 <= n <= T/2. With an
        array, one AV is returned per value.
    covmat : array_like, shape (T, T)
        Covariance matrix of the zero-mean process (per-sample units). Must be square,
        finite and symmetric (to ``1e-10 * max|covmat|``).

    Returns
    -------
    float or numpy.ndarray
        The theoretical AV (a float for scalar ``n``, else an array shaped like ``n``).

    Notes
    -----
    One pass over ``covmat`` (numba, two threads) checks it and gathers, for all the
    scales at once, the sums of its first 2 max(n) diagonals and second-order prefix
    sums in its two 2 max(n) corners; each scale then costs O(n), against O(T n^2)
    per scale for R. See the module docstring for the algorithm and its accuracy.
    Only the upper triangle enters the result (the lower one is only compared to it).

    References
    ----------
    Xu et al. (2017), IEEE Signal Processing Letters 24(8):1257-1260.

    Examples
    --------
    >>> import numpy as np
    >>> moav(2, np.eye(8))          # white noise: sigma2 / n
    0.5
    >>> moav([1, 2, 4], 2.0 * np.eye(16))
    array([2. , 1. , 0.5])
    """
    c, m, ks = _prepare(n, covmat, "moav")
    beta, dp, q1, q2, rr, _ = _pass(c, width=2 * int(ks[-1]))
    return _result(ks, _kernels.moav_from_sums(ks, c.shape[0], beta, dp, q1, q2, rr), m)


def noav(n: Any, covmat: Any) -> float | np.ndarray:
    r"""Theoretical non-overlapping Allan variance for a given covariance matrix.

    As :func:`moav`, averaged over the :math:`M = \lfloor T/(2n) \rfloor` disjoint
    pairs of blocks (1-2, 3-4, ...; window starts 0, 2n, 4n, ...), as R ``avar::NOAV``:
    :math:`\mathrm{NOAV}(n) = \frac{1}{2M}\sum_{k<M}
    \operatorname{Var}(\bar x_{(2k+1)n}(n) - \bar x_{2kn}(n))`.

    Parameters
    ----------
    n : int or array_like of int
        Averaging factor(s) in samples, whole numbers with 1 <= n <= T/2.
    covmat : array_like, shape (T, T)
        Square, finite, symmetric covariance matrix of the zero-mean process.

    Returns
    -------
    float or numpy.ndarray
        The theoretical AV (a float for scalar ``n``, else an array shaped like ``n``).

    Notes
    -----
    Sums the upper triangles of the M disjoint diagonal blocks row by row, in the pass
    over ``covmat`` that checks it (numba, two threads): for each row and scale, two or
    three vectorized segment sums (with many scales, one prefix scan per row instead).
    That is O(n T) per scale, as for R, but without a Python loop over the blocks.

    References
    ----------
    Xu et al. (2017), IEEE Signal Processing Letters 24(8):1257-1260.

    Examples
    --------
    >>> import numpy as np
    >>> noav(2, np.eye(8))
    0.5
    >>> noav([1, 2], np.diag(np.arange(1.0, 9.0)))   # variance t at time t
    array([4.5 , 2.25])
    """
    c, m, ks = _prepare(n, covmat, "noav")
    *_, block_sums = _pass(c, noav_ns=ks)
    return _result(ks, block_sums / (2.0 * ks * ks * (c.shape[0] // (2 * ks))), m)


# --------------------------------------------------------------------------- covmats
def _check_sizes(**sizes: Any) -> list[int]:
    out = []
    for name, val in sizes.items():
        if np.ndim(val) != 0:
            raise ValueError(f"{name} must be a single whole number, got shape {np.shape(val)}")
        out.append(int(_as_whole(val, name)))
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
    p = _scalar(_as_phi(phi), "phi")
    s2 = _scalar(_as_nonnegative(sigma2, "sigma2"), "sigma2")
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
    s2 = _scalar(_as_nonnegative(sigma2, "sigma2"), "sigma2")
    nt, nb = _check_sizes(n_total=n_total, n_block=n_block)
    return np.kron(np.eye(nt // nb), np.full((nb, nb), s2))


def covmat_nswn(sigma2: Any, n_total: Any) -> np.ndarray:
    r"""Covariance matrix of a non-stationary white noise (diagonal).

    For a scalar ``sigma2`` the variance grows linearly with time,
    :math:`C = \operatorname{diag}(\sigma^2 t)` for t = 1..n_total, the non-stationary
    white noise of Xu et al. (2017) (whose supplement compares it with a stationary
    white noise of the average variance (1 + T) / 2). For an array ``sigma2`` of
    length ``n_total``, ``C = diag(sigma2)`` (per-sample variances).

    The R manual does not define the matrix. R ``avar`` 0.1.3's code is
    ``diag(sigma2, n_total, n_total)``: identical for a vector ``sigma2``, but for a
    scalar it gives the *stationary* ``sigma2 * I``, which is not reproduced.

    Parameters
    ----------
    sigma2 : float or array_like
        Variance scale per sample (>= 0), or the ``n_total`` per-sample variances.
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
           [0. , 1. , 0. ],
           [0. , 0. , 1.5]])
    """
    s2 = _as_nonnegative(sigma2, "sigma2")
    (nt,) = _check_sizes(n_total=n_total)
    if s2.ndim == 0:
        return np.diag(float(s2) * np.arange(1.0, nt + 1.0))
    if s2.shape != (nt,):
        raise ValueError(f"sigma2 must be a scalar or have length n_total = {nt}, "
                         f"got shape {s2.shape}")
    return np.diag(s2)
