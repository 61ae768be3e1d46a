"""Which path a call takes: the NumPy twins while the kernels are cold, the kernels once compiled."""

from __future__ import annotations

import pytest
from numba import njit

from avar._kernels.runtime import paths


def test_the_environment_forces_a_path_and_the_switch_wins(monkeypatch):
    cold = njit(lambda x: x)
    monkeypatch.setattr(paths, "ENVIRONMENT_MODE", None)  # AVAR_KERNEL_PATH unset when the kernels loaded
    assert paths.path_mode() == "auto" and paths.numpy_path(10, 100, (cold,))
    monkeypatch.setattr(paths, "ENVIRONMENT_MODE", "compiled")
    assert not paths.numpy_path(10, 100, (cold,))
    with paths.forced("numpy"):
        assert paths.numpy_path(10**9, 100, (cold,))  # any size
    monkeypatch.setattr(paths, "ENVIRONMENT_MODE", "numba")
    with pytest.raises(ValueError, match="AVAR_KERNEL_PATH must be one of auto, numpy, compiled"):
        paths.path_mode()
    with pytest.raises(ValueError, match="mode must be one of"):
        with paths.forced("fast"):
            pass


def test_compiled_kernels_and_large_records_take_the_kernels(monkeypatch):
    monkeypatch.setattr(paths, "ENVIRONMENT_MODE", None)
    kernel = njit(lambda x: x + 1.0)
    assert paths.numpy_path(10, 100, (kernel,)) and not paths.numpy_path(101, 100, (kernel,))
    assert not paths.numpy_path(10, 100, (kernel,), fits=False)
    kernel(1.0)
    assert paths.compiled((kernel,)) and not paths.numpy_path(10, 100, (kernel,))
    assert not paths.compiled(((kernel, 1),))  # compiled for float64, not for an integer argument


def test_a_hot_dispatch_compiles_after_all(monkeypatch):
    monkeypatch.setattr(paths, "ENVIRONMENT_MODE", None)
    monkeypatch.setattr(paths, "HOT_WORK", 1000)
    monkeypatch.setattr(paths, "CALL_WORK", 0)
    kernel = njit(lambda x: x)
    taken = [paths.numpy_path(300, 10_000, (kernel,)) for _ in range(5)]
    assert taken == [True, True, True, False, False]  # 900 units spent in the twin, then the kernels


def test_many_small_calls_turn_hot_too(monkeypatch):
    # each call is charged its twin's fixed cost: 100 units of work + 150 per call
    monkeypatch.setattr(paths, "ENVIRONMENT_MODE", None)
    monkeypatch.setattr(paths, "HOT_WORK", 1000)
    monkeypatch.setattr(paths, "CALL_WORK", 150)
    kernel = njit(lambda x: x)
    taken = [paths.numpy_path(100, 10_000, (kernel,)) for _ in range(6)]
    assert taken == [True, True, True, True, False, False]  # 4 x 250 = 1000 spent
