"""The first run: the compile notice (once on a cold cache, never on a warm one) and where
numba's cache goes when the package folder is not writable."""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import njit

import avar
from avar._kernels.runtime.cache import choose_cache_dir, configure, user_cache_dir, writable
from avar.cli.first_run import compile_notice, notice_text

SRC = Path(avar.__file__).resolve().parent.parent
NOTICE = "compiling the numerical kernels"


def _environment(**extra: str) -> dict[str, str]:
    environment = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    environment["PYTHONPATH"] = os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])
    return {**environment, **extra}


def test_notice_once_per_run_and_only_when_numba_compiles():
    stream = io.StringIO()
    with compile_notice("compute", stream) as notice:
        square = njit(lambda x: x * x)  # new: compiled at its first call with each type
        assert square(3.0) == 9.0 and square(3) == 9
    assert notice.compiled == 2 and stream.getvalue() == notice_text("compute") + "\n"
    stream = io.StringIO()
    with compile_notice("compute", stream) as notice:
        assert square(4.0) == 16.0  # already compiled in this process: nothing to say
    assert notice.compiled == 0 and stream.getvalue() == ""
    with compile_notice("compute", stream):
        pass
    square(5.5)  # the listener is gone after the block
    assert stream.getvalue() == ""


def test_cold_cache_says_it_once_and_warm_cache_never(tmp_path):
    """``avar compute`` in fresh processes sharing a new, empty NUMBA_CACHE_DIR."""
    log = tmp_path / "log.csv"
    x = np.random.default_rng(4).standard_normal(200)
    log.write_text("time,x\n" + "".join(f"{i / 10},{v!r}\n" for i, v in enumerate(x.tolist())))
    cache = tmp_path / "numba-cache"
    # the compiled kernels (a short log's first call otherwise takes their NumPy twins: nothing to compile)
    environment = _environment(NUMBA_CACHE_DIR=str(cache), AVAR_KERNEL_PATH="compiled")
    command = [sys.executable, "-m", "avar", "compute", str(log), "--output", "-"]
    probe = [sys.executable, "-c", "from avar._kernels.runtime.cache import cached_for_this_machine as c; "
             "from avar._kernels.allan.small import small_allan_variance as k; print(c(k))"]
    assert subprocess.run(probe, env=environment, capture_output=True, text=True).stdout.strip() == "False"
    cold = subprocess.run(command, env=environment, capture_output=True, text=True, timeout=600)
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count(NOTICE) == 1
    line = next(line for line in cold.stderr.splitlines() if NOTICE in line)
    assert line.startswith("avar: ") and str(cache) in line and " s)" in line
    assert any(cache.rglob("*.nbi")) and any(cache.rglob("*.nbc"))  # numba wrote its cache there
    assert subprocess.run(probe, env=environment, capture_output=True, text=True).stdout.strip() == "True"
    warm = subprocess.run(command, env=environment, capture_output=True, text=True, timeout=600)
    assert warm.returncode == 0, warm.stderr
    assert NOTICE not in warm.stderr
    assert warm.stdout == cold.stdout  # the same table from the cached code
    expected = avar.avar(x, freq=10.0).summary()
    assert f"{expected['AVar'].iloc[0]:.6g}" in cold.stdout


