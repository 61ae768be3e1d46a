"""Tests of avar.plotting and avar.plotting.imu.

Every figure is rendered to PNG headless (Agg) and checked on its artists:
scales, line data against the result, band vertices against lci/uci (squared
for the Allan variance), titles, labels, legends and grid shapes.
"""

import io

import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.ticker import LogFormatterSciNotation

import avar
from avar.fit.avlr import avlr
from avar.imu import IMU
from avar.io import datasets
from avar.models import RW, WN
from avar.plotting import plot_avar, plot_avlr, plot_compare, plot_imu_avar, plot_imu_avlr
from avar.stability.allan.results import ImuAllanVariance

N = 4096  # octave grid m = 2 .. 2048 = N / 2: the last level has lci < 0


# --------------------------------------------------------------------------- helpers
def render(fig):
    """Draw the figure to PNG in memory and return the bytes."""
    assert isinstance(fig, Figure)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=40)
    content = buffer.getvalue()
    assert content[:8] == b"\x89PNG\r\n\x1a\n"
    return content


def line(ax, label):
    matches = [ln for ln in ax.lines if ln.get_label() == label]
    assert len(matches) == 1, [ln.get_label() for ln in ax.lines]
    return matches[0]


def bands(ax):
    return [c for c in ax.collections if isinstance(c, PolyCollection)]


def band_points(ax):
    """All (x, y) vertices of the single fill_between band of ``ax``."""
    (collection,) = bands(ax)
    vertices = np.concatenate([path.vertices for path in collection.get_paths()])
    return {(float(x), float(y)) for x, y in vertices}


def expected_band(levels, lower, upper, valid):
    return {(float(t), float(v)) for t, lo, hi in zip(levels[valid], lower[valid], upper[valid]) for v in (lo, hi)}


@pytest.fixture(scope="module")
def res():
    return avar.avar(np.random.default_rng(11).standard_normal(N), freq=100.0)


@pytest.fixture(scope="module")
def fit():
    x = (WN(sigma2=1.0) + RW(gamma2=1e-5)).simulate(2**15, seed=5)
    return avlr(x, wn=range(1, 7), rw=range(10, 14))


@pytest.fixture(scope="module")
def navchip():
    return datasets.load("navchip_av")


# --------------------------------------------------------------------------- plot_avar
def test_plot_avar_variance_line_band_and_labels(res):
    fig = plot_avar(res)
    render(fig)
    (ax,) = fig.axes
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert ax.get_title() == "Allan Variance Representation"
    assert ax.get_xlabel() == r"Averaging time $\tau$"
    assert ax.get_ylabel() == r"Allan Variance $\sigma^2(\tau)$"
    empirical = line(ax, "Empirical AV")
    np.testing.assert_array_equal(empirical.get_xdata(), res.levels)
    np.testing.assert_array_equal(empirical.get_ydata(), res.allan)
    valid = res.lci > 0
    assert valid[:-1].all() and not valid[-1]
    assert band_points(ax) == expected_band(res.levels, res.lci**2, res.uci**2, valid)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["Empirical AV", "CI(AV, 0.95)"]
    assert ax.get_legend()._loc == 3  # lower left


def test_plot_avar_deviation_uses_adev_and_ad_band(res):
    fig = plot_avar(res, deviation=True, units="s")
    render(fig)
    ax = fig.axes[0]
    empirical = line(ax, "Empirical AD")
    np.testing.assert_array_equal(empirical.get_ydata(), res.adev)
    valid = res.lci > 0
    assert band_points(ax) == expected_band(res.levels, res.lci, res.uci, valid)
    assert ax.get_xlabel() == r"Averaging time $\tau$ (s)"
    assert ax.get_ylabel() == r"Allan Deviation $\sigma(\tau)$"
    assert ax.get_legend().get_texts()[1].get_text() == "CI(AD, 0.95)"


