"""Every Stable32 table in allantools' test data against avar: values, term counts, noise alpha, bounds.

allantools' source distribution carries Stable32 1.60's printed tables of several
records (NIST's PHASE.DAT, a caesium clock's 556,990-point phase, a GPS receiver's
1 PPS, a Keysight counter's noise floor, an OCXO, a simulated flicker FM record)
together with the data. This script runs avar's statistic on each table's data at its
averaging factors and prints, per table, the largest relative difference of the values,
the share of equal term counts and noise exponents, and the largest relative difference
of the bounds where the noise agrees; then the totals.

Run::

    pip download --no-deps --no-binary :all: allantools==2024.6 -d /tmp/at
    tar xzf /tmp/at/allantools-2024.6.tar.gz -C /tmp/at
    python benchmarks/stable32_tables.py /tmp/at/allantools-2024.6/tests

Measured (allantools 2024.6): alpha 7,094 of 7,106 rows (99.83 %); bounds to 2.4e-4 on
every table but the OCXO's octave ones, which Stable32 computed from frequencies near 1.0
(f / 1e7) and printed with about 1e-3 of rounding (their values differ as much).
"""

from __future__ import annotations

import argparse
import gzip
import warnings
from pathlib import Path

import numpy as np

import avar

STATISTICS = {"Allan": "adev", "Overlapping Allan": "oadev", "Modified Allan": "mdev", "Time": "tdev",
              "Hadamard": "hdev", "Overlapping Hadamard": "ohdev", "Total": "totdev", "Modified Total": "mtotdev",
              "Time Total": "ttotdev", "Hadamard Total": "htotdev", "Thêo1": "theo1"}
#: Tables printed with a fixed noise type their header does not state, or without the bias removal.
FIXED_NOISE = ("Cs5071A/totdev_decade.txt", "ocxo/stable32_totdev_alltau.txt", "pink_frequency/totdev_alpha0.txt",
               "phasedat/phase_dat_htotdev_octave_nobias.txt")


def numbers(path: Path) -> np.ndarray:
    """The last number of every line that has one (gzip or plain text)."""
    opener = gzip.open if path.suffix == ".gz" else open
    values = []
    with opener(path, "rt", errors="ignore") as lines:
        for line in lines:
            fields = line.replace(",", " ").split()
            if fields and not fields[0].startswith(("#", "%")):
                try:
                    values.append(float(fields[-1]))
                except ValueError:
                    pass
    return np.array(values)


def records(tests: Path) -> dict[str, tuple[np.ndarray, str]]:
    ocxo = numbers(tests / "ocxo" / "ocxo_frequency.txt")
    found = {"phasedat": (numbers(tests / "phasedat" / "PHASE.DAT"), "phase"),
             "Cs5071A": (numbers(tests / "Cs5071A" / "5071A_phase.txt.gz"), "phase"),
             "gps": (numbers(tests / "gps" / "gps_1pps_phase_data.txt.gz"), "phase"),
             "Keysight53230A_ti_noise_floor": (numbers(tests / "Keysight53230A_ti_noise_floor" / "tic_phase.txt"), "phase"),
             "ocxo": ((ocxo - 1e7) / 1e7, "freq")}
    pink = sorted((tests / "pink_frequency").glob("*freq*"))
    if pink:
        found["pink_frequency"] = (numbers(pink[0]), "freq")
    return found


def table(text: str) -> np.ndarray:
    rows = []
    for line in text.splitlines():
        fields = line.split()
        if len(fields) >= 7 and fields[0].isdigit():
            try:
                rows.append([float(v) for v in fields[:7]])
            except ValueError:
                pass
    return np.array(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("tests", type=Path, help="allantools' tests folder (from its source distribution)")
    tests = parser.parse_args().tests
    warnings.simplefilter("ignore")
    data = records(tests)
    noise_rows = noise_equal = 0
    worst_bound = 0.0
    for path in sorted(tests.rglob("*.txt")):
        text = path.read_text(errors="ignore")
        if "Sigma Type:" not in text or path.parent.name not in data:
            continue
        statistic = STATISTICS.get(text.split("Sigma Type:")[1].splitlines()[0].strip())
        rows = table(text)
        if statistic is None or rows.size == 0:
            continue
        fixed = next((int(line.split("=")[1]) for line in text.splitlines() if line.lstrip("# ").startswith("Alpha =")),
                     None)
        x, kind = data[path.parent.name]
        if "Data Points 1 thru " in text:
            x = x[: int(text.split("Data Points 1 thru ")[1].split()[0])]
        theo = statistic == "theo1"
        tau0 = float(f"{rows[0, 1] / rows[0, 0] / (0.75 if theo else 1.0):.4g}")
        options = {"bias_correction": False} if "nobias" in path.name else {}
        if fixed is not None:
            options["alpha"] = fixed
        result = getattr(avar, statistic)(x, rate=1 / tau0, data_type=kind,
                                          taus=rows[:, 0] * tau0 * (0.75 if theo else 1.0), **options)
        value = np.abs(result.deviation / rows[:, 5] - 1).max()
        counts = np.nan if theo else np.mean(result.n == rows[:, 2].astype(int))
        same = result.alpha == rows[:, 3].astype(int)
        bounded = (rows[:, 4] > 0) & same
        bound = np.maximum(np.abs(result.lci / rows[:, 4] - 1), np.abs(result.uci / rows[:, 6] - 1))[bounded]
        name = str(path.relative_to(tests))
        if fixed is None and name not in FIXED_NOISE:
            noise_rows += rows.shape[0]
            noise_equal += int(same.sum())
        if bound.size and not (path.parent.name == "ocxo" and "octave" in path.name):
            worst_bound = max(worst_bound, float(bound.max()))
        print(f"{name:50s} {statistic:8s} rows {rows.shape[0]:4d}  value {value:.1e}  # {counts:.3f}  "
              f"alpha {same.mean():.3f}  bounds {bound.max() if bound.size else float('nan'):.1e}")
    print(f"alpha: {noise_equal} of {noise_rows} rows ({noise_equal / noise_rows:.2%}); "
          f"bounds (but the OCXO octave tables): to {worst_bound:.1e}")


if __name__ == "__main__":
    main()
