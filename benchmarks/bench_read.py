"""Reading real logs end to end: ``avar compute`` on 1-hour and 8-hour 200 Hz 6-axis CSVs.

Writes the CSVs (a time column and six channels, written once and kept in ``--dir``), then
times, each in a fresh subprocess, with its peak resident memory (``os.wait4``):

* ``read_csv``: ``python -c "import pandas; pandas.read_csv(f)"`` (the floor: Python, pandas
  and the C parser);
* ``avar compute f``: the command line, end to end (read, rate, the Allan variance of every
  column, the table printed);
* ``read_csv + allantools.oadev``: pandas, then ``allantools.oadev`` of each column on the
  octave grid (the usual script a user would write).

Ratios are to ``read_csv`` of the same file in the same run; the machine's load shows in all
three alike.

``--bags HOURS`` (e.g. 2) writes the same 200 Hz 6-axis data as a CSV (time column and six
channels) and as ``sensor_msgs/Imu`` topics of a ROS 1 ``.bag``, a ROS 2 ``.db3`` and an
``.mcap`` (with ``rosbags``' writers, messages serialized from a template with NumPy), then
times ``avar.read`` of each in a fresh subprocess and prints the ratio bag / CSV (target:
at most 1.5). ``--per-message`` adds rosbags' message-by-message decoding for comparison.
Usage::

    python benchmarks/bench_read.py                 # 1 h and 8 h, best of 3 and 1 runs
    python benchmarks/bench_read.py --hours 1 --repeat 5
    python benchmarks/bench_read.py --bags 2 --repeat 3
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

RATE = 200.0
CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")
SRC = str(Path(__file__).resolve().parent.parent / "src")

READ_CSV = "import sys, pandas; pandas.read_csv(sys.argv[1])"
ALLANTOOLS = (
    "import sys, pandas, allantools\n"
    "frame = pandas.read_csv(sys.argv[1])\n"
    "for name in frame.columns[1:]:\n"
    "    allantools.oadev(frame[name].to_numpy(), rate=float(sys.argv[2]), data_type='freq', taus='octave')\n"
)


def write_log(path: Path, hours: float, seed: int = 0) -> Path:
    """A 200 Hz 6-axis log with a time column, written in blocks (bounded memory)."""
    n = int(hours * 3600 * RATE)
    if path.exists() and path.stat().st_size > 0 and path.with_suffix(".rows").read_text() == str(n):
        return path
    rng = np.random.default_rng(seed)
    block = 500_000
    with path.open("w") as out:
        out.write("time," + ",".join(CHANNELS) + "\n")
        for start in range(0, n, block):
            rows = min(block, n - start)
            table = np.empty((rows, 7))
            table[:, 0] = np.arange(start, start + rows) / RATE
            table[:, 1:] = rng.standard_normal((rows, 6)) * 0.01 + [0, 0, 0, 0, 0, 9.81]
            np.savetxt(out, table, fmt=["%.3f"] + ["%.9f"] * 6, delimiter=",")
    path.with_suffix(".rows").write_text(str(n))
    return path


READ = "import sys, avar; x = avar.read(sys.argv[1]); assert x.n == int(sys.argv[2]), x.n"
READ_SLOW = ("import sys\nfrom avar.io.bags import read_messages\n"
             "assert len(read_messages(sys.argv[1], bulk=False)[1]) == int(sys.argv[2])")


def _imu_bytes(store, ros1: bool, values: np.ndarray, stamps: np.ndarray) -> np.ndarray:
    """Serialized Imu messages (n, size): one template from rosbags, the fields filled with NumPy."""
    t = store.types
    time = t["builtin_interfaces/msg/Time"](sec=0, nanosec=0)
    header = t["std_msgs/msg/Header"]
    head = header(seq=0, stamp=time, frame_id="imu_link") if ros1 else header(stamp=time, frame_id="imu_link")
    vec = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    msg = t["sensor_msgs/msg/Imu"](header=head, orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                                   orientation_covariance=np.zeros(9), angular_velocity=vec,
                                   angular_velocity_covariance=np.zeros(9), linear_acceleration=vec,
                                   linear_acceleration_covariance=np.zeros(9))
    raw = bytes(store.serialize_ros1(msg, "sensor_msgs/msg/Imu") if ros1
                else store.serialize_cdr(msg, "sensor_msgs/msg/Imu", little_endian=True))
    n = len(values)
    rows = np.tile(np.frombuffer(raw, np.uint8), (n, 1))
    first = 16 + 8 if ros1 else 4 + (12 + 9 + 7) // 8 * 8  # frame_id "imu_link" (+ NUL in CDR)
    for at, column in ((4, stamps // 10**9), (8, stamps % 10**9)):
        rows[:, at:at + 4] = column.astype("<u4").view(np.uint8).reshape(n, 4)
    rows[:, first + 104:first + 128] = values[:, :3].astype("<f8").view(np.uint8).reshape(n, 24)
    rows[:, first + 200:first + 224] = values[:, 3:].astype("<f8").view(np.uint8).reshape(n, 24)
    return rows


def write_bags(folder: Path, hours: float, seed: int = 0) -> dict[str, Path]:
    """The same log as CSV, ROS 1 .bag, ROS 2 .db3 and .mcap (written once, kept in ``folder``)."""
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2
    from rosbags.typesys import Stores, get_typestore

    n = int(hours * 3600 * RATE)
    folder = folder / f"bags_{hours:g}h"
    paths = {"CSV": folder / "imu.csv", ".bag": folder / "imu.bag", ".db3": folder / "db3" / "db3.db3",
             ".mcap": folder / "mcap" / "mcap.mcap"}
    if (folder / "rows").exists() and (folder / "rows").read_text() == str(n):
        return paths
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    rng = np.random.default_rng(seed)
    values = rng.standard_normal((n, 6)) * 0.01 + [0, 0, 0, 0, 0, 9.81]
    stamps = 1_700_000_000 * 10**9 + np.arange(n, dtype=np.int64) * round(1e9 / RATE)
    table = np.column_stack([(stamps - stamps[0]) / 1e9, values])
    with paths["CSV"].open("w") as out:
        out.write("time," + ",".join(CHANNELS) + "\n")
        np.savetxt(out, table, fmt=["%.3f"] + ["%.17g"] * 6, delimiter=",")
    store = get_typestore(Stores.ROS1_NOETIC)
    rows = _imu_bytes(store, True, values, stamps)
    with Writer1(paths[".bag"]) as writer:
        connection = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=store)
        for i in range(n):
            writer.write(connection, int(stamps[i]) + 1000, rows[i].tobytes())
    store = get_typestore(Stores.ROS2_HUMBLE)
    rows = _imu_bytes(store, False, values, stamps)
    for kind, plugin in ((".db3", StoragePlugin.SQLITE3), (".mcap", StoragePlugin.MCAP)):
        with Writer2(paths[kind].parent, version=9, storage_plugin=plugin) as writer:
            connection = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=store)
            for i in range(n):
                writer.write(connection, int(stamps[i]) + 1000, rows[i].tobytes())
    (folder / "rows").write_text(str(n))
    return paths


def same_values(paths: dict[str, Path]) -> str:
    """Whether every bag gives exactly the CSV's numbers (read once, in this process, untimed)."""
    sys.path.insert(0, SRC)
    import avar

    table = avar.read(paths["CSV"])
    csv = np.column_stack([np.asarray(table[name]) for name in CHANNELS])
    verdicts = []
    for kind in (".bag", ".db3", ".mcap"):
        verdicts.append(f"{kind} {'yes' if np.array_equal(avar.read(paths[kind]).data, csv) else 'NO'}")
    return ", ".join(verdicts)