def test_non_positive_lower_bound_is_on_the_line_but_not_in_the_band():
    x = np.random.default_rng(2).standard_normal(64)
    res = avar.avar(x, taus="all")  # m = 1 .. 32; lci <= 0 from m = N / 3 on
    invalid = res.lci <= 0
    assert invalid.sum() > 5 and invalid[-1]
    assert res.errors[-1] == pytest.approx(1 / np.sqrt(2))
    for deviation in (False, True):
        fig = plot_avar(res, deviation=deviation)
        render(fig)
        ax = fig.axes[0]
        values = res.adev if deviation else res.allan
        np.testing.assert_array_equal(ax.lines[0].get_xdata(), res.levels)
        np.testing.assert_array_equal(ax.lines[0].get_ydata(), values)
        band_x = {x for x, _ in band_points(ax)}
        assert band_x == set(res.levels[~invalid].tolist())
        assert not band_x & set(res.levels[invalid].tolist())
        assert ax.get_ylim()[0] > 0
    # the trap: lci**2 is positive where lci < 0, but those levels get no band either
    assert (res.lci[invalid] ** 2 > 0).any()


def test_band_absent_when_every_lower_bound_is_non_positive():
    res = avar.avar(np.arange(8.0) ** 2, taus=[3, 4])
    assert (res.lci <= 0).all()
    fig = plot_avar(res)
    render(fig)
    assert bands(fig.axes[0]) == []
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), res.allan)


def test_plot_avar_without_ci_and_custom_text(res):
    fig = plot_avar(res, ci=False, xlab="tau", ylab="AV", main="Gyro run 3", legend_position=None,
                    col_ad="darkred", marker="s", markersize=3)
    render(fig)
    ax = fig.axes[0]
    assert bands(ax) == [] and ax.get_legend() is None
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_title()) == ("tau", "AV", "Gyro run 3")
    assert ax.lines[0].get_color() == "darkred" and ax.lines[0].get_marker() == "s"
    assert plot_avar(res, main="").axes[0].get_title() == ""


def test_decade_ticks_are_labelled_as_powers_of_ten(res):
    fig = plot_avar(res)
    render(fig)
    ax = fig.axes[0]
    for axis in (ax.xaxis, ax.yaxis):
        assert isinstance(axis.get_major_formatter(), LogFormatterSciNotation)
        low, high = axis.get_view_interval()
        ticks = [t for t in axis.get_majorticklocs() if low <= t <= high]
        assert ticks and np.allclose(np.log10(ticks), np.round(np.log10(ticks)))
    labels = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
    assert labels and all("10^{" in text for text in labels)


def test_plot_avar_draws_on_a_given_axes_and_is_the_method(res):
    fig = Figure()
    left, right = fig.subplots(1, 2)
    assert plot_avar(res, ax=right) is fig
    assert len(left.lines) == 0 and len(right.lines) == 1
    method = res.plot(deviation=True)
    np.testing.assert_array_equal(method.axes[0].lines[0].get_ydata(), res.adev)
    sub = Figure().subfigures(1, 2)[1]
    assert isinstance(plot_avar(res, ax=sub.add_subplot()), Figure)


@pytest.mark.parametrize(
    ("position", "loc"),
    [("topright", 1), ("upper right", 1), ("top_left", 2), ("bottomright", 4), ("best", 0), ("Lower Left", 3)],
)
def test_legend_positions_r_and_matplotlib_names(res, position, loc):
    assert plot_avar(res, legend_position=position).axes[0].get_legend()._loc == loc


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"legend_position": "middle"}, ValueError, "legend_position"),
        ({"legend_position": 3}, ValueError, "legend_position"),
        ({"col_ad": "notacolour"}, ValueError, "col_ad"),
        ({"col_ci": 12}, ValueError, "col_ci"),
        ({"deviation": "yes"}, TypeError, "deviation"),
        ({"ci": 1}, TypeError, "ci"),
        ({"markersize": -1}, ValueError, "markersize"),
        ({"main": 5}, TypeError, "main"),
        ({"ax": "axes"}, TypeError, "ax"),
    ],
)
def test_plot_avar_rejects_bad_arguments(res, kwargs, error, message):
    with pytest.raises(error, match=message):
        plot_avar(res, **kwargs)


def test_plot_avar_rejects_other_objects(res):
    with pytest.raises(TypeError, match="AllanVariance"):
        plot_avar(res.allan)


