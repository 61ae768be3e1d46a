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

The covariance matrices of the processes of Xu et al. (2017) are built by
:mod:`avar.models.covariance`.

References
----------
H. Xu, S. Guerrier, R. Molinari, Y. Zhang, "A study of the Allan variance for
constant-mean non-stationary processes", IEEE Signal Processing Letters
24(8):1257-1260, 2017. doi:10.1109/LSP.2017.2722222
N. F. Zhang, "Allan variance of time series models for measurement data",
Metrologia 45(5):549-561, 2008.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from avar import _kernels
from avar.models.arguments import as_whole

if TYPE_CHECKING:
    from avar._kernels.models.covariance import CovariancePass

__all__ = ["moav", "noav"]

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


def _pass(c: np.ndarray, width: int = 0, noav_ns: np.ndarray = _NO_SCALES) -> CovariancePass:
    """Run the one-pass kernel (check + MOAV sums up to ``width`` = 2 max(n) + NOAV
    block sums of ``noav_ns``); raise if covmat is not finite or not symmetric."""
    noav_width = 2 * int(noav_ns.max()) if noav_ns.size else 0
    # many NOAV scales: one prefix scan per row beats per-scale segment sums
    scan = bool(2 * int(noav_ns.sum()) > _kernels.NOAV_SCAN_RATIO * noav_width)
    sums = _kernels.covariance_pass(c, width, noav_ns, scan, noav_width)
    asym = sums.asym
    amax = float(np.int64(sums.top).view(np.float64))  # max |covmat|, inf/NaN if not finite
    if not np.isfinite(amax):
        raise ValueError("covmat must be finite (no NaN or inf)")
    if asym > 0 and not asym <= _SYM_RTOL * amax:
        raise ValueError(f"covmat must be symmetric: max |covmat - covmat.T| = {asym:.3g} "
                         f"(tolerance {_SYM_RTOL:g} * max |covmat|)")
    return sums


def _check_covmat(covmat: Any) -> np.ndarray:
    """Validate a finite, square, symmetric real matrix; return it as C-contiguous float64."""
    c = _as_covmat(covmat)
    _pass(c)
    return c


def _prepare(n: Any, covmat: Any, kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(c, m, ks)``: covmat (shape-checked), the scales as given, the distinct scales."""
    c = _as_covmat(covmat)
    try:
        m = as_whole(n, "n")
        big = 2 * m > c.shape[0]
        if big.any():
            raise ValueError(f"n must satisfy 1 <= n <= T/2 = {c.shape[0] // 2} for {kind} "
                             f"(T = {c.shape[0]} is the size of covmat), "
                             f"got {int(m[big].flat[0])}")
    except (TypeError, ValueError):
        _pass(c)  # a bad covmat is reported first
        raise
    return c, m, np.unique(m).astype(np.int64)


def _check_diagonal(c: np.ndarray) -> None:
    """A covariance matrix has variances >= 0 on its diagonal (positive semi-definite)."""
    diagonal = np.diagonal(c)
    negative = np.flatnonzero((diagonal < 0) & np.isfinite(diagonal))  # NaN/inf: reported by the pass
    if negative.size:
        i = int(negative[0])
        raise ValueError(f"covmat is not a covariance matrix: {negative.size} negative variance(s) on its "
                         f"diagonal, the first covmat[{i}, {i}] = {c[i, i]:g}; a covariance matrix is "
                         "positive semi-definite (diagonal >= 0)")


def _without_overflow(compute, c: np.ndarray) -> np.ndarray:
    """``compute(c)``, or ``2**e compute(c / 2**e)`` when entries near the float64 limit overflow.

    Scaling by a power of two is exact, and the AV is linear in covmat.
    """
    values = compute(c)
    if np.all(np.isfinite(values)):
        return values
    _, exponent = np.frexp(max(abs(float(c.max())), abs(float(c.min()))))
    values = compute(np.ldexp(c, -int(exponent)))
    with np.errstate(over="ignore"):
        values = np.ldexp(values, int(exponent))
    if not np.all(np.isfinite(values)):
        raise ValueError("the theoretical AV of covmat exceeds the float64 range (about 1.8e308); "
                         "rescale covmat (e.g. other units)")
    return values


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
        finite and symmetric (to ``1e-10 * max|covmat|``), with a diagonal >= 0.
        Entries up to the float64 limit are accepted (the sums are rescaled by a
        power of two when they would overflow).

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

    def compute(matrix: np.ndarray) -> np.ndarray:
        sums = _pass(matrix, width=2 * int(ks[-1]))
        return _kernels.moav_from_sums(ks, matrix.shape[0], sums.beta, sums.dp, sums.q1, sums.q2, sums.rr)

    _check_diagonal(c)
    values = _without_overflow(compute, c)
    return _result(ks, values, m)


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
        Square, finite, symmetric covariance matrix of the zero-mean process, with a
        diagonal >= 0 (entries up to the float64 limit are accepted).

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

    def compute(matrix: np.ndarray) -> np.ndarray:
        block_sums = _pass(matrix, noav_ns=ks).noav
        return block_sums / (2.0 * ks * ks * (matrix.shape[0] // (2 * ks)))

    _check_diagonal(c)
    values = _without_overflow(compute, c)
    return _result(ks, values, m)