def bench_bags(args, env: dict) -> None:
    """avar.read of the same data as CSV and as each bag format; ratios bag / CSV."""
    python = sys.executable
    paths = write_bags(args.dir, args.bags)
    n = str(int(args.bags * 3600 * RATE))
    cases = {f"avar.read {kind}": [python, "-c", READ, str(path), n] for kind, path in paths.items()}
    if args.per_message:
        cases.update({f"per-message {kind}": [python, "-c", READ_SLOW, str(path), n]
                      for kind, path in paths.items() if kind != "CSV"})
    best: dict[str, tuple[float, float]] = {}
    for _ in range(args.repeat[0]):
        for name, command in cases.items():
            wall, rss, code = measure(command, env)
            if code == 0 and (name not in best or wall < best[name][0]):
                best[name] = (wall, rss)
    floor = best["avar.read CSV"][0]
    print(f"{args.bags:g} h at {RATE:g} Hz, 6 channels ({n} messages); best of {args.repeat[0]}")
    print("values identical to the CSV's:", same_values(paths))
    print(f"{'case':28s} {'wall s':>8s} {'/ CSV':>7s} {'peak RSS MB':>12s}")
    for name, (wall, rss) in best.items():
        print(f"{name:28s} {wall:8.2f} {wall / floor:7.2f} {rss:12.0f}")


