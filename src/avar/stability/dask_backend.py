"""Out-of-core and distributed Allan variance with Dask (support code).

* :func:`allan_variance_dask`: one long series (or several columns) held as a
  ``dask.array`` chunked along time. Every (chunk, level) task computes the
  sum of squared differences whose *first* window starts in its chunk, from
  the chunk plus the halo of ``2 m - 1`` following samples that level needs
  (dask slicing reads only the chunks that overlap); the driver adds the sums
  in a fixed order, so the result does not depend on the scheduler or on
  which worker ran what.
* :func:`allan_variance_files`: many independent series (files) on a
  ``dask.distributed`` cluster, with a progress bar on a terminal.

Dask is imported inside the functions: this module imports without it.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from avar._kernels import streaming_allan_variance as allan_variance_columns


def _windows(n: int, bounds: list[tuple[int, int]], m: int, type: str):
    """(chunk, start, stop, n_differences) of the sub-series each chunk owns at level m."""
    for i, (lo, hi) in enumerate(bounds):
        if type == "mo":
            last = min(hi, n - 2 * m + 1)  # differences t in [lo, last)
            if last > lo:
                yield i, lo, last - 1 + 2 * m, last - lo
        else:
            first = -(-lo // m) * m
            stop_b = min(hi, (n // m - 1) * m)  # window starts b = k m in [first, stop_b)
            if stop_b > first:
                count = (stop_b - first + m - 1) // m
                yield i, first, first + (count + 1) * m, count


def _partial_sum(block: np.ndarray, m: int, type: str, count: int) -> np.ndarray:
    """Sum of D**2 / m**2 ... as the kernel's AV times its normalisation (per column)."""
    av = allan_variance_columns(block, np.array([m], dtype=np.int64), type)[:, 0]
    return av * (2.0 * count)


def allan_variance_dask(array: Any, factors: Any, type: str = "mo") -> np.ndarray:
    """Allan variance of a 1-D or 2-D ``dask.array`` (time along axis 0), shape (C, L).

    Computed on whatever dask scheduler is active (threads, processes or a
    ``distributed.Client``). The NumPy path and this one agree to ~1e-15
    relative: each partial sum is the streaming kernel's exact result on a
    sub-series, and the partial sums (all non-negative) are added in chunk
    order.
    """
    import dask
    import dask.array as da

    x = array if isinstance(array, da.Array) else da.from_array(np.asarray(array))
    if x.ndim == 1:
        x = x[:, None]
    factors = np.asarray(factors, dtype=np.int64).reshape(-1)
    n, channels = int(x.shape[0]), int(x.shape[1])
    edges = np.concatenate(([0], np.cumsum(x.chunks[0])))
    bounds = [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]
    tasks, owners = [], []
    for k, m in enumerate(map(int, factors)):
        if m < 1 or m > n // 2:
            continue
        for i, start, stop, count in _windows(n, bounds, m, type):
            part = dask.delayed(_partial_sum)(x[start:stop], m, type, count)
            tasks.append(part)
            owners.append((k, i, count))
    results = dask.compute(*tasks)
    sums = np.zeros((channels, factors.shape[0]))
    counts = np.zeros(factors.shape[0])
    for (k, _, count), value in sorted(zip(owners, results), key=lambda item: item[0][:2]):
        sums[:, k] += value
        counts[k] += count
    with np.errstate(invalid="ignore", divide="ignore"):
        out = sums / (2.0 * counts)
    out[:, counts == 0] = np.nan
    return out


def _one_file(path: Any, reader: Callable[[Any], Any], factors_fn: Callable[[int], Any], type: str):
    data = np.asarray(reader(path))
    factors = np.asarray(factors_fn(data.shape[0]), dtype=np.int64)
    return factors, allan_variance_columns(data, factors, type)


def allan_variance_files(
    paths: Iterable[Any],
    reader: Callable[[Any], Any],
    factors_fn: Callable[[int], Any],
    type: str = "mo",
    scheduler: Any = None,
    workers: int = 2,
    progress: bool | None = None,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Allan variance of many independent series on a ``dask.distributed`` cluster.

    ``reader(path)`` returns an (N,) or (N, C) array (read on the worker, e.g.
    ``np.load(p, mmap_mode="r")``); ``factors_fn(N)`` the cluster sizes.
    ``scheduler``: a ``distributed.Client``, a scheduler address, or None for
    a ``LocalCluster`` of ``workers`` single-threaded worker processes (closed
    afterwards). A tqdm progress bar goes to stderr when it is a terminal
    (``progress`` forces it on or off). Returns ``(factors, allan (C, L))`` per
    path, in the order of ``paths``.
    """
    from dask.distributed import Client, LocalCluster, as_completed

    paths = list(paths)
    own_cluster = None
    if scheduler is None:
        own_cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(own_cluster)
    elif isinstance(scheduler, str):
        client = Client(scheduler)
    else:
        client = scheduler
    show = sys.stderr.isatty() if progress is None else progress
    try:
        futures = [client.submit(_one_file, p, reader, factors_fn, type, pure=False) for p in paths]
        bar = None
        if show:
            from tqdm import tqdm

            bar = tqdm(total=len(futures), file=sys.stderr, unit="series")
        for _ in as_completed(futures):
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
        return client.gather(futures)
    finally:
        if own_cluster is not None:
            client.close()
            own_cluster.close()
        elif isinstance(scheduler, str):
            client.close()