# --------------------------------------------------------------------------- plot_avlr
def test_plot_avlr_implied_curve(fit):
    fig = fit.plot()
    render(fig)
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    np.testing.assert_array_equal(line(ax, "Empirical AV").get_ydata(), fit.av.allan)
    implied = line(ax, "Implied AV")
    np.testing.assert_array_equal(implied.get_xdata(), fit.av.levels)
    # the variances of the processes add (DESIGN defect 6); R's curve on request
    np.testing.assert_allclose(implied.get_ydata(), sum(d**2 for d in fit.implied_ad_decomp.values()), rtol=1e-14)
    np.testing.assert_allclose(implied.get_ydata(), fit.implied_av, rtol=1e-15)
    r_curve = line(plot_avlr(fit, implied="r").axes[0], "Implied AV").get_ydata()
    np.testing.assert_allclose(r_curve, fit.implied_ad**2, rtol=1e-15)
    assert np.all(r_curve > implied.get_ydata())  # (a + b)^2 > a^2 + b^2
    valid = fit.av.lci > 0
    assert band_points(ax) == expected_band(fit.av.levels, fit.av.lci**2, fit.av.uci**2, valid)
    assert [ln.get_label() for ln in ax.lines] == ["Empirical AV", "Implied AV"]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["Empirical AV", "CI(AV, 0.95)", "Implied AV"]
    low, high = ax.get_ylim()
    assert low <= min(fit.av.allan.min(), fit.implied_av.min()) and high >= (fit.av.uci**2).max()


def test_plot_avlr_decomposition_lines(fit):
    fig = plot_avlr(fit, decomp=True)
    render(fig)
    ax = fig.axes[0]
    processes = list(fit.estimates.index)
    decomposition = [ln for ln in ax.lines if ln.get_label() in processes]
    assert len(decomposition) == len(fit.estimates) == 2
    for ln, process in zip(decomposition, processes):
        assert ln.get_label() == process
        np.testing.assert_allclose(ln.get_ydata(), fit.implied_ad_decomp[process] ** 2, rtol=1e-15)
    colours = {ln.get_color() for ln in decomposition} | {line(ax, "Implied AV").get_color()}
    assert len(colours) == 3
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == ["Empirical AV", "CI(AV, 0.95)", "Implied AV", "WN", "RW"]


def test_plot_avlr_show_scales_deviation(fit):
    fig = plot_avlr(fit, show_scales=True, deviation=True, units="s")
    render(fig)
    ax = fig.axes[0]
    np.testing.assert_allclose(line(ax, "Implied AD").get_ydata(), np.sqrt(fit.implied_av), rtol=1e-15)
    np.testing.assert_array_equal(line(ax, "Empirical AD").get_ydata(), fit.av.adev)
    assert band_points(ax) == expected_band(fit.av.levels, fit.av.lci, fit.av.uci, fit.av.lci > 0)
    for process, scales in fit.scales_used.items():
        marks = line(ax, f"Scales used for {process}")
        assert marks.get_linestyle() == "None"
        np.testing.assert_array_equal(marks.get_xdata(), fit.av.levels[scales - 1])
        np.testing.assert_array_equal(marks.get_ydata(), fit.av.adev[scales - 1])
    assert not any(ln.get_label() in fit.estimates.index for ln in ax.lines)
    assert ax.get_xlabel() == r"Averaging time $\tau$ (s)"


def test_plot_avlr_validation(fit, res):
    with pytest.raises(TypeError, match="AvlrResult"):
        plot_avlr(res)
    with pytest.raises(TypeError, match="decomp"):
        plot_avlr(fit, decomp="yes")
    with pytest.raises(ValueError, match="col_implied"):
        plot_avlr(fit, col_implied="nope")
    with pytest.raises(ValueError, match="legend_position"):
        plot_avlr(fit, legend_position="somewhere")


# --------------------------------------------------------------------------- plot_compare
def test_plot_compare_overlays_curves(res, fit):
    other = avar.avar(3 * np.random.default_rng(4).standard_normal(2 * N), freq=50.0)
    fig = avar.plotting.plot_compare([res, other, fit], labels=["a", "b", "fit"], deviation=True)
    render(fig)
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert [ln.get_label() for ln in ax.lines] == ["a", "b", "fit"]
    for ln, r in zip(ax.lines, (res, other, fit.av)):
        np.testing.assert_array_equal(ln.get_xdata(), r.levels)
        np.testing.assert_array_equal(ln.get_ydata(), r.adev)
    assert len({ln.get_color() for ln in ax.lines}) == 3
    assert bands(ax) == []
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["a", "b", "fit"]
    assert ax.get_title() == "Allan Variance Comparison"


