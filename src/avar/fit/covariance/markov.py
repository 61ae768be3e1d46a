"""The second cumulative sums S2 of a Gauss-Markov term's structure function: a short table, then closed form.

The structure function of a first-order Gauss-Markov term of per-sample variance c
and shape phi is D(u) = A (1 - phi^u), A = 2 c / (1 - phi^2), and
:mod:`avar.fit.covariance.structure` reads its second cumulative sums
S2(x) = sum_{u<x-1} (x - 1 - u) D(u) at up to twice the record's length. Summed, the table
costs a pass over millions of lags per term; in closed form, with K = x - 1,

    S2(x) = A [K (K + 1) / 2 - (K (1 - phi) - phi (1 - phi^K)) / (1 - phi)^2],

it cancels badly at small x when phi is near 1 (both parts grow as K^2 / 2 while S2
grows as A (1 - phi) K^3 / 6). So S2 is summed outward from 0 over the first
:data:`MARKOV_TABLE` correlation times, where the cancellation lives, and taken in
closed form beyond (phi^K < 1e-17 there; the two agree to about 1e-10 relative).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from avar.fit.terms import Component

__all__ = ["MARKOV_TABLE", "MarkovSums", "markov_sums"]

#: Correlation times of a Gauss-Markov term its S2 table covers (phi^x < 1e-17 beyond).
MARKOV_TABLE = 40


class MarkovSums(NamedTuple):
    """S2 of one Gauss-Markov term: its ``table`` (S2(0..len - 1)), ``scale`` c and ``phi``; call it at integers."""

    table: np.ndarray
    scale: float
    phi: float

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """S2 at integers x >= 0: the table within it, the closed form (module docstring) beyond."""
        size = self.table.size
        if int(x.max()) < size:
            return self.table[x]
        k = x - 1.0
        q = 1.0 - self.phi
        geometric = (k * q + self.phi * np.expm1(k * math.log(self.phi))) / (q * q)
        closed = (2.0 * self.scale / (q * (1.0 + self.phi))) * (k * (k + 1.0) / 2.0 - geometric)
        return np.where(x < size, self.table[np.minimum(x, size - 1)], closed)


def markov_sums(term: Component, size: int) -> MarkovSums:
    """S2 of the Gauss-Markov ``term`` (per-sample scale c, shape phi) for arguments up to ``size``.

    >>> term = Component("AR1", 1.0, math.exp(-1.0 / 2.0))
    >>> x = np.arange(2000)
    >>> d = 2.0 * (1.0 - term.shape ** x) / (1.0 - term.shape ** 2)          # D(u), summed plainly
    >>> plain = np.concatenate([[0.0, 0.0], np.cumsum(np.cumsum(d))])[:2000]
    >>> sums = markov_sums(term, 2000)
    >>> sums.table.size < 200, bool(np.allclose(sums(x), plain, rtol=1e-10, atol=0.0))
    (True, True)
    """
    phi = float(term.shape)
    rows = min(size, max(64, math.ceil(MARKOV_TABLE / -math.log(phi))))
    u = np.arange(rows, dtype=np.float64)
    structure = 2.0 * float(term.scale) * (-np.expm1(u * math.log(phi))) / ((1.0 - phi) * (1.0 + phi))
    s1 = np.concatenate([[0.0], np.cumsum(structure)])
    return MarkovSums(np.concatenate([[0.0], np.cumsum(s1)]), float(term.scale), phi)
