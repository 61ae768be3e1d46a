"""The deviation family avar.adev ... avar.totdev, avar.mhdev, avar.htdev against allantools, exact
arithmetic, plain loops and NIST."""

from __future__ import annotations

import math

import allantools
import numpy as np
import pandas as pd
import pytest

import avar
from avar.stability.shared.grids import deviation_factors, max_factor
from avar.stability.shared.registry import CLASSIC as ESTIMATORS
from tests._support.deviation_reference import exact_variance, fsum_variance, nbs14_1000
from tests._support.paths import STABLE32

RATE = 2.0


def power_law(kind: str, n: int, seed: int) -> np.ndarray:
    """White, flicker (by the FN process) or random-walk noise."""
    rng = np.random.default_rng(seed)
    if kind == "white":
        return rng.standard_normal(n)
    if kind == "random walk":
        return np.cumsum(rng.standard_normal(n))
    return avar.FN(1.0).simulate(n, seed=seed)


def raw(estimator):
    """The raw statistic, as its definition: TOTDEV without the removal of TOTVAR's bias."""
    return {"bias_correction": False} if estimator == "totdev" else {}


def allantools_result(estimator, data, data_type, taus):
    return getattr(allantools, estimator)(data, rate=RATE, data_type=data_type, taus=taus)


#: The statistics allantools computes (it has no modified Hadamard deviation, nor HTDEV).
IN_ALLANTOOLS = [name for name in ESTIMATORS if hasattr(allantools, name)]


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("kind", ["white", "flicker", "random walk"])
@pytest.mark.parametrize("n", [10, 101, 1000, 10_000])
@pytest.mark.parametrize("estimator", IN_ALLANTOOLS)
def test_equals_allantools(estimator, n, kind):
    """Same taus, same n, values to 1e-10; ours adds only levels with a single term."""
    data = power_law(kind, n, seed=n) * 1e-9
    for data_type in ("freq", "phase"):
        taus = "all" if n <= 1000 else "octave"
        ours = getattr(avar, estimator)(data, rate=RATE, data_type=data_type, taus=taus, **raw(estimator))
        t, dev, _, ns = allantools_result(estimator, data, data_type, taus)
        common = np.isin(ours.taus, t)
        assert np.array_equal(ours.taus[common], t)
        np.testing.assert_allclose(ours.deviation[common], dev, rtol=1e-10, atol=0)
        assert ours.n[common].tolist() == ns.astype(int).tolist()
        # every level allantools lacks has a single term (its remove_small_ns)
        assert set(ours.n[~common].tolist()) <= {1}
        assert ours.averaging_factors[-1] <= max_factor(estimator, ours.n_samples + (data_type == "freq"))


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_largest_level_has_one_term(estimator):
    data = power_law("white", 37, seed=1)
    res = getattr(avar, estimator)(data, data_type="phase", taus="all")
    assert res.averaging_factors[-1] == max_factor(estimator, 37)
    expected = {"adev": 1, "oadev": 1, "mdev": 2, "tdev": 2, "hdev": 1, "ohdev": 1, "totdev": 35,  # 37 - 36 + 1 for MDEV
                "mhdev": 2, "htdev": 2}  # 37 - 36 + 1 at m = 9
    assert res.n[-1] == expected[estimator]
    with pytest.raises(ValueError, match="outside the valid range"):
        getattr(avar, estimator)(data, data_type="phase", taus=[max_factor(estimator, 37) + 1])


def test_grids():
    assert deviation_factors("oadev", 1025).tolist() == [1, 2, 4, 8, 16, 32, 64, 128, 256, 512]
    assert deviation_factors("mdev", 1025).tolist() == [1, 2, 4, 8, 16, 32, 64, 128, 256]
    assert deviation_factors("adev", 1001, taus="decade").tolist() == [1, 2, 4, 10, 20, 40, 100, 200, 400]
    assert deviation_factors("oadev", 101, 10.0, [0.1, 0.21, 0.2]).tolist() == [1, 2]
    assert avar.oadev(np.ones(64) + np.arange(64) % 2).taus[0] == 1.0


ADVERSARIAL = {
    "offset 1e6 + 1e-3 noise": lambda rng, n: 1e6 + 1e-3 * rng.standard_normal(n),
    "drift 1e3 + 1e-9 noise": lambda rng, n: 1e3 * np.arange(n) + 1e-9 * rng.standard_normal(n),
    "quadratic + random walk": lambda rng, n: 1e-2 * np.arange(n) ** 2 + 1e-6 * np.cumsum(rng.standard_normal(n)),
    "tiny 1e-300": lambda rng, n: 1e-300 * rng.standard_normal(n),
}


