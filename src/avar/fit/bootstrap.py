"""Parametric bootstrap of the AVLR estimator.

The fitted per-sample model is simulated ``B`` times at the length and rate
of the data; each replicate's Allan variance (same estimator, same averaging
factors) is refitted on the same scales. Replicates are simulated in chunks
whose Allan variances are computed in one parallel kernel call.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator, Mapping
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar.fit.slopes import log_mean_estimate
from avar.models import NoiseModel
from avar.stability.allan.columns import allan_variance_columns
from avar.stability.allan.results import AllanVariance

#: Bootstrap samples per chunk of replicates: ~28 bytes each (series, scratch and the
#: compensated cumulative sums) bound the memory to about 1 GB whatever B and N.
CHUNK_SAMPLES = 1 << 25
#: A progress bar is drawn (on a terminal) when B * N reaches this.
PROGRESS_MIN_SAMPLES = 50_000_000


def show_progress(done: int, total: int) -> None:
    """Draw the bootstrap progress bar on stderr (a newline when done)."""
    filled = 30 * done // total
    end = "\n" if done == total else ""
    sys.stderr.write(f"\ravlr bootstrap [{'#' * filled}{'.' * (30 - filled)}] {done}/{total}{end}")
    sys.stderr.flush()


class ReplicateChunk(NamedTuple):
    """The Allan variances of a chunk of bootstrap replicates (:func:`replicate_allan_variances`)."""

    #: Index of the chunk's first replicate.
    first: int
    #: One row per replicate, one column per averaging factor.
    allan: np.ndarray


def replicate_allan_variances(
    model: NoiseModel, n: int, factors: np.ndarray, type: str, replicates: int, rng: np.random.Generator,
    progress: Callable[[int, int], None] | None = None,
) -> Iterator[ReplicateChunk]:
    """Allan variances of ``replicates`` series of length ``n`` simulated from ``model``.

    The one simulation loop of every parametric bootstrap (AVLR and GMWM):
    replicates are generated in chunks of at most :data:`CHUNK_SAMPLES`
    samples into one reused buffer, and each chunk's Allan variances (type
    ``type`` at the averaging factors ``factors``) come from one parallel
    kernel call. Yields a :class:`ReplicateChunk` (first replicate index, array (rows,
    len(factors))) chunk by chunk; ``progress(done, replicates)`` is called after each.
    """
    chunk = max(1, min(replicates, CHUNK_SAMPLES // n))
    buffer = np.empty((chunk, n))
    for start in range(0, replicates, chunk):
        rows = buffer[: min(chunk, replicates - start)]
        model.simulate_into(rows, rng)
        yield ReplicateChunk(start, allan_variance_columns(rows.T, factors, type))
        if progress is not None:
            progress(start + rows.shape[0], replicates)


def bootstrap_estimates(
    model: NoiseModel, av: AllanVariance, selections: Mapping[str, np.ndarray], replicates: int,
    seed: Any = None, progress: Callable[[int, int], None] | None = None,
) -> dict[str, np.ndarray]:
    """AVLR estimates of ``replicates`` series simulated from ``model``.

    Each replicate has the length ``av.n``; its Allan variance of type
    ``av.type`` is computed only at the selected averaging factors of ``av``
    and refitted with tau = ``av.levels`` (so at ``av.freq``). Replicates are
    generated in chunks of at most :data:`CHUNK_SAMPLES` samples, a chunk at
    a time, and their Allan variances computed in one parallel call;
    ``progress(done, replicates)`` is called after every chunk.

    Returns process -> float64 array of the ``replicates`` estimates.
    """
    used = np.unique(np.concatenate(list(selections.values()))) - 1
    factors = av.averaging_factors[used]
    log_tau = np.log(av.levels[used])
    positions = {p: np.searchsorted(used, s - 1) for p, s in selections.items()}
    estimates = {p: np.empty(replicates) for p in selections}
    chunks = replicate_allan_variances(model, av.n, factors, av.type, replicates, np.random.default_rng(seed), progress)
    for start, allan in chunks:
        with np.errstate(divide="ignore"):
            log_adev = 0.5 * np.log(allan)
        for process, where in positions.items():
            estimates[process][start : start + allan.shape[0]] = log_mean_estimate(
                process, log_adev[:, where], log_tau[where]
            )
    return estimates


def bootstrap_table(estimates: pd.Series, replicates: Mapping[str, np.ndarray], significance: float) -> pd.DataFrame:
    """Bias-corrected estimates, bootstrap SDs and normal intervals.

    Estimate = 2 theta - mean(theta*), SD = sd(theta*) (ddof 1),
    Lower/Upper = Estimate -/+ z SD with z the normal *quantile*
    ``norm.isf(significance / 2)``, significance = 1 - confidence (R ``avar`` 0.1.3
    used the density ``dnorm(1 - alpha/2)`` = 0.248 for its alpha = 0.05, 8 times too narrow).
    """
    from scipy.stats import norm  # scipy.stats is heavy: loaded on first use

    z = norm.isf(significance / 2.0)  # not ppf(1 - s/2), which rounds to inf for s < 1e-16
    means = np.array([replicates[p].mean() for p in estimates.index])
    sds = np.array([replicates[p].std(ddof=1) for p in estimates.index])
    corrected = 2.0 * estimates.to_numpy() - means
    return pd.DataFrame(
        {"Estimate": corrected, "SD": sds, "Lower": corrected - z * sds, "Upper": corrected + z * sds},
        index=estimates.index,
    )


def parametric_bootstrap(
    estimates: pd.Series, model: NoiseModel, av: AllanVariance, selections: Mapping[str, np.ndarray],
    replicates: int, significance: float, seed: Any = None,
) -> pd.DataFrame:
    """The interval table of :func:`avar.avlr` with ``ci=True``.

    Draws a progress bar on stderr when it is a terminal and ``B * N`` is at
    least :data:`PROGRESS_MIN_SAMPLES`.
    """
    long_run = replicates * av.n >= PROGRESS_MIN_SAMPLES and getattr(sys.stderr, "isatty", bool)()
    draws = bootstrap_estimates(model, av, selections, replicates, seed, show_progress if long_run else None)
    return bootstrap_table(estimates, draws, significance)


def imu_bootstrap(
    estimates: pd.Series | pd.DataFrame, models: Mapping[str, NoiseModel], channels: Mapping[str, AllanVariance],
    selections: Mapping[str, np.ndarray], per_axis: bool, replicates: int, significance: float,
    rng: np.random.Generator,
) -> pd.DataFrame:
    """Bootstrap table of the AVLR of one IMU sensor type.

    Per axis: every channel is bootstrapped on its own model (index
    (axis, process)). Jointly: every replicate simulates all the axes from
    the shared model and refits the pooled estimator, whose value is the
    geometric mean over the axes of the per-axis estimates (every axis has
    the same scales, so the mean of log AD - b log tau over (axis, scale)
    pairs is the mean over axes of the per-axis means).
    """
    if per_axis:  # estimates: one row per channel, in channel order (index: axis labels)
        frames = {label: bootstrap_table(estimates.iloc[k], bootstrap_estimates(
                  models[name], channels[name], selections, replicates, rng), significance)
                  for k, (label, name) in enumerate(zip(estimates.index, channels))}
        return pd.concat(frames, names=["Axis", "Process"])
    draws = [bootstrap_estimates(models[name], av, selections, replicates, rng) for name, av in channels.items()]
    pooled = {p: np.exp(np.mean([np.log(d[p]) for d in draws], axis=0)) for p in selections}
    return bootstrap_table(estimates, pooled, significance)
