"""Accuracy of the noise report against the truth and against two peers, in one run.

Simulates ``REPETITIONS`` (default 50) gyroscopes of 2 hours at 200 Hz, each
the sum of white noise (angle random walk N), flicker (bias instability B) and
a random walk (rate random walk K) of known size, exactly (``avar.WN``,
``avar.FN``, ``avar.RW`` in per-sample form). On every series it estimates N,
B and K with

* ``avar.noise_report`` (no scales given);
* the PyPI package ``allan-variance`` (``compute_avar`` with its defaults,
  then the joint NNLS fit ``estimate_parameters`` of all five terms);
* the reading rules of ``allan_variance_ros``: N = the -1/2 line fitted on
  tau <= 10 s read at tau = 1 s, B = min AD / 0.664, K = the +1/2 line
  fitted on tau >= 1000 s read at tau = 3 s (K = AD(3 s)), on the same octave
  Allan deviation as the report;

and prints the median and 90th percentile of |estimate / truth - 1| per term.

Truth (rad/s units): N = 1.2e-4 rad/s/sqrt(Hz) (0.41 deg/sqrt(h)), B = 1e-4
rad/s (20.6 deg/h), K = 1.2e-5 rad/s^2/sqrt(Hz) (149 deg/h/sqrt(h)): white
noise meets the flicker plateau at tau = 3.3 s, flicker meets the random walk
at tau = 92 s, so each term has a region of at least a decade in the record.

Usage::

    PYTHONPATH=src python benchmarks/noise_report_accuracy.py [REPETITIONS [SEED]]
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
import pandas as pd

import avar
from avar.models.flicker import FLICKER_AV_FACTOR

FREQ = 200.0
N_SAMPLES = int(2 * 3600 * FREQ)
TRUTH = {"ARW": 1.2e-4, "BI": 1e-4, "RRW": 1.2e-5}


def peer_allan_variance(x: np.ndarray) -> dict[str, float]:
    import allan_variance

    tau, av = allan_variance.compute_avar(x, dt=1.0 / FREQ)
    params, _ = allan_variance.estimate_parameters(tau, av)
    return {"ARW": params["white"], "BI": params["flicker"], "RRW": params["walk"]}


def _fixed_slope_line(tau: np.ndarray, adev: np.ndarray, slope: float, at: float) -> float:
    intercept = np.mean(np.log(adev) - slope * np.log(tau))
    return float(np.exp(intercept + slope * np.log(at)))


def ros_rules(av) -> dict[str, float]:
    tau, adev = av.levels, av.adev
    white = tau <= 10.0
    walk = tau >= 1000.0
    return {
        "ARW": _fixed_slope_line(tau[white], adev[white], -0.5, 1.0),
        "BI": float(adev.min()) / math.sqrt(FLICKER_AV_FACTOR),
        "RRW": _fixed_slope_line(tau[walk], adev[walk], 0.5, 3.0),
    }


def report_terms(x: np.ndarray) -> tuple[dict[str, float], object]:
    report = avar.noise_report(x, gyro_units="rad/s", rate=FREQ)
    values = {name: report.value("x", process) for name, process in (("ARW", "WN"), ("BI", "FN"), ("RRW", "RW"))}
    # an absent term is an error of 100%
    return {k: (0.0 if v is None else v) for k, v in values.items()}, report.avs["x"]


def main(repetitions: int, seed: int) -> pd.DataFrame:
    model = (avar.WN.from_continuous(TRUTH["ARW"], FREQ) + avar.FN.from_continuous(TRUTH["BI"], FREQ)
             + avar.RW.from_continuous(TRUTH["RRW"], FREQ))
    rng = np.random.default_rng(seed)
    errors = {name: [] for name in ("noise_report", "allan-variance (NNLS)", "allan_variance_ros rules")}
    seconds = dict.fromkeys(errors, 0.0)
    for _ in range(repetitions):
        x = model.simulate(N_SAMPLES, seed=rng)
        started = time.perf_counter()
        ours, av = report_terms(x)
        seconds["noise_report"] += time.perf_counter() - started
        started = time.perf_counter()
        peer = peer_allan_variance(x)
        seconds["allan-variance (NNLS)"] += time.perf_counter() - started
        ros = ros_rules(av)
        for name, values in zip(errors, (ours, peer, ros)):
            errors[name].append([abs(values[t] / TRUTH[t] - 1.0) for t in TRUTH])
    rows = {}
    for name, values in errors.items():
        table = np.array(values)
        for k, term in enumerate(TRUTH):
            rows[(name, term)] = {"median": np.median(table[:, k]), "p90": np.percentile(table[:, k], 90)}
    result = pd.DataFrame(rows).T.unstack()
    result = result.reindex(columns=[(s, t) for s in ("median", "p90") for t in TRUTH])
    print(f"{repetitions} gyros, 2 h at {FREQ:g} Hz, truth N = {TRUTH['ARW']:g}, B = {TRUTH['BI']:g}, "
          f"K = {TRUTH['RRW']:g} (rad/s units); |estimate / truth - 1|:")
    print((100 * result).round(1).to_string(float_format=lambda v: f"{v:.1f}%"))
    print("seconds per series: " + ", ".join(f"{k} {v / repetitions:.2f}" for k, v in seconds.items() if v))
    return result


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 50, int(sys.argv[2]) if len(sys.argv) > 2 else 2026)
