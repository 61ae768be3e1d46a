"""``avar simulate``: a log simulated from a fitted noise model, to check a calibration or test a pipeline.

Reads the terms (the CSV that ``avar report LOG --output terms.csv`` writes, or a Kalibr
``imu.yaml``), simulates every present term of every channel with the library's own
process simulators (:func:`avar.simulate_log`) and writes the log: a CSV with a ``time``
column (seconds) and the channels ``gx gy gz ax ay az`` (rad/s, m/s^2), or a ROS 2 bag
(``.db3``, ``.mcap``) or ROS 1 bag (``.bag``) of ``sensor_msgs/msg/Imu`` messages written
with ``rosbags``, so that ``avar report`` reads it back with no options.
"""

from __future__ import annotations

import argparse
import io
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from avar._escape import terminal_lines
from avar.cli.common import Progress, UsageError, add_rate_arguments, printable, seed_number, whole_number
from avar.cli.outputs import PENDING, check_output_path, csv_text, rename_no_replace, write_all

#: Log formats by extension.
FORMATS = {".csv": "CSV", ".db3": "ROS 2 bag (SQLite)", ".mcap": "ROS 2 bag (MCAP)", ".bag": "ROS 1 bag"}
#: The bags' topic by default, and the first header stamp (ns since 1970: 2023-11-14).
DEFAULT_TOPIC = "/imu0"
START_NS = 1_700_000_000 * 10**9
IMU_TYPE = "sensor_msgs/msg/Imu"
#: Sentinels that mark where the stamp and the six values sit in a serialized message.
SENTINELS = (1.0e300, 2.0e300, 3.0e300, 4.0e300, 5.0e300, 6.0e300)
SECONDS_SENTINEL, NANOSECONDS_SENTINEL, SEQUENCE_SENTINEL = 0x7A5B3C1D, 0x1C2D3E4F, 0x3A4B5C6D


def csv_bytes(recording) -> bytes:
    """The log as CSV: ``time`` (s from the first sample) and the channels, every number in its shortest
    exact decimal form (read back bit for bit); pyarrow's writer when installed (ten times pandas')."""
    import pandas as pd

    columns = {"time": np.arange(recording.n_samples) / recording.rate, **recording.columns}
    header = csv_text(pd.DataFrame(columns=list(columns))).encode("utf-8")  # names quoted and defused as always
    try:
        import pyarrow as pa
        import pyarrow.csv as pa_csv
    except ImportError:
        return header + pd.DataFrame(columns).to_csv(index=False, header=False).encode("utf-8")
    buffer = io.BytesIO()
    pa_csv.write_csv(pa.table({f"c{k}": v for k, v in enumerate(columns.values())}), buffer,
                     pa_csv.WriteOptions(include_header=False))
    return header + buffer.getvalue()


def _template(store, ros1: bool) -> tuple[bytes, list[int], list[int]]:
    """A serialized Imu message, the byte offsets of its six values and those of its stamp's seconds and
    nanoseconds (and, in ROS 1, the header's sequence number)."""
    types = store.types
    header = types["std_msgs/msg/Header"]
    stamp = types["builtin_interfaces/msg/Time"](sec=SECONDS_SENTINEL, nanosec=NANOSECONDS_SENTINEL)
    vector = types["geometry_msgs/msg/Vector3"]
    covariance = np.zeros(9)
    message = types[IMU_TYPE](
        header=header(seq=SEQUENCE_SENTINEL, stamp=stamp, frame_id="imu") if ros1 else header(stamp=stamp, frame_id="imu"),
        orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=np.array([-1.0, *[0.0] * 8]),  # REP 145: no orientation estimate
        angular_velocity=vector(x=SENTINELS[0], y=SENTINELS[1], z=SENTINELS[2]),
        angular_velocity_covariance=covariance,
        linear_acceleration=vector(x=SENTINELS[3], y=SENTINELS[4], z=SENTINELS[5]),
        linear_acceleration_covariance=covariance)
    data = bytes(store.serialize_ros1(message, IMU_TYPE) if ros1 else store.serialize_cdr(message, IMU_TYPE))
    places = [data.index(np.float64(value).tobytes()) for value in SENTINELS]
    counters = [data.index(np.uint32(value).tobytes())
                for value in (SECONDS_SENTINEL, NANOSECONDS_SENTINEL, SEQUENCE_SENTINEL)[:3 if ros1 else 2]]
    return data, places, counters


