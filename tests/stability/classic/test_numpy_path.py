"""Short records' NumPy path (nothing to compile) against the compiled kernels, each path forced in turn.

Issue 39: the first call of a statistic on a short record answers without compiling, through
NumPy twins (:mod:`avar.stability.classic.small`, :mod:`avar.stability.uncertainty.lag1`, the
scan), which certify their error and otherwise leave the call to the kernels. Both paths must
give the same statistic: variances to 1e-12 (relative), the same noise exponents, the same
EDF. The whole suite passes on either path (``AVAR_KERNEL_PATH=numpy`` or ``compiled``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction

import numpy as np
import pytest

import avar
from avar._kernels.classic.phase import scan
from avar._kernels.runtime.paths import forced
from avar.stability.classic import core, small
from avar.stability.shared.grids import deviation_factors
from avar.stability.shared.inputs import check_data
from avar.stability.shared.registry import CLASSIC
from tests._support.powerlaw import powerlaw_phase

#: Records of every noise type and the hard cases of the compensated kernels, n values each.
DATA = {
    "white FM": lambda rng, n: rng.standard_normal(n),
    "flicker FM": lambda rng, n: np.diff(powerlaw_phase(n + 1, -1, int(rng.integers(1000)))),
    "random-walk FM": lambda rng, n: np.cumsum(rng.standard_normal(n)),
    "white PM": lambda rng, n: np.diff(rng.standard_normal(n + 1)),
    "offset 1e9 + 1e-6 noise": lambda rng, n: 1e9 + 1e-6 * rng.standard_normal(n),
    "offset 1e6 + 1e-3 random walk": lambda rng, n: 1e6 + 1e-3 * np.cumsum(rng.standard_normal(n)),
    "integers": lambda rng, n: rng.integers(-500, 500, n).astype(np.float64),
}
#: (record length, taus) pairs: every level of a short record, decades, octaves of a longer one, a list.
GRIDS = [(300, "all"), (2000, "decade"), (20_000, "octave"), (1500, [1, 3, 7, 20, 100])]


def _both(statistic: str, data: np.ndarray, **options) -> tuple:
    """The statistic by the NumPy path and by the compiled one."""
    results = []
    for mode in ("numpy", "compiled"):
        with forced(mode):
            results.append(getattr(avar, statistic)(data, **options))
    return tuple(results)


def _same(numpy_result, compiled_result, rtol=1e-12):
    np.testing.assert_array_equal(numpy_result.averaging_factors, compiled_result.averaging_factors)
    np.testing.assert_array_equal(numpy_result.n, compiled_result.n)
    np.testing.assert_allclose(numpy_result.variance, compiled_result.variance, rtol=rtol, atol=0)
    np.testing.assert_array_equal(numpy_result.alpha, compiled_result.alpha)
    np.testing.assert_allclose(numpy_result.edf, compiled_result.edf, rtol=1e-9)


def _took_numpy(estimator: str, data: np.ndarray, data_type: str, taus) -> bool:
    """Whether the NumPy path certifies these levels (rather than leaving them to the kernels)."""
    values, scanned = check_data(data, data_type, "raise", weigh=estimator in core.HADAMARD and data_type == "freq")
    factors = deviation_factors(estimator, values.size + (data_type == "freq"), 1.0, taus)
    with forced("numpy"):
        return core.numpy_levels(estimator, values, factors, data_type, scanned) is not None


@pytest.mark.parametrize("kind", DATA)
@pytest.mark.parametrize("estimator", CLASSIC)
def test_both_paths_give_the_same_statistic(estimator, kind):
    rng = np.random.default_rng(sorted(DATA).index(kind))
    for n, taus in GRIDS:
        data = DATA[kind](rng, n)
        for data_type in ("freq", "phase"):
            numpy_result, compiled_result = _both(estimator, data, data_type=data_type, taus=taus, rate=2.0)
            _same(numpy_result, compiled_result)
            assert _took_numpy(estimator, data, data_type, taus), (n, taus, data_type)


@pytest.mark.parametrize(("data", "estimator", "data_type"), [
    (np.pi * np.arange(300.0) ** 2, "hdev", "phase"),  # the Hadamard terms are the data's rounding
    (np.pi * np.arange(300.0) ** 2, "ohdev", "phase"),
    (np.random.default_rng(3).standard_normal(300) * 10.0 ** np.random.default_rng(4).integers(-150, 150, 300),
     "oadev", "phase"),  # 300 decades
])
def test_levels_the_bound_cannot_certify_take_the_kernels(data, estimator, data_type):
    assert not _took_numpy(estimator, data, data_type, "all")
    numpy_result, compiled_result = _both(estimator, data, data_type=data_type, taus="all")
    np.testing.assert_array_equal(numpy_result.variance, compiled_result.variance)  # the same kernels ran


def test_gaps_take_the_kernels():
    data = np.random.default_rng(5).standard_normal(1000)
    data[[10, 500]] = np.nan
    values, scanned = check_data(data, "freq", "omit")
    with forced("numpy"):
        assert core.numpy_levels("oadev", values, np.array([1, 2, 4]), "freq", scanned) is None
    numpy_result, compiled_result = _both("oadev", data, nan_policy="omit")
    np.testing.assert_allclose(numpy_result.variance, compiled_result.variance, rtol=1e-14)  # the scans' sums


def test_warm_kernels_take_their_path_in_auto_mode():
    data = np.random.default_rng(6).standard_normal(3000)
    with forced("compiled"):
        avar.mdev(data)  # compiles (or loads) the kernels of MDEV's levels
    values, scanned = check_data(data, "freq", "raise")
    factors = deviation_factors("mdev", values.size + 1, 1.0, "octave")
    with forced("auto"):
        assert core.numpy_levels("mdev", values, factors, "freq", scanned) is None


def test_the_split_running_sum_is_exact_up_to_its_bound():
    """hi: exact running sums of the high parts; lo within ``k step`` of the exact rest after k steps."""
    rng = np.random.default_rng(7)
    high = 1e6 + rng.standard_normal(500) * 1e3
    low = rng.standard_normal(500) * 1e-12
    total = small.split_running_sum(small.Pairs(high, low))
    exact = Fraction(0)
    for k in range(1, 501):
        exact += Fraction(float(high[k - 1])) + Fraction(float(low[k - 1]))
        assert Fraction(float(total.hi[k])) % Fraction(total.grid) == 0  # on the grid
        assert abs(Fraction(float(total.hi[k])) + Fraction(float(total.lo[k])) - exact) <= k * Fraction(total.step)


def test_a_grid_too_fine_for_exact_sums_is_refused():
    high = np.full(1000, 1.0)
    assert small.split_running_sum(small.Pairs(high, np.zeros(1000)), grid=2.0**-45) is None  # sums reach 2**55 g
    assert small.split_running_sum(small.Pairs(high, np.zeros(1000)), grid=2.0**-38) is not None


def test_data_on_a_coarse_grid_are_summed_exactly():
    """Integers (or a large offset): the line is moved to the grid and no low part is left."""
    data = np.random.default_rng(8).integers(-1000, 1000, 5000).astype(np.float64)
    exact = small.exact_phase(data, 0, float(data.mean()), 0.0, 1.0 / 1024)
    assert exact.phase.step == 0.0 and not exact.phase.lo.any()


def test_the_scan_is_the_same_on_both_paths():
    rng = np.random.default_rng(9)
    for data in (rng.standard_normal(10_000), np.r_[rng.standard_normal(99), np.nan, 3.0, np.inf],
                 np.full(10, np.nan), 1e9 + rng.standard_normal(1000)):
        with forced("numpy"):
            numpy_scan = scan(data, weigh=True)
        with forced("compiled"):
            compiled_scan = scan(data, weigh=True)
        assert numpy_scan[0] == compiled_scan[0] and numpy_scan[2:4] == compiled_scan[2:4]
        np.testing.assert_allclose(numpy_scan[1], compiled_scan[1], rtol=1e-13)
        # the centred moment (a drift's numerator: any value keeps the statistics exact) to the rounding of its terms
        weights = np.abs(np.arange(data.size) - (data.size - 1) / 2.0) * np.abs(data)
        np.testing.assert_allclose(numpy_scan[4], compiled_scan[4], rtol=0, atol=1e-13 * np.sum(weights))


@pytest.mark.parametrize("dtype", ["float64", "float32", "int16", "int64", "uint8", "bool"])
def test_allan_variance_paths_agree(dtype):
    rng = np.random.default_rng(10)
    raw = np.cumsum(rng.standard_normal(4000)) * 40 + 1e4
    data = (raw > 1e4) if dtype == "bool" else raw.astype(dtype)
    for kind in ("mo", "to"):
        for taus in ("octave", "all", [0.01, 0.07, 1.0]):
            results = []
            for mode in ("numpy", "compiled"):
                with forced(mode):
                    results.append(avar.avar(data, type=kind, rate=100.0, taus=taus, ci="chi2"))
            np.testing.assert_allclose(results[0].allan, results[1].allan, rtol=1e-12, atol=0)
            np.testing.assert_array_equal(results[0].alpha, results[1].alpha)


def test_allan_variance_of_an_imu_and_of_huge_integers():
    from avar.stability.allan.columns import numpy_columns

    rng = np.random.default_rng(11)
    imu = avar.IMU(rng.standard_normal((3000, 6)) * 1e-3, 100.0, gyro=[0, 1, 2], accel=[3, 4, 5])
    with forced("numpy"):
        a = avar.avar(imu)
    with forced("compiled"):
        b = avar.avar(imu)
    for channel in imu.channels:
        np.testing.assert_allclose(a[channel].allan, b[channel].allan, rtol=1e-12)
    beyond = rng.integers(2**60, 2**62, 1000)  # not exact in float64: the kernels split them
    with forced("numpy"):
        assert numpy_columns(beyond, np.array([1, 2, 4]), "mo") is None


#: A fresh interpreter with an empty numba cache: counts numba's compilations during the calls.
COLD = """
import json, numpy as np
from numba.core import event
compiled = []
class Count(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__qualname__)
    def on_end(self, ev):
        pass
