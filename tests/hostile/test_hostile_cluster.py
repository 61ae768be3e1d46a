"""Hostile runs on a local Dask cluster: more workers than files, Ctrl-C while the workers compute."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

import avar
from tests._support.cli_runner import cli

pytest.importorskip("dask.distributed")


def test_workers_are_capped_by_files_and_cores(tmp_path, capsys):
    rng = np.random.default_rng(11)
    files = []
    for i in range(2):
        path = tmp_path / f"f{i}.csv"
        pd.DataFrame({"x": rng.standard_normal(1024)}).to_csv(path, index=False)
        files.append(path)
    code, _, err = cli(capsys, "compute", *files, "--workers", "8", "--output", tmp_path / "o.csv")
    assert code == 0, err
    started = min(2, os.cpu_count() or 1)
    assert f"--workers 8: 2 file(s) on {os.cpu_count()} core(s); starting {started} worker process(es)" in err
    table = pd.read_csv(tmp_path / "o.csv")
    for i, path in enumerate(files):
        want = avar.avar(pd.read_csv(path)["x"].to_numpy()).allan
        np.testing.assert_allclose(table[table["File"] == f"f{i}"]["AVar"], want, rtol=1e-12)


def test_ctrl_c_with_workers_is_one_line(tmp_path):
    paths = []
    for i in range(2):
        path = tmp_path / f"long{i}.npy"
        np.save(path, np.random.default_rng(i).standard_normal(2_000_000))
        paths.append(str(path))
    process = subprocess.Popen(
        [sys.executable, "-m", "avar", "compute", *paths, "--workers", "2", "--taus", "all",
         "--output", str(tmp_path / "o.csv")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and len(_children(process.pid)) < 3:  # the workers have started
            time.sleep(0.5)
        time.sleep(2.0)
        process.send_signal(signal.SIGINT)
        code = process.wait(timeout=60)
        time.sleep(2.0)  # what the cluster's helper processes print on their way out
        err = process.stderr.read()
    finally:
        process.kill()
    assert code == 130
    assert err.strip().splitlines() == ["avar: interrupted"], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long0.npy", "long1.npy"]


def _children(pid: int) -> list[int]:
    try:
        out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout
    except FileNotFoundError:
        return [0, 0, 0]
    return [int(p) for p in out.split()]
