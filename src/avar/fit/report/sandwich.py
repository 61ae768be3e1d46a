"""The covariance of a sensor model's parameters: a sandwich of the fit's weights around the levels' covariance.

Whatever weights W a fit gives the Allan variance estimates nu_hat (the
diagonal of the maximum-likelihood fit, or a full matrix), the parameters
theta vary with the estimates' covariance S as::

    Cov(theta) = A^-1 J' W S W J A^-1,   A = J' W J,

J the Jacobian of the model's Allan variance (per-sample scales, then the
shapes of AR1 and SIN terms). With W = S^-1 this is the inverse Fisher
information of the Gaussian approximation, (J' S^-1 J)^-1.
"""

from __future__ import annotations

import numpy as np

from avar.fit.terms import Component, basis

__all__ = ["jacobian", "parameter_covariance", "independent_levels"]


def jacobian(components: tuple[Component, ...], factors: np.ndarray) -> np.ndarray:
    """d nu / d (scales, then shapes) at ``factors``: the unit AV of each term, then forward differences."""
    columns = [basis(c.kind, c.shape, factors) for c in components]
    for c in components:
        if c.shape is None:
            continue
        step = 1e-6 * max(abs(c.shape), 1e-3) if c.kind == "SIN" else 1e-6 * (1.0 - c.shape)
        moved = min(c.shape + step, 0.5 - 1e-12) if c.kind == "SIN" else min(c.shape + step, 1.0 - 1e-15)
        columns.append(c.scale * (basis(c.kind, moved, factors) - basis(c.kind, c.shape, factors)) / (moved - c.shape))
    return np.column_stack(columns) if columns else np.zeros((np.size(factors), 0))


def parameter_covariance(components: tuple[Component, ...], factors: np.ndarray, weights: np.ndarray,
                         levels: np.ndarray) -> np.ndarray:
    """Covariance of (scales, shapes) for a fit with ``weights`` and levels of covariance ``levels``.

    ``weights``: a vector of degrees of freedom (W = diag(edf / (2 nu^2)), the
    maximum-likelihood fit's), or the weight matrix W itself.
    """
    design = jacobian(components, factors)
    if design.shape[1] == 0:
        return np.zeros((0, 0))
    nu = np.sum([c.av(factors) for c in components], axis=0)
    matrix = np.diag(weights / (2.0 * nu**2)) if np.ndim(weights) == 1 else np.asarray(weights)
    # relative residuals and unit-norm columns: the scales span many decades (DR's m^2 / 2 against QN's 3 / m^2)
    norms = np.linalg.norm(design / nu[:, None], axis=0)
    norms[norms == 0] = 1.0
    design = design / norms
    weighted = matrix @ design
    bread = np.linalg.pinv(design.T @ weighted)
    return (bread @ (weighted.T @ levels @ weighted) @ bread) / np.outer(norms, norms)


def independent_levels(components: tuple[Component, ...], factors: np.ndarray, edf: np.ndarray) -> np.ndarray:
    """Covariance of independent Allan variance estimates of ``edf`` degrees of freedom: diag(2 nu^2 / edf)."""
    nu = np.sum([c.av(factors) for c in components], axis=0) if components else np.ones(np.size(factors))
    return np.diag(2.0 * nu**2 / edf)