event.register("numba:compile", Count())
import avar
y = np.random.default_rng(1).standard_normal(10_000)
out = {name: getattr(avar, name)(y).variance.tolist() for name in %r}
out["phase"] = avar.mdev(np.cumsum(y), data_type="phase").variance.tolist()
out["avar"] = avar.avar(y, rate=100.0).allan.tolist()
out["chi2"] = avar.avar(y, type="to", ci="chi2").alpha.tolist()
print(json.dumps({"compiled": compiled, "results": out}))
"""


def test_a_first_call_compiles_nothing(tmp_path):
    """Every classic statistic and ``avar()`` on 1e4 samples, in a new process with an empty cache."""
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")}
    environment.pop("AVAR_KERNEL_PATH", None)
    run = subprocess.run([sys.executable, "-c", COLD % (list(CLASSIC),)], env=environment, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout.splitlines()[-1])
    assert report["compiled"] == []
    y = np.random.default_rng(1).standard_normal(10_000)
    with forced("compiled"):
        expected = {name: getattr(avar, name)(y).variance for name in CLASSIC}
        expected["phase"] = avar.mdev(np.cumsum(y), data_type="phase").variance
        expected["avar"] = avar.avar(y, rate=100.0).allan
        expected["chi2"] = avar.avar(y, type="to", ci="chi2").alpha
    for name, values in expected.items():
        np.testing.assert_allclose(report["results"][name], values, rtol=1e-12, err_msg=name)