def measure(command: list[str], env: dict) -> tuple[float, float, int]:
    """Wall time (s), peak resident memory (MB) and exit status of one subprocess."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    error = process.stderr.read().decode(errors="replace")
    process.stderr.close()
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        print(f"  {command[:4]} failed ({code}): {error.strip().splitlines()[-1:]}", file=sys.stderr)
    return wall, usage.ru_maxrss / 1024.0, code


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, nargs="+", default=[1.0, 8.0])
    parser.add_argument("--repeat", type=int, nargs="+", default=[3, 1], help="runs per file (best kept)")
    parser.add_argument("--dir", type=Path, default=Path(tempfile.gettempdir()) / "avar_bench_read")
    parser.add_argument("--no-allantools", action="store_true", help="skip the allantools script")
    parser.add_argument("--bags", type=float, metavar="HOURS", help="compare avar.read of CSV and ROS bags")
    parser.add_argument("--per-message", action="store_true", help="with --bags: also rosbags' per-message path")
    args = parser.parse_args(argv)
    args.dir.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""), MPLBACKEND="Agg")
    if args.bags:
        bench_bags(args, env)
        return 0
    python = sys.executable
    rows = []
    for i, hours in enumerate(args.hours):
        repeat = args.repeat[min(i, len(args.repeat) - 1)]
        path = write_log(args.dir / f"imu_{hours:g}h.csv", hours)
        size = path.stat().st_size / 1e6
        cases = {
            "read_csv": [python, "-c", READ_CSV, str(path)],
            "avar compute": [python, "-m", "avar", "compute", str(path)],
        }
        if not args.no_allantools:
            cases["read_csv + allantools.oadev"] = [python, "-c", ALLANTOOLS, str(path), str(RATE)]
        best = {}
        for _ in range(repeat):  # interleaved, so that load changes hit every case alike
            for name, command in cases.items():
                wall, rss, code = measure(command, env)
                if code == 0 and (name not in best or wall < best[name][0]):
                    best[name] = (wall, max(rss, best.get(name, (0, 0))[1]))
        floor = best["read_csv"][0]
        for name, (wall, rss) in best.items():
            rows.append((f"{hours:g} h ({int(hours * 3600 * RATE):,} rows, {size:.0f} MB)", name, wall, wall / floor, rss))
    print(f"{'file':34s} {'command':30s} {'wall s':>8s} {'/ read_csv':>10s} {'peak RSS MB':>12s}")
    for file, name, wall, ratio, rss in rows:
        print(f"{file:34s} {name:30s} {wall:8.2f} {ratio:10.2f} {rss:12.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