def test_user_cache_dir_follows_xdg(tmp_path, monkeypatch):
    assert user_cache_dir({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "avar" / "numba"
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert user_cache_dir({}) == tmp_path / "home" / ".cache" / "avar" / "numba"


def test_a_folder_whose_cache_cannot_be_created_is_not_writable(tmp_path):
    assert writable(tmp_path) and (tmp_path / "__pycache__").is_dir()
    blocked = tmp_path / "blocked"
    blocked.mkdir()
    (blocked / "__pycache__").write_text("a file where numba needs a folder")  # fails even for root
    assert not writable(blocked)
    environ = {"XDG_CACHE_HOME": str(tmp_path / "xdg")}
    assert choose_cache_dir(blocked, environ) == tmp_path / "xdg" / "avar" / "numba"
    assert choose_cache_dir(tmp_path, environ) is None  # writable: numba's default, next to the code
    assert choose_cache_dir(blocked, {**environ, "NUMBA_CACHE_DIR": "/theirs"}) is None  # the user's choice wins
    assert configure(blocked, environ) == tmp_path / "xdg" / "avar" / "numba"
    assert environ["NUMBA_CACHE_DIR"] == str(tmp_path / "xdg" / "avar" / "numba")


def test_a_kernel_subpackage_whose_cache_cannot_be_created_makes_the_package_unwritable(tmp_path):
    """The kernels live in a folder per family: numba writes beside each of them."""
    (tmp_path / "allan").mkdir()
    (tmp_path / "allan" / "__init__.py").write_text("")
    assert writable(tmp_path)
    (tmp_path / "allan" / "__pycache__").rmdir()
    (tmp_path / "allan" / "__pycache__").write_text("not a folder")
    assert not writable(tmp_path)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_not_writable(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        assert not writable(folder)
    finally:
        folder.chmod(0o755)


def test_an_unwritable_package_caches_its_kernels_in_the_user_cache(tmp_path):
    """A copy of the package whose kernel folder cannot hold numba's cache, imported fresh."""
    copy = tmp_path / "site"
    shutil.copytree(SRC / "avar", copy / "avar", ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "avar" / "_kernels" / "__pycache__").write_text("not a folder")
    environment = _environment(PYTHONPATH=str(copy), XDG_CACHE_HOME=str(tmp_path / "xdg"))
    code = ("import os, avar._kernels; from avar._kernels.allan.small import small_allan_variance as k; "
            "print(avar._kernels.__file__); print(os.environ.get('NUMBA_CACHE_DIR')); print(k._cache._cache_path)")
    lines = subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True,
                           check=True).stdout.splitlines()
    assert lines[0].startswith(str(copy))
    assert lines[1] == str(tmp_path / "xdg" / "avar" / "numba")
    assert lines[2].startswith(lines[1])
    mine = str(tmp_path / "mine")
    lines = subprocess.run([sys.executable, "-c", code], env={**environment, "NUMBA_CACHE_DIR": mine},
                           capture_output=True, text=True, check=True).stdout.splitlines()
    assert lines[1] == mine and lines[2].startswith(mine)
    (copy / "avar" / "_kernels" / "__pycache__").unlink()  # writable again: numba's default, beside the code
    lines = subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True,
                           check=True).stdout.splitlines()
    assert lines[1] == "None" and lines[2].startswith(str(copy / "avar" / "_kernels"))


def test_the_warm_up_thread_is_quiet():
    """compute's warm-up may compile the short-series kernel while the file is read: speculative."""
    import threading

    from avar.cli.compute import WARM_UP_THREAD
    from avar.cli.first_run import QUIET_THREADS

    assert WARM_UP_THREAD in QUIET_THREADS
    stream = io.StringIO()
    cube = njit(lambda x: x * x * x)
    with compile_notice("compute", stream) as notice:
        worker = threading.Thread(target=cube, args=(2.0,), name=WARM_UP_THREAD)
        worker.start()
        worker.join()
        assert notice.compiled == 0 and stream.getvalue() == ""
        assert cube(2) == 8  # a new signature, in the run's own thread
    assert notice.compiled == 1 and stream.getvalue().count(NOTICE) == 1


def test_deviation_says_it_compiles_too():
    """``avar deviation`` runs kernels: it is among the subcommands that print the notice."""
    from avar.cli.first_run import COMPILE_SECONDS

    assert {"demo", "compute", "fit", "report", "deviation", "warmup"} <= set(COMPILE_SECONDS)


def test_after_warmup_no_command_compiles(tmp_path):
    """``avar warmup --quick`` fills a new, empty cache; then ``avar deviation`` of phase and
    frequency data (every statistic), ``avar compute`` and ``avar report`` of a short log, in
    fresh processes sharing that cache, compile nothing."""
    environment = _environment(NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    warm = subprocess.run([sys.executable, "-m", "avar", "warmup", "--quick"], env=environment,
                          capture_output=True, text=True, timeout=900)
    assert warm.returncode == 0, warm.stderr
    families = [line for line in warm.stderr.splitlines() if line.startswith("avar warmup: ")]
    assert len(families) == 4 and all(line.endswith(" s") for line in families)
    assert "every kernel compiled and cached in" in warm.stdout
    y = np.random.default_rng(5).standard_normal(3000)
    clock = tmp_path / "clock.csv"
    clock.write_text("y\n" + "".join(f"{v!r}\n" for v in y.tolist()))
    log = tmp_path / "imu.csv"
    rows = np.random.default_rng(6).standard_normal((5000, 6)) * 1e-3
    log.write_text("time,gx,gy,gz,ax,ay,az\n" + "".join(
        f"{i / 100}," + ",".join(repr(v) for v in row) + "\n" for i, row in enumerate(rows.tolist())))
    from avar.stability.shared.registry import DEVIATION_STATISTICS

    stats = sum((["--stat", name] for name in DEVIATION_STATISTICS), [])
    for arguments in (["deviation", str(clock), "--data-type", "freq", *stats],
                      ["deviation", str(clock), "--data-type", "phase", *stats],
                      ["compute", str(log), "--output", "-"],
                      ["report", str(log)]):
        run = subprocess.run([sys.executable, "-m", "avar", *arguments], env=environment, capture_output=True,
                             text=True, timeout=600)
        assert run.returncode == 0, run.stderr
        assert NOTICE not in run.stderr, (arguments[0], run.stderr)
