"""The noise report on sensors as they are: simulations by independent code, and real logs.

Every series is made here, with NumPy alone (no ``avar`` process class), so the
report is checked against a generator that shares none of its code:

* white noise: N sqrt(f) times i.i.d. normals (angle random walk N);
* flicker: a one-sided spectrum B^2 / (pi f) shaped by FFT on twice the
  length, the first half kept (IEEE 952's bias instability B: AD plateau 0.664 B);
* random walk: the cumulative sum of K / sqrt(f) normals (rate random walk K);
* Gauss-Markov: x_t = phi x_{t-1} + e_t, phi = exp(-1 / (T f)) (scipy.signal.lfilter);
* quantization: rounding to an LSB; spikes: 3 % of the samples moved by 20 sigma.

Scenarios (2 h at 200 Hz, rad/s), each over ``REPS`` seeds:

(a) white + flicker + a visible random walk; (b) the same plus a Gauss-Markov
term; (c) (a) quantized to an LSB of 0.4 sigma (rounding a rate sample adds white noise, so
N's truth there is sqrt(N^2 + LSB^2 / (12 f))); (d) (a) with 3 % spikes, the
report with and without ``robust=True``.

For each term it prints the median |estimate / truth - 1|, the share of seeds
whose 95 % interval covers the truth, and for the random walk how often it is
``present`` or ``bound`` with the truth under the bound. Then (e) the real logs
of ``AVAR_REALDATA`` (a folder of ``.npz`` files with ``data`` (N, 6) and
``columns``, 100 Hz, deg/s and g; default ``../shared/realdata`` when it exists):
per channel the share of levels where the implied deviation fits, the
Allan-deviation minimum against the empirical one, and the terms selected.

Usage::

    PYTHONPATH=src python benchmarks/noise_report_real.py [REPS [SCENARIOS]]   # e.g. 100 abcde
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

import avar

FREQ = 200.0
N_SAMPLES = int(2 * 3600 * FREQ)
TRUTH = {"WN": 1.2e-4, "FN": 1e-4, "RW": 1.2e-5}  # N rad/s/sqrt(Hz), B rad/s, K rad/s^2/sqrt(Hz)
GAUSS_MARKOV = {"sigma": 1.5e-4, "T": 2.0}        # rad/s, s


def flicker(rng: np.random.Generator, n: int, b: float, freq: float) -> np.ndarray:
    """1/f noise of one-sided PSD B^2 / (pi f), by FFT on 2n samples (the first n kept)."""
    size = 2 * n
    f = np.fft.rfftfreq(size, d=1.0 / freq)
    psd = np.zeros_like(f)
    psd[1:] = b * b / (math.pi * f[1:])
    coefficients = np.sqrt(psd * freq * size / 4.0) * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
    coefficients[0] = 0.0
    coefficients[-1] = coefficients[-1].real * math.sqrt(2.0)
    return np.fft.irfft(coefficients, n=size)[:n]


def gyro(rng: np.random.Generator, gauss_markov: bool = False) -> np.ndarray:
    from scipy.signal import lfilter

    x = TRUTH["WN"] * math.sqrt(FREQ) * rng.standard_normal(N_SAMPLES)
    x += flicker(rng, N_SAMPLES, TRUTH["FN"], FREQ)
    x += np.cumsum(TRUTH["RW"] / math.sqrt(FREQ) * rng.standard_normal(N_SAMPLES))
    if gauss_markov:
        phi = math.exp(-1.0 / (GAUSS_MARKOV["T"] * FREQ))
        e = GAUSS_MARKOV["sigma"] * math.sqrt(1 - phi * phi) * rng.standard_normal(N_SAMPLES)
        x += lfilter([1.0], [1.0, -phi], e)
    return x


def spiked(rng: np.random.Generator, x: np.ndarray, share: float = 0.03, size: float = 20.0) -> np.ndarray:
    out = x.copy()
    where = rng.choice(x.size, int(share * x.size), replace=False)
    sigma = TRUTH["WN"] * math.sqrt(FREQ)
    out[where] += size * sigma * rng.choice([-1.0, 1.0], where.size)
    return out


def row_of(report, process: str) -> dict:
    table = report.table
    return table[table["Process"] == process].iloc[0].to_dict()


def scenario(name: str, reps: int, make, robust: bool = False, truth: dict | None = None) -> None:
    truth_of = dict(TRUTH, **(truth or {}))
    errors = {p: [] for p in TRUTH}
    covered = {p: [] for p in TRUTH}
    rw_ok, times, gm_err, gm_cov = [], [], [], []
    for seed in range(reps):
        rng = np.random.default_rng(1000 + seed)
        x = make(rng)
        start = time.perf_counter()
        kwargs = {"robust": True} if robust else {}
        report = avar.noise_report(x, gyro_units="rad/s", rate=FREQ, **kwargs)
        times.append(time.perf_counter() - start)
        for process, truth in truth_of.items():
            row = row_of(report, process)
            if row["Status"] == "present":
                errors[process].append(abs(float(row["Value"]) / truth - 1))
                covered[process].append(float(row["Lower"]) <= truth <= float(row["Upper"]))
            elif row["Status"] == "bound":
                covered[process].append(truth <= float(row["Upper"]))
        rw = row_of(report, "RW")
        rw_ok.append(rw["Status"] == "present" or (rw["Status"] == "bound" and TRUTH["RW"] <= float(rw["Upper"])))
        if "gauss" in name:
            rows = report.table[report.table["Process"].str.endswith(".T")]
            if len(rows):
                best = rows.iloc[int(np.argmin(np.abs(np.log(rows["Value"].astype(float) / GAUSS_MARKOV["T"]))))]
                gm_err.append(abs(float(best["Value"]) / GAUSS_MARKOV["T"] - 1))
                gm_cov.append(float(best["Lower"]) <= GAUSS_MARKOV["T"] <= float(best["Upper"]))
            else:
                gm_err.append(math.inf)
    print(f"\n({name}) {reps} seeds, report {np.median(times):.2f} s median")
    print(f"  {'term':<4} {'present':>8} {'median |err|':>13} {'coverage':>9}")
    for process in TRUTH:
        values = errors[process]
        median = f"{100 * np.median(values):.2f} %" if values else "-"
        cover = f"{np.mean(covered[process]):.2f}" if covered[process] else "-"
        print(f"  {process:<4} {len(values):>8} {median:>13} {cover:>9}")
    print(f"  random walk present, or bound above the truth: {np.mean(rw_ok):.2f}")
    if gm_err:
        print(f"  Gauss-Markov correlation time: found in {np.mean(np.isfinite(gm_err)):.2f} of seeds, median "
              f"|err| {100 * np.median(gm_err):.1f} %, coverage {np.mean(gm_cov) if gm_cov else float('nan'):.2f}")


def real_logs() -> None:
    folder = Path(os.environ.get("AVAR_REALDATA", Path(__file__).resolve().parents[2] / "shared" / "realdata"))
    files = sorted(folder.glob("*.npz")) if folder.is_dir() else []
    if not files:
        print(f"\n(e) no real logs in {folder}; set AVAR_REALDATA")
        return
    for path in files:
        data = np.load(path)
        columns = [str(c) for c in data["columns"]]
        table = {c: data["data"][:, k] for k, c in enumerate(columns)}
        gyro_names = [c for c in columns if c.lower().startswith("gyr")]
        accel_names = [c for c in columns if c.lower().startswith("acc")]
        import pandas as pd

        start = time.perf_counter()
        report = avar.noise_report(pd.DataFrame(table), gyro_units="deg/s", accel_units="g", rate=100.0,
                                   gyro=gyro_names, accel=accel_names)
        elapsed = time.perf_counter() - start
        print(f"\n(e) {path.name}: {len(columns)} channels, report {elapsed:.2f} s, warnings: {len(report.warnings)}")
        for channel in columns:
            curves = report.curves[report.curves["Channel"] == channel]
            minimum = row_of_channel(report, channel, "MIN")
            empirical = float(curves["ADEV"].min())
            kinds = "+".join(c.kind for c in report.fits[channel].components)
            print(f"  {channel:<9} fits {curves['Fits'].mean():.2f} of levels; minimum "
                  f"{float(minimum['Customary']):.4g} {minimum['Customary unit']} at {float(minimum['Tau (s)']):.4g} s "
                  f"(empirical {empirical:.4g}, ratio {float(minimum['Value']) / to_si(report, channel, empirical):.4f}); "
                  f"model {kinds}")


def row_of_channel(report, channel: str, process: str) -> dict:
    table = report.table
    return table[(table["Channel"] == channel) & (table["Process"] == process)].iloc[0].to_dict()


def to_si(report, channel: str, value: float) -> float:
    from avar.fit.report.noise_terms import to_si as convert

    k = report.channels.index(channel)
    return convert(value, report.sensor_types[k], report.units[k])


def main() -> None:
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    chosen = sys.argv[2] if len(sys.argv) > 2 else "abcde"
    print(f"truth: N {TRUTH['WN']:.3g} rad/s/sqrt(Hz), B {TRUTH['FN']:.3g} rad/s, K {TRUTH['RW']:.3g} rad/s^2/sqrt(Hz);"
          f" {N_SAMPLES} samples at {FREQ:g} Hz")
    lsb = 0.4 * TRUTH["WN"] * math.sqrt(FREQ)
    if "a" in chosen:
        scenario("a: white + flicker + random walk", reps, gyro)
    if "b" in chosen:
        scenario("b: gauss-markov added", reps, lambda rng: gyro(rng, gauss_markov=True))
    if "c" in chosen:
        # rounding a rate sample adds white noise of variance LSB^2 / 12 per sample: N^2 + LSB^2 / (12 f)
        white = math.sqrt(TRUTH["WN"] ** 2 + lsb**2 / (12 * FREQ))
        scenario(f"c: quantized, LSB {lsb:.3g} rad/s (N with the rounding's white noise {white:.4g})", reps,
                 lambda rng: np.round(gyro(rng) / lsb) * lsb, truth={"WN": white})
    if "d" in chosen:
        scenario("d: 3 % spikes, plain", reps, lambda rng: spiked(rng, gyro(rng)))
        try:
            scenario("d: 3 % spikes, robust=True", reps, lambda rng: spiked(rng, gyro(rng)), robust=True)
        except TypeError as error:
            print(f"  robust: {error}")
    if "e" in chosen:
        real_logs()


if __name__ == "__main__":
    main()
