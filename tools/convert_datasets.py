"""Convert the R package's IMU data sets (``.rda``) into the plain ``.npz`` files shipped in the package.

Run once, from the repository root, when the data sets change (needs the ``dev`` extra for
``rdata``)::

    python tools/convert_datasets.py DIR   # the folder holding the R package's .rda files

Every ``<name>.rda`` must match the SHA-256 digest of R ``avar`` 0.1.3 below. Each data set
becomes ``src/avar/io/data/<name>.npz`` holding only numbers and strings (no pickles):

* ``sensor``, ``freq``, ``n``: the sensor name, the sampling rate (Hz), the series length;
* ``type``, ``axis``, ``channels``: the sensor type, axis and name of every channel;
* ``levels_<i>``, ``allan_<i>``, ``errors_<i>``: the stored Allan variance of channel ``i``
  (0-based, in the order of ``channels``), bit for bit as R stored it; ``avtype_<i>`` its
  estimator type ("mo").

R's ``adev``, ``lci`` and ``uci`` are not stored: they derive from ``allan`` and ``errors``
(``tests/io/test_datasets.py`` checks that against the ``.rda`` files).
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import warnings
from pathlib import Path

import numpy as np

#: SHA-256 of the files of R avar 0.1.3.
SHA256 = {
    "adis_av": "000a7533f73e1f848346dd4de91caded998ace37eff161900c6e3dd0fff7cbc1",
    "imar_av": "dd64f49f11ef4669f769d21f2e5754bb1b2526a97ea228143b116f77d997864b",
    "kvh1750_av": "66181ec8841f9974e3f4c2e2dafcbd15fd75af39169609ebcba01c4a66a3d9b7",
    "ln200_av": "8fa8457abcd0a41ec0ab2b9ca36b9d300d33e5eb79802b6f9f2d622cb8b56381",
    "navchip_av": "ea92f1187cc7defc400c7de3b2a430527f9143a81f63031e4667b52df85546d0",
}
TARGET = Path(__file__).resolve().parent.parent / "src" / "avar" / "io" / "data"


def _scalar(value):
    return np.asarray(value).reshape(-1)[0]


def read_r_object(path: Path) -> dict:
    """The R object of ``<name>.rda`` as ``rdata`` reads it, after checking its digest."""
    import rdata

    name = path.stem
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != SHA256[name]:
        raise ValueError(f"{path} has SHA-256 {digest}, expected {SHA256[name]} (R avar 0.1.3)")
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Missing constructor", category=UserWarning)
        return rdata.read_rda(path)[name]


def arrays_of(obj: dict) -> dict[str, np.ndarray]:
    """The arrays of one data set, ready for ``numpy.savez``."""
    freq = float(_scalar(obj["freq"]))
    n = int(_scalar(obj["n"]))
    channels = [str(key) for key in obj["avar"]]
    arrays = {
        "sensor": np.array(str(_scalar(obj["sensor"]))),
        "freq": np.array(freq),
        "n": np.array(n, dtype=np.int64),
        "type": np.array([str(v) for v in np.asarray(obj["type"]).reshape(-1)]),
        "axis": np.array([str(v) for v in np.asarray(obj["axis"]).reshape(-1)]),
        "channels": np.array(channels),
    }
    for i, record in enumerate(obj["avar"].values()):
        channel_freq = float(_scalar(record["freq"])) if "freq" in record else freq
        channel_n = int(_scalar(record["n"])) if "n" in record else n
        if (channel_freq, channel_n) != (freq, n):
            raise ValueError(f"channel {channels[i]!r} has freq {channel_freq} / n {channel_n}, the set {freq} / {n}")
        arrays[f"levels_{i}"] = np.asarray(record["levels"], dtype=np.float64)
        arrays[f"allan_{i}"] = np.asarray(record["allan"], dtype=np.float64)
        arrays[f"errors_{i}"] = np.asarray(record["errors"], dtype=np.float64)
        arrays[f"avtype_{i}"] = np.array(str(_scalar(record["type"])) if "type" in record else "mo")
    return arrays


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source", type=Path, help="directory holding the five <name>.rda files")
    parser.add_argument("--target", type=Path, default=TARGET, help=f"output directory (default {TARGET})")
    args = parser.parse_args(argv)
    args.target.mkdir(parents=True, exist_ok=True)
    for name in SHA256:
        arrays = arrays_of(read_r_object(args.source / f"{name}.rda"))
        np.savez_compressed(args.target / f"{name}.npz", **arrays)
        print(f"wrote {args.target / f'{name}.npz'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