def test_plot_compare_bands_default_labels_and_mappings(res, navchip):
    fig = plot_compare([res, res], ci=True, colours=["red", "blue"])
    render(fig)
    ax = fig.axes[0]
    assert [ln.get_label() for ln in ax.lines] == ["Series 1", "Series 2"]
    assert len(bands(ax)) == 2
    valid = res.lci > 0
    vertices = {(float(x), float(y)) for p in bands(ax)[0].get_paths() for x, y in p.vertices}
    assert vertices == expected_band(res.levels, res.lci**2, res.uci**2, valid)
    gyros = navchip.channels_of("Gyroscope")
    fig = plot_compare(gyros)
    assert [ln.get_label() for ln in fig.axes[0].lines] == list(gyros)
    np.testing.assert_array_equal(fig.axes[0].lines[2].get_ydata(), gyros["Gyro. Z"].allan)
    assert [ln.get_label() for ln in plot_compare(list(navchip.channels.values())[:2]).axes[0].lines] == [
        "Gyro. X", "Gyro. Y"]


@pytest.mark.parametrize(
    ("args", "kwargs", "error", "message"),
    [
        (([],), {}, ValueError, "at least one"),
        (({},), {}, ValueError, "at least one"),
        (("res",), {}, TypeError, "list"),
        ((None,), {}, TypeError, "list"),
        (("RES2",), {"labels": ["only one"]}, ValueError, "one label per result"),
        (("RES2",), {"labels": "ab"}, TypeError, "labels"),
        (("MAP",), {"labels": ["x"]}, ValueError, "not both"),
        (("RES2",), {"colours": ["red"]}, ValueError, "colours"),
        (("RES2",), {"colours": ["red", "nocolour"]}, ValueError, r"colours\[1\]"),
        (("BAD",), {}, TypeError, r"results\[1\]"),
        (("RES2",), {"legend_position": "nowhere"}, ValueError, "legend_position"),
    ],
)
def test_plot_compare_validation(res, navchip, args, kwargs, error, message):
    substitute = {"res": res, "RES2": [res, res], "MAP": {"x": res}, "BAD": [res, res.allan]}
    args = tuple(substitute.get(a, a) if isinstance(a, str) else a for a in args)
    with pytest.raises(error, match=message):
        plot_compare(*args, **kwargs)
    with pytest.raises(TypeError, match=r"\.channels"):
        plot_compare(navchip)


# --------------------------------------------------------------------------- IMU grids
def test_plot_imu_avar_navchip_grid(navchip):
    fig = navchip.plot()
    render(fig)
    assert len(fig.axes) == 6
    assert {ax.get_subplotspec().get_geometry()[:2] for ax in fig.axes} == {(2, 3)}
    assert fig._suptitle.get_text() == "Allan Variance Representation - NAVCHIP_FLT @ 250 Hz"
    assert [ax.get_title() for ax in fig.axes] == ["Axis - X", "Axis - Y", "Axis - Z", "", "", ""]
    assert fig.axes[0].get_ylabel().startswith("Gyroscope")
    assert fig.axes[3].get_ylabel().startswith("Accelerometer")
    assert fig._supxlabel.get_text() == r"Averaging time $\tau$ (s)"
    for ax, av in zip(fig.axes, navchip.channels.values()):
        assert ax.get_xscale() == ax.get_yscale() == "log"
        np.testing.assert_array_equal(line(ax, "Empirical AV").get_xdata(), av.levels)
        np.testing.assert_array_equal(line(ax, "Empirical AV").get_ydata(), av.allan)
        valid = av.lci > 0
        assert not valid[-1]  # navchip's largest level: drawn, but without band
        assert band_points(ax) == expected_band(av.levels, av.lci**2, av.uci**2, valid)
    gyro_limits = {ax.get_ylim() for ax in fig.axes[:3]}
    accel_limits = {ax.get_ylim() for ax in fig.axes[3:]}
    assert len(gyro_limits) == 1 and len(accel_limits) == 1 and gyro_limits != accel_limits
    (low, high), = gyro_limits
    gyro = list(navchip.channels.values())[:3]
    assert low <= min(av.allan.min() for av in gyro) and high >= max((av.uci[av.lci > 0] ** 2).max() for av in gyro)


