"""Which path a call takes: plain NumPy for small inputs (nothing to compile) or the compiled kernels.

A kernel's first call on a machine waits for numba to compile it (seconds; see
docs/numerics.md). A NumPy twin answers such a call at once, as exact where it certifies
its own error, but warm it is 2 to 10 times slower than the kernels (vectorized NumPy
makes several passes over the data where a kernel makes one, on the threads). So each
dispatch takes the twin only while it is cold: when its record is small (its work, in
samples or terms, within the twin's ``limit``) and the kernels it would run are not
compiled yet, neither in this process nor in numba's cache for this machine
(:func:`compiled`). Once they are (``avar warmup``, a long record, an earlier run), the
kernels run, as fast as before. A process that keeps calling turns hot: once a dispatch
has spent :data:`HOT_WORK` units in its twin (under a second lost), it compiles its kernels
after all, and is fast from then on (and so are later processes, from numba's cache).
The two paths agree to about 1e-15 (the tests ask 1e-12): the last bits of a result may
differ between a cold and a warm run, as they do between CPUs.

The dispatching points: the deviation family's phase and levels
(:func:`avar.stability.classic.core.numpy_levels`, twin :mod:`avar.stability.classic.small`),
its noise identification (:mod:`avar.stability.uncertainty.lag1`), the scan of the data
(:func:`avar._kernels.classic.phase.scan`), Greenhall's EDF sums
(:func:`avar._kernels.uncertainty.edf.greenhall_sums`), the Allan variance
(:func:`avar.stability.allan.columns.numpy_columns`) and the total family's phase, MTOTDEV,
TTOTDEV and HTOTDEV levels and Theo1 levels (:mod:`avar.stability.total.deviations`, twins
:mod:`avar.stability.total.small` and :mod:`avar._kernels.total.theo1_numpy`; ThêoH's kf,
:mod:`avar.stability.total.small_theobr`, and its displayed OADEV levels, twin
:func:`avar.stability.total.small.oavar_sums`; MHTOTDEV's levels, :mod:`avar.stability.total.mhtot`,
twin :mod:`avar.stability.total.small_mhtot`) and the dynamic deviations' phase and window sums
(:mod:`avar.stability.dynamic.estimator`, twin :mod:`avar.stability.dynamic.small`), the time-error
levels of MTIE, TIE rms, PDEV and GCODEV (:mod:`avar.stability.time_error.deviations`, twin
:mod:`avar.stability.time_error.small`) and the robust Allan variance's running median, outlier
and square kernels (:mod:`avar.stability.robust.estimator`, twin :mod:`avar.stability.robust.small`).
Where a twin cannot certify its
result (adversarial data), or cannot apply (gaps), the kernels run whatever this says.

Forcing one path (the tests run the exactness tests on each): the environment variable
``AVAR_KERNEL_PATH`` (read when the kernels load: :data:`ENVIRONMENT_MODE`), or
:data:`FORCED` (wins when set; see :func:`forced`), is ``"numpy"`` (the NumPy twins at
any size), ``"compiled"`` (never them) or ``"auto"`` (the default).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["CALL_WORK", "ENVIRONMENT", "ENVIRONMENT_MODE", "FORCED", "PATHS", "compiled", "forced", "numpy_path", "path_mode"]

#: The environment variable that forces a path.
ENVIRONMENT = "AVAR_KERNEL_PATH"
#: Its values: by size, NumPy whenever it applies, compiled always.
PATHS = ("auto", "numpy", "compiled")
#: ``AVAR_KERNEL_PATH`` as it was when the kernels loaded (read once: a dispatch costs no lookup).
ENVIRONMENT_MODE: str | None = os.environ.get(ENVIRONMENT) or None
#: A path forced from Python (``None``: the environment variable decides); tests set it through :func:`forced`.
FORCED: str | None = None


def path_mode() -> str:
    """The mode in force: :data:`FORCED`, else :data:`ENVIRONMENT_MODE`, else ``"auto"``.

    >>> with forced("compiled"):
    ...     path_mode()
    'compiled'
    """
    mode = FORCED or ENVIRONMENT_MODE or "auto"
    if mode not in PATHS:
        raise ValueError(f"{ENVIRONMENT} must be one of {', '.join(PATHS)}, got {mode!r}")
    return mode


#: Work (samples, terms) a dispatch may spend in its NumPy twin in one process before it compiles
#: its kernels after all (ski rental: about as much time lost to the twin as compiling costs once).
#: Measured (issue 39): the twins lose about 25 ms per 1e6 samples to the kernels (OADEV's noise
#: identification and scan) and 0.4 ms per call of 1e4 (``avar()``), so 2**25 units plus
#: :data:`CALL_WORK` per call lose 0.5 to 1 s, against 1 to 3 s of compilation.
HOT_WORK = 1 << 25
#: Work charged per dispatch on top of its size: a twin's fixed cost per call (NumPy's per-operation
#: overhead, a few hundred microseconds) in samples, so that many small calls turn hot too.
CALL_WORK = 1 << 13
#: (kernel, first argument's type) pairs known compiled, and those numba's cache lacked at the first look.
_COMPILED: set[tuple] = set()
_NOT_CACHED: set[tuple] = set()
#: Work spent in the twins so far, by the kernels they stood in for.
_SPENT: dict[tuple, int] = {}
#: Callers' routes whose kernels were found compiled (a dispatch then costs one set lookup).
_WARM_ROUTES: set = set()


def _type_key(argument: object) -> object:
    """A cheap stand-in for the numba type of ``argument`` (arrays: dtype, dimensions, layout, flags)."""
    if argument is None:
        return None
    flags = getattr(argument, "flags", None)
    if flags is None:
        return type(argument)
    return (argument.dtype.str, argument.ndim, flags.c_contiguous, flags.f_contiguous, flags.writeable,
            flags.aligned)


def compiled(kernels: tuple, argument: object = None) -> bool:
    """Whether every numba dispatcher in ``kernels`` has machine code, compiled in this
    process or in numba's cache for this CPU (with ``argument``: for its type as the first
    argument; an entry ``(dispatcher, argument)`` gives its own). Never compiles; numba's
    cache index is read once per kernel and process, and a kernel found compiled is
    remembered (a set lookup per call from then on).

    >>> from numba import njit
    >>> twice = njit(lambda x: 2 * x)
    >>> compiled((twice,)), twice(1.0), compiled((twice,)), compiled(((twice, 1),))
    (False, 2.0, True, False)
    """
    for entry in kernels:
        kernel, given = entry if isinstance(entry, tuple) else (entry, argument)
        key = (id(kernel), _type_key(given))
        if key in _COMPILED:
            continue
        import numba

        first = None if given is None else numba.typeof(given)
        if any(first is None or signature[0] == first for signature in kernel.signatures):
            _COMPILED.add(key)
            continue
        if key in _NOT_CACHED:
            return False
        from avar._kernels.runtime.cache import cached_for_this_machine

        if not cached_for_this_machine(kernel, first):
            _NOT_CACHED.add(key)
            return False
        _COMPILED.add(key)
    return True


def numpy_path(work: int | Callable[[], int], limit: int, kernels: tuple | Callable[[], tuple] = (),
               argument: object = None, fits: bool = True, route: object = None) -> bool:
    """Whether a call of ``work`` units (samples, terms) takes the NumPy twin: forced, or its
    work is within ``limit`` (and ``fits``, the caller's other size limits, holds),
    ``kernels`` are not :func:`compiled` yet (for ``argument``) and the twins standing in
    for them have spent less than :data:`HOT_WORK` in this process (each call its work plus
    :data:`CALL_WORK`). ``work`` and ``kernels``
    may be callables, evaluated only when needed; ``route``, a hashable that determines
    ``kernels`` and their argument types, skips even that once they were found compiled.

    >>> from numba import njit
    >>> cold = njit(lambda x: x)
    >>> with forced("auto"):
    ...     numpy_path(10_000, 1 << 17, (cold,)), numpy_path(1 << 20, 1 << 17, (cold,))
    (True, False)
    >>> with forced("numpy"):
    ...     numpy_path(1 << 20, 1 << 17, (cold,))
    True
    """
    mode = path_mode()
    if mode != "auto":
        return mode == "numpy"
    if not fits or (route is not None and route in _WARM_ROUTES):
        return False
    kernels = kernels() if callable(kernels) else kernels
    if compiled(kernels, argument):
        if route is not None:
            _WARM_ROUTES.add(route)
        return False
    work = work() if callable(work) else work
    if work > limit:
        return False
    # the kernels themselves, not their id(): an id is reused once its object is collected, and a
    # new kernel must not inherit a dead one's spent work
    key = tuple(entry[0] if isinstance(entry, tuple) else entry for entry in kernels)
    spent = _SPENT.get(key, 0) + work + CALL_WORK
    if spent > HOT_WORK:
        return False  # hot: compile now, and be fast from here on
    _SPENT[key] = spent
    return True


@contextmanager
def forced(mode: str) -> Iterator[None]:
    """Within the block, every dispatch takes the path ``mode`` (one of :data:`PATHS`)."""
    global FORCED
    if mode not in PATHS:
        raise ValueError(f"mode must be one of {', '.join(PATHS)}, got {mode!r}")
    before = FORCED
    FORCED = mode
    try:
        yield
    finally:
        FORCED = before
