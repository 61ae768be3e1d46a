"""The two algorithms of avar.fit.covariance agree on the same model.

:func:`~avar.fit.covariance.exact.exact_covariance` sums every lag of the
increments' autocovariance convolved by FFT; :func:`~avar.fit.covariance.structure.structure_covariance`
reads the cross-covariances off the structure function's second sums and sums
the lags sparsely. Given the same sum of processes they must agree to the
structure path's stated accuracy, relative to the levels' spread.
"""

from __future__ import annotations

import numpy as np
import pytest

from avar.fit.covariance.exact import exact_covariance
from avar.fit.covariance.structure import ACCURACY, MAX_EXACT_LEVELS, structure_covariance
from avar.fit.terms import components_of
from avar.models import AR1, DR, QN, RW, WN
from avar.stability.shared.grids import octave_factors

MODELS = {
    "WN+RW": WN(sigma2=1.0) + RW(gamma2=1e-3),
    "QN+WN+AR1": QN(q2=0.5) + WN(sigma2=1.0) + AR1(phi=0.9, sigma2=0.2),
    "WN+RW+DR": WN(sigma2=1.0) + RW(gamma2=1e-3) + DR(omega=0.05),
}


def grids(n: int) -> dict[str, np.ndarray]:
    top = (n - 1) // 2
    return {
        "octaves": octave_factors(n)[octave_factors(n) <= top],
        "every factor": np.arange(1, min(24, top) + 1),
        "irregular": np.unique(np.geomspace(1, top, 17).round().astype(np.int64)),
    }


def relative_gap(fast: np.ndarray, exact: np.ndarray) -> float:
    spread = np.sqrt(np.diag(exact))
    return float(np.max(np.abs(fast - exact) / np.outer(spread, spread)))


@pytest.mark.parametrize("n", [300, 2000, 2**14])
@pytest.mark.parametrize("name", list(MODELS))
def test_structure_and_exact_covariances_agree(name, n):
    model = MODELS[name]
    for grid, factors in grids(n).items():
        assert factors.size <= MAX_EXACT_LEVELS
        exact = exact_covariance(model, n, factors)
        fast = structure_covariance(model, n, factors)
        assert relative_gap(fast, exact) < ACCURACY, (grid, relative_gap(fast, exact))
        np.testing.assert_allclose(np.diag(fast), np.diag(exact), rtol=ACCURACY, err_msg=grid)


def test_the_twins_take_processes_and_components_alike():
    model = MODELS["QN+WN+AR1"]
    factors = np.array([1, 2, 4, 8, 16])
    components = components_of(model)
    np.testing.assert_array_equal(exact_covariance(components, 500, factors), exact_covariance(model, 500, factors))
    np.testing.assert_array_equal(structure_covariance(components, 500, factors),
                                  structure_covariance(model, 500, factors))


def test_the_comparison_sees_a_wrong_model():
    """A term left out by one side is far beyond the stated accuracy: the agreement above is not vacuous."""
    n, factors = 2000, octave_factors(2000)[:9]
    exact = exact_covariance(MODELS["WN+RW+DR"], n, factors)
    assert relative_gap(structure_covariance(MODELS["WN+RW"], n, factors), exact) > 100 * ACCURACY
    ar1 = MODELS["QN+WN+AR1"]
    tweaked = QN(q2=0.5) + WN(sigma2=1.0) + AR1(phi=0.91, sigma2=0.2)
    assert relative_gap(structure_covariance(tweaked, n, factors), exact_covariance(ar1, n, factors)) > 10 * ACCURACY