def test_plot_imu_avar_deviation_units_and_partial_grid():
    data = np.random.default_rng(8).standard_normal((2048, 4))
    imu = IMU(data, freq=20, gyro=[0, 1, 2], accel=[3], name="demo", units={"gyro": "rad/s", "accel": "m/s^2"})
    res = avar.avar(imu)
    fig = plot_imu_avar(res, deviation=True, main="", legend_position=None)
    render(fig)
    assert len(fig.axes) == 6 and fig._suptitle is None
    assert [ax.axison for ax in fig.axes] == [True, True, True, True, False, False]
    assert fig.axes[0].get_ylabel() == "Gyroscope\n" + r"$\sigma(\tau)$ [rad/s]"
    assert fig.axes[3].get_ylabel() == "Accelerometer\n" + r"$\sigma(\tau)$ [m/s^2]"
    np.testing.assert_array_equal(fig.axes[3].lines[0].get_ydata(), res["Accel. X"].adev)
    assert all(ax.get_legend() is None for ax in fig.axes)
    assert plot_imu_avar(res).axes[0].get_ylabel() == "Gyroscope\n" + r"$\sigma^2(\tau)$ [(rad/s)$^2$]"


def test_plot_imu_avar_given_figure_and_validation(navchip, res):
    fig = Figure()
    assert plot_imu_avar(navchip, fig=fig, ci=False) is fig
    assert all(bands(ax) == [] for ax in fig.axes)
    with pytest.raises(ValueError, match="already has axes"):
        plot_imu_avar(navchip, fig=fig)
    with pytest.raises(TypeError, match="ImuAllanVariance"):
        plot_imu_avar(res)
    with pytest.raises(TypeError, match="fig"):
        plot_imu_avar(navchip, fig="figure")
    with pytest.raises(ValueError, match="legend_position"):
        plot_imu_avar(navchip, legend_position="outside")
    twice_x = ImuAllanVariance("twin", 100.0, res.n, {"a": res, "b": res}, ["Gyroscope"] * 2, ["X", "X"])
    with pytest.raises(ValueError, match="one channel per sensor type and axis"):
        plot_imu_avar(twice_x)


@pytest.fixture(scope="module")
def navchip_fit(navchip):
    return avlr(navchip, wn_gyro=range(6, 9), rw_gyro=range(10, 14), wn_acc=range(1, 7), rw_acc=range(14, 17))


def test_plot_imu_avlr_overlays_the_implied_curves(navchip_fit):
    fig = navchip_fit.plot()
    render(fig)
    imu = navchip_fit.imu_av
    assert len(fig.axes) == 6
    assert {ax.get_subplotspec().get_geometry()[:2] for ax in fig.axes} == {(2, 3)}
    assert fig._suptitle.get_text() == "Allan Variance Representation - NAVCHIP_FLT @ 250 Hz"
    assert [ax.get_title() for ax in fig.axes[:3]] == ["Axis - X", "Axis - Y", "Axis - Z"]
    for ax, (name, av) in zip(fig.axes, imu.channels.items()):
        assert ax.get_xscale() == ax.get_yscale() == "log"
        np.testing.assert_array_equal(line(ax, "Empirical AV").get_ydata(), av.allan)
        implied = line(ax, "Implied AV")
        np.testing.assert_array_equal(implied.get_xdata(), av.levels)
        np.testing.assert_allclose(implied.get_ydata(), navchip_fit.implied_av[name], rtol=1e-15)
        assert band_points(ax) == expected_band(av.levels, av.lci**2, av.uci**2, av.lci > 0)
        low, high = ax.get_ylim()
        curve = navchip_fit.implied_av[name]
        assert low <= curve.min() and high >= curve.max()  # the shared row range covers the fit
    assert len({ax.get_ylim() for ax in fig.axes[:3]}) == 1
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == [
        "Empirical AV", "CI(AV, 0.95)", "Implied AV"]


