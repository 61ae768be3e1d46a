"""avar: the Allan variance of time series and latent noise model estimation.

The public API is re-exported here; see each module for the details.
"""

from avar.estimate import avar
from avar.results import AllanVariance

__version__ = "0.1.0"

__all__ = [
    "AllanVariance",
    "avar",
]
