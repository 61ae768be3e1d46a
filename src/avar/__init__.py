"""avar: the Allan variance of time series and latent noise model estimation.

The public API is re-exported here; see each module for the details.
"""

from avar import datasets
from avar.avlr import AvlrResult, avlr
from avar.estimate import avar
from avar.imu import IMU
from avar.imu_avlr import ImuAvlrResult
from avar.models import AR1, DR, QN, RW, WN, CompositeModel, NoiseModel
from avar.nonstationary import covmat_ar1blocks, covmat_bi, covmat_nswn, moav, noav
from avar.results import AllanVariance, ImuAllanVariance
from avar.theory import av_ar1, av_dr, av_qn, av_rw, av_wn

__version__ = "0.1.0"


def __getattr__(name: str):
    # Plotting pulls in matplotlib: imported on first use, not with avar.
    if name == "plot_compare":
        from avar.plotting import plot_compare

        return plot_compare
    raise AttributeError(f"module 'avar' has no attribute {name!r}")


__all__ = [
    "AR1",
    "DR",
    "IMU",
    "QN",
    "RW",
    "WN",
    "AllanVariance",
    "AvlrResult",
    "CompositeModel",
    "ImuAllanVariance",
    "ImuAvlrResult",
    "NoiseModel",
    "av_ar1",
    "av_dr",
    "av_qn",
    "av_rw",
    "av_wn",
    "avar",
    "avlr",
    "covmat_ar1blocks",
    "covmat_bi",
    "covmat_nswn",
    "datasets",
    "moav",
    "noav",
    "plot_compare",
]