def test_plot_imu_avlr_decomposition_scales_and_deviation(navchip_fit):
    fig = plot_imu_avlr(navchip_fit, decomp=True, show_scales=True, deviation=True)
    render(fig)
    imu = navchip_fit.imu_av
    for ax, (name, kind) in zip(fig.axes, zip(imu.channels, imu.sensor_types)):
        av = imu.channels[name]
        np.testing.assert_allclose(line(ax, "Implied AD").get_ydata(), np.sqrt(navchip_fit.implied_av[name]),
                                   rtol=1e-15)
        processes = list(navchip_fit.estimates[kind].index)
        decomposition = [ln for ln in ax.lines if ln.get_label() in processes]
        assert len(decomposition) == len(processes) == 2
        for ln in decomposition:
            np.testing.assert_array_equal(ln.get_ydata(), navchip_fit.implied_ad_decomp[name][ln.get_label()])
        for process, scales in navchip_fit.scales_used[kind].items():
            marks = line(ax, f"Scales used for {process}")
            np.testing.assert_array_equal(marks.get_xdata(), av.levels[scales - 1])
            np.testing.assert_array_equal(marks.get_ydata(), av.adev[scales - 1])
        assert band_points(ax) == expected_band(av.levels, av.lci, av.uci, av.lci > 0)


def test_plot_imu_avlr_per_axis_fit_and_validation(navchip, navchip_fit, fit):
    per_axis = avlr(navchip, wn_gyro=range(1, 8), wn_acc=range(1, 8), per_axis=True)
    fig = plot_imu_avlr(per_axis, legend_position="topright", implied="r")
    curves = [line(ax, "Implied AV").get_ydata() for ax in fig.axes]
    for curve, name in zip(curves, navchip.channels):
        np.testing.assert_array_equal(curve, per_axis.implied_ad[name] ** 2)  # R's curve on request
    assert not np.array_equal(curves[0], curves[1])  # one model per axis
    assert fig.axes[0].get_legend()._loc == 1
    with pytest.raises(TypeError, match="ImuAvlrResult"):
        plot_imu_avlr(navchip)
    with pytest.raises(TypeError, match="ImuAvlrResult"):
        plot_imu_avlr(fit)
    with pytest.raises(TypeError, match="show_scales"):
        plot_imu_avlr(navchip_fit, show_scales=None)
    with pytest.raises(ValueError, match="col_implied"):
        plot_imu_avlr(navchip_fit, col_implied="not a colour")


def test_plot_compare_is_exported_lazily(res):
    fig = avar.plot_compare({"run": res})
    assert [ln.get_label() for ln in fig.axes[0].lines] == ["run"]


# --------------------------------------------------------------------------- chi-squared band
def test_plot_draws_the_chi2_band_at_every_level():
    res = avar.avar(np.random.default_rng(11).standard_normal(N), freq=100.0, ci="chi2")
    r_band = avar.avar(np.random.default_rng(11).standard_normal(N), freq=100.0)
    assert (res.lci > 0).all() and r_band.lci[-1] < 0
    every = np.ones(len(res), dtype=bool)
    ax = res.plot(deviation=True).axes[0]
    assert band_points(ax) == expected_band(res.levels, res.lci, res.uci, every)
    assert band_points(ax) != expected_band(r_band.levels, r_band.lci, r_band.uci, r_band.lci > 0)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["Empirical AD", "chi2 CI(AD, 0.683)"]
    ax = res.plot().axes[0]
    assert band_points(ax) == expected_band(res.levels, res.lci**2, res.uci**2, every)
    low, high = ax.get_ylim()
    assert low <= (res.lci**2).min() and high >= (res.uci**2).max()
    render(ax.figure)


def test_plot_imu_draws_each_channels_chi2_band():
    data = np.random.default_rng(3).standard_normal((4096, 2))
    res = avar.avar(IMU(data, freq=10, gyro=[0], accel=[1], name="demo"), ci="chi2", confidence=0.95)
    fig = res.plot(deviation=True)
    for ax, av in zip(fig.axes, res.channels.values()):
        assert band_points(ax) == expected_band(av.levels, av.lci, av.uci, np.ones(len(av), dtype=bool))
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["Empirical AD", "chi2 CI(AD, 0.95)"]
