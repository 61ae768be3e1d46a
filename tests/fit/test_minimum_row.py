"""The Allan-deviation minimum of the noise report is read on well-sampled levels only."""

import numpy as np
import pytest

import avar
from avar.fit.report.rows import MIN_CLUSTERS, minimum_row


def test_the_minimum_is_taken_where_at_least_eight_clusters_average():
    tau = 2.0 ** np.arange(10)  # 1 .. 512 s of a 1000 s record
    adev = 1.0 / np.sqrt(tau)   # white noise: falls to the last level
    row = minimum_row("x", None, None, tau, adev, adev * 0.9, adev * 1.1, duration=1000.0)
    assert row["Tau (s)"] == 64.0 == tau[tau <= 1000.0 / MIN_CLUSTERS].max()
    assert row["Value"] == pytest.approx(1 / 8.0, rel=1e-15)
    assert "global minimum 0.04419 u at tau = 512 s" in row["Note"]
    same = minimum_row("x", None, None, tau, adev[::-1], adev, adev, duration=1000.0)
    assert same["Tau (s)"] == 1.0 and "global minimum" not in same["Note"]
    everywhere = minimum_row("x", None, None, tau, adev, adev, adev)  # no duration: every level
    assert everywhere["Tau (s)"] == 512.0


def test_the_report_of_white_noise_reads_the_minimum_at_an_eighth_of_the_record():
    rate = 100.0
    y = np.random.default_rng(5).standard_normal(60_000) * 1e-3
    report = avar.noise_report(avar.IMU(np.column_stack([y]), rate, gyro=[0]))
    row = report.table.set_index("Process").loc["MIN"]
    assert row["Tau (s)"] <= 60_000 / rate / MIN_CLUSTERS
    assert "global minimum" in row["Note"]