@pytest.mark.parametrize("case", ADVERSARIAL)
@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_exact_arithmetic_on_adversarial_data(estimator, case):
    """Against a loop over the formula in exact rationals, to 1e-10 relative."""
    rng = np.random.default_rng(7)
    data = ADVERSARIAL[case](rng, 48)
    for data_type in ("freq", "phase"):
        if estimator not in ("hdev", "ohdev") and case.startswith("quadratic") and data_type == "phase":
            continue  # not cancellation-prone: the quadratic dominates the second differences
        res = getattr(avar, estimator)(data, rate=3.0, data_type=data_type, taus="all", **raw(estimator))
        for m, variance, n in zip(res.averaging_factors[::3], res.variance[::3], res.n[::3]):
            expected, count = exact_variance(estimator, data, int(m), data_type, 3.0)
            assert n == count
            assert variance == pytest.approx(expected, rel=1e-10, abs=0), (m, data_type)


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_fsum_loop_larger(estimator):
    data = 5.0 + power_law("flicker", 600, seed=3)
    res = getattr(avar, estimator)(data, data_type="freq", taus=[1, 7, 64, 150], **raw(estimator))
    for m, variance, n in zip(res.averaging_factors, res.variance, res.n):
        expected, count = fsum_variance(estimator, data, int(m), "freq")
        assert n == count
        assert variance == pytest.approx(expected, rel=1e-10)


#: NIST SP 1065, table of the 1000-point test suite (tau = 1, 10, 100), as printed.
NBS14_1000 = {
    "adev": [2.922319e-01, 9.965736e-02, 3.897804e-02],
    "oadev": [2.922319e-01, 9.159953e-02, 3.241343e-02],
    "mdev": [2.922319e-01, 6.172376e-02, 2.170921e-02],
    "tdev": [1.687202e-01, 3.563623e-01, 1.253382e00],
    "hdev": [2.943883e-01, 1.052754e-01, 3.910860e-02],
    "ohdev": [2.943883e-01, 9.581083e-02, 3.237638e-02],
    "totdev": [2.922319e-01, 9.134743e-02, 3.406530e-02],
}


@pytest.mark.parametrize("estimator", NBS14_1000)
def test_nist_nbs14_1000_point(estimator):
    y = nbs14_1000()
    phase = np.concatenate(([0.0], np.cumsum(y - y.mean())))
    for data, data_type in ((y, "freq"), (phase, "phase")):
        res = getattr(avar, estimator)(data, data_type=data_type, taus=[1, 10, 100])
        # printed to 7 significant digits: half a unit of the last one
        np.testing.assert_allclose(res.deviation, NBS14_1000[estimator], rtol=5e-7)


def test_tdev_is_tau_over_sqrt3_mdev():
    y = power_law("white", 500, 2)
    m, t = avar.mdev(y, rate=4.0, taus="all"), avar.tdev(y, rate=4.0, taus="all")
    np.testing.assert_allclose(t.deviation, m.taus / np.sqrt(3) * m.deviation, rtol=1e-14)


def test_hadamard_ignores_frequency_drift():
    y = power_law("white", 2000, 4)
    drifted = y + 1e3 + 0.5 * np.arange(2000)
    for estimator in ("hdev", "ohdev", "mhdev", "htdev"):
        a = getattr(avar, estimator)(y, taus="all").variance
        b = getattr(avar, estimator)(drifted, taus="all").variance
        np.testing.assert_allclose(b, a, rtol=1e-9)


def plain_mhdev(x: np.ndarray, m: int, rate: float) -> tuple[float, int]:
    """MHVAR by its definition (NIST SP 1065 section 5.2.10), a plain loop over the phase x (s)::

        sum_{j=0}^{N-4m} [sum_{i=j}^{j+m-1} (x_{i+3m} - 3 x_{i+2m} + 3 x_{i+m} - x_i)]^2 / (6 m^2 tau^2 (N - 4m + 1))
    """
    n = x.size
    tau = m / rate
    total = []
    for j in range(n - 4 * m + 1):
        inner = 0.0
        for i in range(j, j + m):
            inner += x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i]
        total.append(inner * inner)
    return math.fsum(total) / (6.0 * m * m * tau * tau * len(total)), len(total)