def _messages(recording, store, ros1: bool) -> tuple[np.ndarray, np.ndarray]:
    """Every message serialized (one row of bytes each) and its stamp (ns)."""
    data, places, counters = _template(store, ros1)
    n = recording.n_samples
    stamps = START_NS + np.round(np.arange(n) * (1e9 / recording.rate)).astype(np.int64)
    rows = np.tile(np.frombuffer(data, dtype=np.uint8), (n, 1))
    values = np.column_stack([recording[name] for name in ("gx", "gy", "gz", "ax", "ay", "az")])
    for column, at in enumerate(places):
        rows[:, at:at + 8] = values[:, column].astype("<f8").view(np.uint8).reshape(n, 8)
    for at, count in zip(counters, (stamps // 10**9, stamps % 10**9, np.arange(n))):
        rows[:, at:at + 4] = count.astype("<u4").view(np.uint8).reshape(n, 4)
    return rows, stamps


def _check_imu_channels(recording, path: Path) -> None:
    needed = ("gx", "gy", "gz", "ax", "ay", "az")
    if tuple(recording.names) != needed:
        raise UsageError(f"{printable(str(path))}: an Imu message holds three gyroscope and three accelerometer axes; "
                         f"the model gives the channels {list(recording.names)} (write a .csv instead)")


def write_bag(recording, path: Path, topic: str, force: bool) -> None:
    """The log as a bag of ``sensor_msgs/msg/Imu`` messages: written in a temporary folder beside ``path``,
    then its storage file renamed into place (a reader never sees half a bag)."""
    try:
        from rosbags.rosbag1 import Writer as Writer1
        from rosbags.rosbag2 import StoragePlugin
        from rosbags.rosbag2 import Writer as Writer2
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise UsageError(f"{printable(str(path))}: writing ROS bags needs the 'rosbags' package: "
                         "pip install \"allanvar[ros]\"") from None
    _check_imu_channels(recording, path)
    suffix = path.suffix.lower()
    ros1 = suffix == ".bag"
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    rows, stamps = _messages(recording, store, ros1)
    folder = tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name[:40]}.", suffix=".part")
    PENDING.add(folder)
    try:
        if ros1:
            written = Path(folder) / f"log{suffix}"
            writer = Writer1(written)
        else:
            plugin = StoragePlugin.MCAP if suffix == ".mcap" else StoragePlugin.SQLITE3
            writer = Writer2(Path(folder) / "bag", version=9, storage_plugin=plugin)
        with writer:
            connection = writer.add_connection(topic, IMU_TYPE, typestore=store)
            for row, stamp in zip(rows, stamps.tolist()):
                writer.write(connection, stamp, row.tobytes())
        if not ros1:
            written = next((Path(folder) / "bag").glob(f"*{suffix}"))
        if force:
            os.replace(written, path)
        else:
            try:
                rename_no_replace(str(written), path)
            except FileExistsError:
                raise UsageError(f"{printable(str(path))} was created by another program while this run computed; "
                                 "it is left as it is (pass --force to replace it)") from None
    finally:
        shutil.rmtree(folder, ignore_errors=True)
        PENDING.discard(folder)


def run(args: argparse.Namespace) -> int:
    from avar.fit.report.simulate import parse_duration, simulated

    source = Path(args.terms)
    path = check_output_path("--output", args.output, [source], args.force)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise UsageError(f"--output {printable(args.output)}: name the log's format by its extension: "
                         + ", ".join(f"{s} ({name})" for s, name in FORMATS.items()))
    try:
        duration = parse_duration(args.duration, "--duration")
    except ValueError as error:
        raise UsageError(str(error)) from None
    if args.topic is not None and suffix == ".csv":
        raise UsageError("--topic names the topic of a bag; a .csv log has none")
    progress = Progress()
    progress(f"reading {args.terms}")
    try:
        log = simulated(source, duration, args.rate, args.seed)
    except ValueError as error:
        if str(error).startswith("rate:"):
            what = "the yaml has no update_rate" if source.suffix.lower() in (".yaml", ".yml") else \
                "a terms CSV does not hold the sampling rate"
            raise UsageError(f"{printable(args.terms)}: {what}; give --rate HZ") from None
        raise
    recording = log.recording
    progress(f"writing {recording.n_samples} samples of {len(recording.names)} channel(s) at {recording.rate:g} Hz")
    if suffix == ".csv":
        write_all([(path, csv_bytes(recording))], args.force)
    else:
        write_bag(recording, path, args.topic or DEFAULT_TOPIC, args.force)
    progress("done")
    for channel in log.channels:
        terms = ", ".join(f"{t.process} {t.value:.4g}" + ("" if t.shape is None else f" ({t.shape:.4g})")
                          for t in channel.terms)
        print(f"{printable(channel.column)}: {printable(channel.channel)} ({channel.sensor or 'no sensor type'}): "
              f"{terms}", file=sys.stderr)
    print(f"Wrote {printable(str(path))}: {recording.n_samples} samples x {len(recording.names)} channels "
          f"({', '.join(map(printable, recording.names))}) at {recording.rate:g} Hz, {FORMATS[suffix]}")
    return 0


def add_parser(commands) -> None:
    simulate = commands.add_parser(
        "simulate", help="simulate a log from a noise model (terms CSV of avar report, or Kalibr imu.yaml)",
        description="A log simulated from a fitted noise model: every term of every axis of the terms CSV that "
                    "'avar report LOG --output terms.csv' writes (white noise, bias instability, random walk, ramp, "
                    "quantization, Gauss-Markov, sinusoid), or N and K of a Kalibr imu.yaml on three axes per "
                    "sensor; written as CSV (time, gx gy gz ax ay az) or as a ROS bag that 'avar report' reads "
                    "back with no options.")
    simulate.add_argument("terms", help="terms CSV (avar report --output) or Kalibr imu.yaml (.yaml, .yml)")
    simulate.add_argument("--duration", required=True, metavar="SECONDS",
                          help="length of the log: seconds, or a number with a unit: 7200, 2h, 90min, 600s")
    add_rate_arguments(simulate, "the yaml's update_rate; required for a terms CSV")
    simulate.add_argument("--output", required=True, metavar="LOG",
                          help="the log to write: .csv (time, gx gy gz ax ay az), .db3 or .mcap (ROS 2 bag), "
                               ".bag (ROS 1 bag)")
    simulate.add_argument("--topic", metavar="TOPIC",
                          help=f"topic of the Imu messages of a bag (default {DEFAULT_TOPIC})")
    simulate.add_argument("--seed", type=seed_number, default=None,
                          help="seed of the simulation, a whole number >= 0 (default: fresh randomness)")
    simulate.add_argument("--force", action="store_true", help="replace an existing output file (default: refuse)")
    simulate.set_defaults(handler=run)


#: ``--recheck R``: a whole number of simulated logs >= 1.
recheck_count = whole_number(1, "simulated logs")


def add_recheck_arguments(parser: argparse.ArgumentParser) -> None:
    """``avar report``'s ``--recheck R`` and ``--seed N``."""
    parser.add_argument("--recheck", type=recheck_count, metavar="R", default=None,
                        help="re-fit R logs simulated from the fitted model (same length and rate) and print, per "
                             "term, the median ratio recovered / fitted and the coverage of the intervals "
                             "(default: none)")
    parser.add_argument("--seed", type=seed_number, default=None,
                        help="seed of the --recheck simulations, a whole number >= 0 (default: fresh randomness)")


def print_recheck(report, args: argparse.Namespace) -> None:
    """Run ``--recheck R`` on the report and print its table (on stderr when stdout holds the CSV)."""
    if getattr(args, "recheck", None) is None:
        return
    from avar.fit.report.recheck import recheck

    Progress()(f"recheck: simulating and fitting {args.recheck} log(s)")
    check = recheck(report, args.recheck, seed=args.seed)
    print("\n" + terminal_lines(str(check)), file=sys.stderr if args.output == "-" else sys.stdout)
