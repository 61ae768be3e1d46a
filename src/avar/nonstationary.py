"""Theoretical Allan variance of constant-mean (possibly non-stationary) processes.

For a zero-mean process x_1..x_T with covariance matrix C, the theoretical AV at
averaging factor n is half the variance of the difference of two adjacent n-means,
averaged over the windows of the estimator (Xu et al. 2017): ``moav`` uses the
T - 2n + 1 windows starting at 0, 1, ..., T - 2n; ``noav`` the floor(T / (2n))
disjoint pairs of blocks (window starts 0, 2n, 4n, ...). With w = (-1 x n, +1 x n)
and C_s the 2n x 2n diagonal block at s, the window variance is w' C_s w / n^2.

Algorithm. R ``avar`` 0.1.3 sums n x n sub-blocks per window: O(T n^2) per scale.
Here, grouping the entries of C by diagonal d,

    sum_s w' C_s w = sum_{d<2n} mult_d sum_{m<2n-d} w_m w_{m+d} sum_s C[s+m, s+m+d]

(mult_0 = 1, else 2): the inner sum is a difference of prefix sums along diagonal d,
and u_d(m) = w_m w_{m+d} has at most three constant pieces, so the sum over m is a few
differences of second-order prefix sums. Prefix tables along the first 2 max(n)
diagonals cost O(T max(n)) once (O(T^2) for an octave grid); then a scale costs O(n)
(moav) or O(T) (noav), with no loop over windows.

Accuracy. Each diagonal is centered on its middle element before the prefix sums
(then exactly zero for a Toeplitz matrix). A 2-D summed-area table, the textbook O(1)
block sum, cancels badly on growing covariances (4e-8 relative error for a random walk
with T = 2000); this float64 scheme gives ~1e-10 there, ~1e-14 on random PSD matrices.

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

from avar.theory import _as_nonnegative, _as_phi, _as_whole

__all__ = ["moav", "noav", "covmat_ar1blocks", "covmat_bi", "covmat_nswn"]

# Relative tolerance of the symmetry check, scaled by max |covmat|.
_SYM_RTOL = 1e-10


# --------------------------------------------------------------------------- helpers
def _check_covmat(covmat: Any) -> np.ndarray:
    """Validate a finite, square, symmetric real matrix; return it as C-contiguous float64."""
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
    c = np.ascontiguousarray(c, dtype=np.float64)
    asym = _asymmetry(c)
    if not np.isfinite(asym) and not np.isfinite(c).all():
        raise ValueError("covmat must be finite (no NaN or inf)")
    if asym > 0 and not asym <= _SYM_RTOL * float(np.abs(c).max()):
        raise ValueError(f"covmat must be symmetric: max |covmat - covmat.T| = {asym:.3g} "
                         f"(tolerance {_SYM_RTOL:g} * max |covmat|)")
    return c


def _asymmetry(c: np.ndarray, rows: int = 128, cols: int = 512) -> float:
    """max |c - c.T| over cache-sized tiles of the upper triangle; NaN/inf if not finite."""
    t, worst = c.shape[0], 0.0
    with np.errstate(invalid="ignore", over="ignore"):
        for i in range(0, t, rows):
            for j in range(i, t, cols):
                diff = float(np.abs(c[i:i + rows, j:j + cols] - c[j:j + cols, i:i + rows].T).max())
                if not diff <= worst:
                    worst = diff
                    if not np.isfinite(diff):
                        return worst
    return worst


def _cumsum_rows(src: np.ndarray, dst: np.ndarray) -> None:
    """``dst[r] = src[0] + ... + src[r]`` (dst C-contiguous, may be src), in sequential
    order but blocked so that each NumPy call adds slabs of rows (np.cumsum is slower)."""
    r, width = dst.shape
    b = max(1, int(np.sqrt(r)))
    nb = r // b
    sh = src[: nb * b].reshape(nb, b, width)
    dh = dst[: nb * b].reshape(nb, b, width)  # a view: dst is C-contiguous
    if dst is not src:
        dh[:, 0] = sh[:, 0]
    for k in range(1, b):
        np.add(dh[:, k - 1], sh[:, k], out=dh[:, k])
    for k in range(1, nb):
        np.add(dh[k], dh[k - 1, -1], out=dh[k])
    for k in range(nb * b, r):
        np.add(dst[k - 1], src[k], out=dst[k])


def _diagonal_prefix(c: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """``(p, beta)``: ``p[r, d] = sum_{i < r} (c[i, i+d] - beta[d])`` for r <= T - d
    (later rows hold unused finite values), ``beta[d]`` the middle of diagonal d."""
    t = c.shape[0]
    # Row i of this view holds c[i, i:i+width] (diagonals side by side); the entries
    # with i + d >= T wrap into the next row and are never used.
    view = np.lib.stride_tricks.as_strided(
        c.ravel(), shape=(t - 1, width), strides=((t + 1) * c.itemsize, c.itemsize),
        writeable=False)
    d = np.arange(width)
    beta = view[(t - 1 - d) // 2, d]  # middle of the valid part of each diagonal
    p = np.empty((t + 1, width))
    p[0] = 0.0
    np.subtract(view, beta, out=p[1:t])
    p[t] = 0.0
    p[t, 0] = c[t - 1, t - 1] - beta[0]
    body = p[1:]
    _cumsum_rows(body, body)
    return p, beta


def _pieces(n: int) -> tuple[np.ndarray, ...]:
    """Split points of u_d(m) = w_m w_(m+d) for d = 0..2n-1 (w = -1 on A, +1 on B).

    u_d = +1 on [0, n1), -1 on [n1, n2), +1 on [n, n3); rho(d) = sum_m u_d(m).
    """
    d = np.arange(2 * n)
    n1 = np.maximum(n - d, 0)
    n2 = np.minimum(n, 2 * n - d)
    n3 = np.maximum(n, 2 * n - d)
    rho = (2 * n1 - n2 + n3 - n).astype(np.float64)
    mult = np.where(d == 0, 1.0, 2.0)  # (k, l) and (l, k) for d > 0
    return d, n1, n2, n3, rho, mult


def _moav_one(q: np.ndarray, beta: np.ndarray, t: int, n: int) -> float:
    """``q[r] = PP[r + 1]``, PP[x] = sum_{r < x} P[r] (second-order prefix sums)."""
    w = t - 2 * n + 1
    d, n1, n2, n3, rho, mult = _pieces(n)

    def f(x: np.ndarray) -> np.ndarray:  # sum_{m < x} (P[m + W] - P[m])
        return q[x + w - 1, d] - q[np.maximum(x - 1, 0), d]  # PP[0] = PP[1] = 0

    pieces = 2.0 * f(n1) - f(np.zeros_like(d)) - f(n2) + (f(n3) - f(np.full_like(d, n)))
    total = np.sum(mult * (pieces + beta[: 2 * n] * (w * rho)))
    return float(total) / (2.0 * n * n * w)


def _noav_one(p: np.ndarray, beta: np.ndarray, t: int, n: int) -> float:
    m = t // (2 * n)
    d, n1, n2, n3, rho, mult = _pieces(n)
    base = (2 * n * np.arange(m))[:, None]

    def g(x: np.ndarray) -> np.ndarray:  # sum_j P[2 n j + x]
        return p[base + x[None, :], d[None, :]].sum(axis=0)

    pieces = 2.0 * g(n1) - g(np.zeros_like(d)) - g(n2) + (g(n3) - g(np.full_like(d, n)))
    total = np.sum(mult * (pieces + beta[: 2 * n] * (m * rho)))
    return float(total) / (2.0 * n * n * m)


def _result(values: list[float], m: np.ndarray) -> float | np.ndarray:
    if m.ndim == 0:
        return values[0]
    return np.asarray(values, dtype=np.float64).reshape(m.shape)


def _check_n(n: Any, t: int, kind: str) -> np.ndarray:
    m = _as_whole(n, "n")
    big = 2 * m > t
    if big.any():
        raise ValueError(f"n must satisfy 1 <= n <= T/2 = {t // 2} for {kind} "
                         f"(T = {t} is the size of covmat), got {int(m[big].flat[0])}")
    return m


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
    O(T max(n)) for centered prefix sums along the first 2 max(n) diagonals, then O(n)
    per scale, against O(T n^2) per scale for R; see the module docstring for the
    algorithm and its accuracy. Only the upper triangle is read (after the check).

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
    c = _check_covmat(covmat)
    t = c.shape[0]
    m = _check_n(n, t, "moav")
    p, beta = _diagonal_prefix(c, 2 * int(m.max()))
    _cumsum_rows(p, p)  # in place: now p[r] = sum_{x <= r} P[x] = PP[r + 1]
    vals = [_moav_one(p, beta, t, int(k)) for k in m.ravel()]
    return _result(vals, m)


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
    Sums the M disjoint diagonal blocks directly (strided view, 3 n^2 M reads) or uses
    the prefix sums of :func:`moav` (O(T max(n)) once, O(T) per scale), whichever is
    cheaper for the requested scales.

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
    c = _check_covmat(covmat)
    t = c.shape[0]
    m = _check_n(n, t, "noav")
    ks = [int(k) for k in m.ravel()]
    # direct block sums read <= 2 n T entries: cheaper unless many scales at once
    direct_cost = sum(4 * k * k * (t // (2 * k)) for k in ks)
    if direct_cost <= 4 * t * 2 * max(ks) + 10 * t * len(ks):
        return _result([_noav_direct(c, k) for k in ks], m)
    p, beta = _diagonal_prefix(c, 2 * max(ks))
    return _result([_noav_one(p, beta, t, k) for k in ks], m)


def _noav_direct(c: np.ndarray, n: int) -> float:
    """NOAV by summing the disjoint 2n x 2n diagonal blocks (strided view, no copy)."""
    t, k = c.shape[0], 2 * n
    m = t // k
    blocks = np.lib.stride_tricks.as_strided(
        c, shape=(m, k, k), strides=(k * (t + 1) * c.itemsize, t * c.itemsize, c.itemsize),
        writeable=False)
    a, b = blocks[:, :n, :n], blocks[:, n:, n:]
    total = a.sum() + b.sum() - 2.0 * blocks[:, :n, n:].sum()
    return float(total) / (2.0 * n * n * m)


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