@pytest.mark.parametrize("kind", ["white", "flicker", "random walk"])
def test_mhdev_and_htdev_equal_plain_loops(kind):
    """MHDEV and HTDEV = tau / sqrt(10/3) MHDEV against a plain loop over the definition, to 1e-10."""
    data = power_law(kind, 700, seed=11) * 1e-9
    for data_type in ("freq", "phase"):
        x = np.concatenate(([0.0], np.cumsum(data))) / RATE if data_type == "freq" else data
        mh = avar.mhdev(data, rate=RATE, data_type=data_type, taus="all")
        ht = avar.htdev(data, rate=RATE, data_type=data_type, taus="all")
        assert mh.averaging_factors[-1] == x.size // 4 and mh.n[-1] == x.size - 4 * (x.size // 4) + 1
        for k in list(range(0, mh.taus.size, 17)) + [mh.taus.size - 1]:
            m = int(mh.averaging_factors[k])
            variance, count = plain_mhdev(x, m, RATE)
            assert mh.n[k] == ht.n[k] == count
            assert mh.variance[k] == pytest.approx(variance, rel=1e-10)
            tau = m / RATE
            assert ht.variance[k] == pytest.approx(variance * tau * tau * 3 / 10, rel=1e-10)
        np.testing.assert_array_equal(ht.alpha, mh.alpha)
        np.testing.assert_allclose(ht.edf, mh.edf, rtol=0)


def test_htdev_is_the_phase_deviation_of_white_pm():
    """The factor sqrt(10/3): HTDEV of white PM of standard deviation s is s / sqrt(m), as TDEV."""
    x = np.random.default_rng(12).standard_normal(200_000) * 1e-9
    res = avar.htdev(x, data_type="phase", taus=[1, 4, 16])
    np.testing.assert_allclose(res.deviation * np.sqrt(res.averaging_factors), 1e-9, rtol=0.02)
    assert res.alpha.tolist() == [2, 2, 2]


def test_mhdev_edf_is_greenhalls_modified_hadamard():
    from avar.stability.uncertainty.edf import greenhall_edf

    y = power_law("white", 3000, 13)
    res = avar.mhdev(y, taus="octave")
    expected = greenhall_edf(res.alpha, 3, res.averaging_factors, 3001, overlapping=True, modified=True)
    np.testing.assert_allclose(res.edf, expected, rtol=1e-14)
    assert np.all((res.lci < res.deviation) & (res.deviation < res.uci))


def test_result_fields_summary_and_text():
    y = power_law("white", 4096, 5)
    res = avar.oadev(y, rate=10.0, confidence=0.95)
    assert isinstance(res, avar.Deviation)
    assert res.estimator == "oadev" and res.data_type == "freq" and res.rate == 10.0 and res.n_samples == 4096
    assert res.alpha.tolist()[:6] == [0] * 6  # white FM
    assert np.all((res.lci < res.deviation) & (res.deviation < res.uci))
    np.testing.assert_allclose(res.variance, res.deviation**2)
    table = res.summary()
    assert list(table.columns) == ["Tau", "m", "N terms", "Alpha", "Min sigma", "Sigma", "Max sigma", "EDF"]
    assert table["Tau"].iloc[0] == 0.1 and table["N terms"].iloc[0] == 4095
    assert "OADEV" in str(res) and "OADEV" in repr(res)
    with pytest.raises(AttributeError):
        res.deviation = 0
    with pytest.raises(ValueError):
        res.deviation[0] = 1.0
    # a wider confidence gives wider bounds
    narrow = avar.oadev(y, rate=10.0)
    assert np.all(narrow.uci < res.uci) and np.all(narrow.lci > res.lci)


