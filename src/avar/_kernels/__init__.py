"""Hot loops of the library, compiled with numba: nothing else lives here.

Nothing here validates input or builds objects: the public functions
validate once at the boundary and call these kernels on clean arrays. The
tests check every kernel against a plain NumPy transcription.

* :mod:`avar._kernels.classic.sums`: compensated cumulative sums held in memory and
  squared second differences per level (the deviation family's kernels).
* :mod:`avar._kernels.allan.columns`: the plain-array entry point of the Allan
  variance, :func:`allan_variance_columns` (any real dtype, read in place in
  blocks, a small workspace instead of O(N) arrays). It dispatches to
  :mod:`avar._kernels.allan.small` (short series: one call, one thread),
  :mod:`avar._kernels.allan.haar` (octave "to": the Haar pyramid, one read),
  :mod:`avar._kernels.allan.sweep` and :mod:`avar._kernels.allan.far` (octave "mo":
  a cache-blocked sweep of the small levels, the large ones by residue
  class) or :mod:`avar._kernels.allan.levels` (any other grid, level by level),
  all on the primitives of :mod:`avar._kernels.allan.blocks`.
* :mod:`avar._kernels.models.covariance`: the theoretical Allan variance of a
  covariance matrix (one validating pass, then O(n) per scale).
* :mod:`avar._kernels.robust`: residuals from interpolation and the running median (outliers).
* :mod:`avar._kernels.models.simulation`: recursions of the simulated processes.
* :mod:`avar._kernels.runtime.cache`: where numba's cache goes (the user's cache
  directory when the package folder is not writable).
"""

import os

from avar._kernels.runtime.cache import configure as _configure_cache

# Before numba loads: a read-only package keeps its compiled kernels in the user's cache.
_configure_cache()

# numba's OpenMP threads spin-wait between parallel regions by default; when
# another process holds a core, a short parallel call can then take 10-100x
# longer. A short spin before sleeping keeps full speed on an idle machine and
# degrades gracefully on a busy one. The user's own settings win. (Read by
# libgomp when numba first starts its thread pool, i.e. after this import.)
if "OMP_WAIT_POLICY" not in os.environ and "GOMP_SPINCOUNT" not in os.environ:
    os.environ["GOMP_SPINCOUNT"] = "1000"

from avar._kernels.allan.columns import allan_variance_columns as streaming_allan_variance  # noqa: E402
from avar._kernels.classic.sums import (  # noqa: E402
    BLOCK,
    CHUNK,
    CUMSUM_BLOCK,
    FUSED_BLOCK,
    FUSED_MAX_LEVELS,
    centred_cumsum,
    fused_overlapping_sums,
    squared_difference_sums,
    task_sums,
)
from avar._kernels.models.covariance import COV_TILE, NOAV_SCAN_RATIO, covariance_pass, moav_from_sums  # noqa: E402
from avar._kernels.models.simulation import ar1_recursion  # noqa: E402
from avar._kernels.robust import (  # noqa: E402
    intact_squares,
    interpolation_residuals,
    release_candidates,
    running_median,
)