def test_series_input():
    y = pd.Series(power_law("white", 300, 6))
    np.testing.assert_array_equal(avar.adev(y).deviation, avar.adev(y.to_numpy()).deviation)


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(data="abc"), TypeError, "data"),
        (dict(data=np.ones((10, 2))), ValueError, "data must be 1-D"),
        (dict(data=[1.0]), ValueError, "data has 1 sample"),
        (dict(data=[1.0, np.inf, 2.0, 3.0, 4.0]), ValueError, "infinite value.*index 1"),
        (dict(data=[1.0, 2.0, np.nan, 3.0, 4.0]), ValueError, "NaN value.*index 2.*nan_policy"),
        (dict(data_type="time"), ValueError, "data_type"),
        (dict(rate=0.0), ValueError, "rate"),
        (dict(rate="1"), TypeError, "rate"),
        (dict(taus="weekly"), ValueError, "taus"),
        (dict(taus=[[1.0]]), TypeError, "taus"),
        (dict(taus=[0.1]), ValueError, r"taus \[0.1\] are outside the valid range \[1, 50\] s of oadev"),
        (dict(confidence=1.5), ValueError, "confidence"),
        (dict(confidence="high"), TypeError, "confidence"),
        (dict(nan_policy="drop"), ValueError, "nan_policy"),
        (dict(data=pd.DataFrame({"a": range(10)})), TypeError, "DataFrame"),
        (dict(data=np.ones(10, dtype=complex)), TypeError, "complex"),
        (dict(alpha=3), ValueError, r"alpha must be in -2 \.\. 2"),
        (dict(alpha=0.5), TypeError, "alpha must be None or an integer"),
        (dict(alpha=True), TypeError, "alpha must be None or an integer"),
    ],
)
def test_bad_inputs_name_the_argument(kwargs, error, message):
    arguments = dict(data=np.arange(100.0) % 7)
    arguments.update(kwargs)
    data = arguments.pop("data")
    with pytest.raises(error, match=message):
        avar.oadev(data, **arguments)


@pytest.mark.filterwarnings("ignore")
def test_nan_omit_matches_gradev():
    rng = np.random.default_rng(8)
    phase = np.cumsum(rng.standard_normal(2000)) * 1e-9
    phase[[10, 500, 501, 502, 1333]] = np.nan
    ours = avar.oadev(phase, rate=RATE, data_type="phase", taus="all", nan_policy="omit")
    t, dev, _, ns = allantools.gradev(phase, rate=RATE, data_type="phase", taus="all")
    common = np.isin(ours.taus, t)
    assert np.array_equal(ours.taus[common], t)
    np.testing.assert_allclose(ours.deviation[common], dev, rtol=1e-10)
    assert ours.n[common].tolist() == ns.astype(int).tolist()
    assert ours.n[0] == 1998 - 3 - 5 - 3  # terms b .. b + 2 touching 10; 500..502; 1333


@pytest.mark.parametrize("estimator", ESTIMATORS)
@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_nan_omit_matches_the_definition(estimator, data_type):
    rng = np.random.default_rng(9)
    data = 3.0 + rng.standard_normal(60)
    data[[0, 17, 18, 41]] = np.nan
    res = getattr(avar, estimator)(data, data_type=data_type, taus="all", nan_policy="omit", **raw(estimator))
    for m, variance, n in zip(res.averaging_factors, res.variance, res.n):
        expected, count = exact_variance(estimator, data, int(m), data_type)
        assert n == count > 0
        assert variance == pytest.approx(expected, rel=1e-10)
    assert res.n_samples == 60


def test_avar_nan_omit_is_oadev_and_adev():
    rng = np.random.default_rng(10)
    y = rng.standard_normal(3000)
    y[[5, 1200, 1201, 2999]] = np.nan
    mo = avar.avar(y, taus="all", nan_policy="omit")
    o = avar.oadev(y, taus="all", nan_policy="omit")
    keep = np.isin(o.averaging_factors, mo.averaging_factors)
    np.testing.assert_allclose(mo.allan, o.variance[keep], rtol=1e-12)
    assert mo.n_differences.tolist() == o.n[keep].tolist()
    to = avar.avar(y, type="to", taus="all", nan_policy="omit", ci="chi2")
    a = avar.adev(y, taus="all", nan_policy="omit")
    keep = np.isin(a.averaging_factors, to.averaging_factors)
    np.testing.assert_allclose(to.allan, a.variance[keep], rtol=1e-12)
    assert to.n_differences.tolist() == a.n[keep].tolist()
    assert np.all(to.chi2_lci < to.adev)
    # without NaN, "omit" changes nothing
    clean = np.nan_to_num(y)
    np.testing.assert_array_equal(avar.avar(clean, nan_policy="omit").allan, avar.avar(clean).allan)
    with pytest.raises(ValueError, match="NaN"):
        avar.avar(y)
    with pytest.raises(ValueError, match="nan_policy"):
        avar.avar(clean, nan_policy="skip")


def test_gap_scaled_edf_never_falls_below_one_degree_of_freedom():
    # a level whose terms nearly all touch a gap keeps EDF >= 1, so both bounds stay finite
    y = np.random.default_rng(10).standard_normal(3000)
    y[[5, 1200, 1201, 2999]] = np.nan
    for result in (avar.adev(y, taus="all", nan_policy="omit"),
                   avar.avar(y, type="to", taus="all", nan_policy="omit", ci="chi2")):
        assert result.edf.min() == 1.0
        assert np.isfinite(result.uci).all() and (result.lci > 0).all()


# Stable32, pink_frequency.txt (flicker FM, 10,000 frequency points, tau0 = 42 s), TOTDEV with the noise
# identified (allantools' tests/pink_frequency/totdev.txt): AF, alpha, Total Sigma.
STABLE32_PINK_TOTDEV = [(1, -1, 1.4064e-07), (2, -2, 1.3636e-07), (16, -2, 1.3668e-07), (33, -2, 1.3507e-07),
                        (46, -1, 1.3697e-07), (48, 0, 1.3697e-07), (2369, 0, 3.0657e-08)]


def test_totdev_removes_totvars_bias_as_stable32():
    """Stable32 divides TOTVAR by 1 - a m / N at flicker (a = 1 / 3 ln 2) and random-walk FM (3 / 4):
    its printed values, which the raw statistic misses by up to 1.2e-3 here."""
    y = np.loadtxt(STABLE32 / "pink_frequency.txt")
    rows = np.array(STABLE32_PINK_TOTDEV)
    res = avar.totdev(y, rate=1 / 42, taus=rows[:, 0] * 42)
    plain = avar.totdev(y, rate=1 / 42, taus=rows[:, 0] * 42, bias_correction=False)
    assert res.alpha.tolist() == rows[:, 1].astype(int).tolist()
    np.testing.assert_allclose(res.deviation, rows[:, 2], rtol=3e-5)  # Stable32 prints 5 digits
    assert np.abs(plain.deviation / rows[:, 2] - 1).max() > 1e-3
    a = np.select([res.alpha == -1, res.alpha == -2], [1 / (3 * np.log(2)), 0.75], 0.0)
    np.testing.assert_allclose(res.variance, plain.variance / (1 - a * rows[:, 0] / 10_000), rtol=1e-14)  # N given
    np.testing.assert_allclose(res.edf, plain.edf, rtol=0)
    with pytest.raises(TypeError, match="bias_correction must be True or False"):
        avar.totdev(y, bias_correction="yes")


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_a_fixed_alpha_sets_every_levels_edf_and_bounds(estimator):
    """alpha= as Stable32's fixed noise type: the same deviations, the EDF of that noise at every
    level (NIST SP 1065's tables / Greenhall's algorithm), its chi-squared bounds."""
    from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES, chi2_bounds
    from avar.stability.uncertainty.edf import estimator_edf

    y = np.random.default_rng(5).standard_normal(2000)
    free = getattr(avar, estimator)(y, taus="decade", bias_correction=False) if estimator == "totdev" \
        else getattr(avar, estimator)(y, taus="decade")
    for alpha in (2, 0, -1) if estimator in ("hdev", "ohdev") else (2, 1, 0):
        kwargs = {"bias_correction": False} if estimator == "totdev" else {}
        fixed = getattr(avar, estimator)(y, taus="decade", alpha=alpha, **kwargs)
        assert fixed.alpha.tolist() == [alpha] * free.taus.size
        np.testing.assert_array_equal(fixed.deviation, free.deviation)
        given = y.size if estimator == "totdev" else y.size + 1  # TOTDEV's N: the points given, as Stable32
        edf = estimator_edf(estimator, fixed.alpha, fixed.averaging_factors, given)
        np.testing.assert_allclose(fixed.edf, edf, rtol=1e-14)
        lci, uci = chi2_bounds(fixed.deviation, edf, fixed.confidence, quantiles=CATALOGUE_QUANTILES)
        np.testing.assert_allclose(fixed.lci, lci, rtol=1e-14)
        np.testing.assert_allclose(fixed.uci, uci, rtol=1e-14)


def test_totdev_with_a_fixed_flicker_fm_removes_the_bias_at_every_level():
    y = np.random.default_rng(6).standard_normal(1000)
    raw = avar.totdev(y, alpha=-1, bias_correction=False)
    unbiased = avar.totdev(y, alpha=-1)
    m = raw.averaging_factors
    np.testing.assert_allclose(unbiased.variance, raw.variance / (1 - m / (3 * np.log(2)) / 1000), rtol=1e-14)
    np.testing.assert_array_equal(avar.totdev(y, alpha=0).deviation, raw.deviation)  # white FM: no bias
