"""ROS bags: ``sensor_msgs/msg/Imu`` topics of ROS 1 ``.bag`` and ROS 2 ``.db3``/``.mcap`` bags.

Read with the ``rosbags`` package (``pip install "allanvar[ros]"``), which needs no ROS
installation. A ROS 2 bag is given as its ``.db3``/``.mcap`` file or as its directory
(with ``metadata.yaml``). Each message gives one sample of six channels:

* ``angular_velocity.x/y/z`` -> gyroscope X, Y, Z (rad/s, as REP 103 and the message say);
* ``linear_acceleration.x/y/z`` -> accelerometer X, Y, Z (m/s^2).

Messages are decoded in bulk: their raw bytes are collected per file
(:mod:`avar.io.bag_storage`) and the fields read with NumPy from the fixed ROS 1 / CDR
layout (:mod:`avar.io.bag_decode`). A bag the bulk path cannot vouch for (an unknown
compression, an unindexed file, a layout that varies in ways the decoder does not
know) is decoded message by message with ``rosbags``; both give the same values.
Messages come in the order of their receive time, as ``rosbags`` yields them.

The rate comes from the messages' ``header.stamp`` (exact integer nanoseconds), like a
time column: 1 / the mean step between gaps, with the jitter reported and gaps refused
unless ``gaps="ignore"``. Stamps that are all zero (a driver that does not fill them)
fall back to the bag's receive times, and the result says so.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from avar._vocabulary import check_rate, renamed
from avar.imu import IMU
from avar.io.bag_decode import decode_imu
from avar.io.bag_storage import Connection, Db3Bag, McapBag, Ros1Bag, Untrusted
from avar.io.streams import progress_enabled
from avar.io.timecols import rate_of

IMU_TYPE = "sensor_msgs/msg/Imu"
UNITS = {"gyro": "rad/s", "accel": "m/s^2"}
STORAGES = {".bag": Ros1Bag, ".db3": Db3Bag, ".mcap": McapBag}


class BagError(ValueError):
    """A bag that cannot be read as asked; the message names the file (and topic)."""


def _reader(path: Path):
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ImportError(
            f"{path}: reading ROS bags needs the 'rosbags' package: pip install \"allanvar[ros]\""
        ) from None
    return AnyReader([path], default_typestore=get_typestore(Stores.LATEST))


def _files(path: Path) -> list[Path]:
    """The storage files of a bag (a ROS 2 directory lists them in ``metadata.yaml``)."""
    if not path.is_dir():
        return [path]
    import yaml

    info = yaml.safe_load((path / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    if info.get("compression_format") or info.get("storage_identifier") not in ("sqlite3", "mcap"):
        raise Untrusted("compressed or unknown storage")
    return [path / name for name in info["relative_file_paths"]]


def _choose_topic(connections: list[Connection], path: Path, topic: str | None) -> str:
    """The Imu topic to read, from a bag's connections."""
    imu = sorted({c.topic for c in connections if c.msgtype == IMU_TYPE})
    if topic is None:
        if len(imu) != 1:
            found = f"its Imu topics are {imu}" if imu else "it has none"
            raise BagError(f"{path}: give the sensor_msgs/msg/Imu topic to read (--topic / topic=); {found}")
        topic = imu[0]
    types = sorted({c.msgtype for c in connections if c.topic == topic})
    if not types:
        raise BagError(f"{path}: no topic {topic!r}; its Imu topics are {imu}")
    if types != [IMU_TYPE]:
        raise BagError(f"{path}: topic {topic!r} carries {types}, not {IMU_TYPE}; its Imu topics are {imu}")
    return topic


def imu_topics(path: str | Path) -> list[str]:
    """The ``sensor_msgs/msg/Imu`` topics of a bag, sorted."""
    path = Path(path)
    try:
        storages = [STORAGES[file.suffix.lower()](file) for file in _files(path)]
    except (Untrusted, KeyError):
        with _reader(path) as reader:
            return sorted({c.topic for c in reader.connections if c.msgtype == IMU_TYPE})
    for storage in storages:
        storage.close()
    return sorted({c.topic for s in storages for c in s.connections if c.msgtype == IMU_TYPE})


def _bulk(path: Path, topic: str | None, progress: bool):
    """Values, header stamps and receive times of a topic, decoded in bulk (or Untrusted)."""
    files = _files(path)
    kind = {p.suffix.lower() for p in files}
    if len(kind) != 1 or next(iter(kind)) not in STORAGES:
        raise Untrusted("storage")
    storages = []
    try:
        for file in files:
            storages.append(STORAGES[file.suffix.lower()](file))
        name = _choose_topic([c for s in storages for c in s.connections], path, topic)
        parts = []
        for storage in storages:
            ids = {c.id for c in storage.connections if c.topic == name}
            batches = storage.batches(ids) if ids else ()
            if progress:
                from tqdm import tqdm

                batches = tqdm(batches, desc=f"reading {path.name}", unit="batch", file=sys.stderr, leave=False)
            for batch in batches:
                decoded = decode_imu(batch.buf, batch.starts, batch.lengths, cdr=not isinstance(storage, Ros1Bag))
                if decoded is None:
                    raise Untrusted("layout")
                parts.append((decoded.values, decoded.stamps, batch.receive_ns))
    finally:
        for storage in storages:
            storage.close()
    if not parts:
        return name, np.empty((0, 6)), np.empty(0, np.int64), np.empty(0, np.int64)
    values, stamps, received = (p[0] if len(parts) == 1 else np.concatenate(p) for p in zip(*parts))
    if np.any(np.diff(received) < 0):  # receive-time order, as rosbags yields the messages
        order = np.argsort(received, kind="stable")
        values, stamps, received = values[order], stamps[order], received[order]
    return name, values, stamps, received


def _per_message(path: Path, topic: str | None, progress: bool | None):
    """The same, deserializing each message with ``rosbags`` (any layout it knows)."""
    with _reader(path) as reader:
        name = _choose_topic([Connection(c.id, c.topic, c.msgtype) for c in reader.connections], path, topic)
        connections = [c for c in reader.connections if c.topic == name]
        total = sum(c.msgcount for c in connections)  # the bag's own count: only for the bar
        messages = reader.messages(connections=connections)
        if progress_enabled(progress, 6 * total):
            from tqdm import tqdm

            messages = tqdm(messages, total=total, desc=f"reading {path.name}", unit="msg", file=sys.stderr,
                            leave=False)
        rows, stamps, received = [], [], []
        for connection, timestamp, raw in messages:
            msg = reader.deserialize(raw, connection.msgtype)
            w, a = msg.angular_velocity, msg.linear_acceleration
            rows.append((w.x, w.y, w.z, a.x, a.y, a.z))
            stamps.append(int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec))
            received.append(timestamp)
    values = np.array(rows, dtype=float).reshape(-1, 6)
    return name, values, np.array(stamps, dtype=np.int64), np.array(received, dtype=np.int64)


def read_messages(path: str | Path, topic: str | None = None, progress: bool | None = None,
                  bulk: bool = True) -> tuple[str, np.ndarray, np.ndarray, np.ndarray]:
    """Topic name, values (n, 6), header stamps and receive times (ns) of a bag's Imu topic.

    ``bulk=False`` forces the message-by-message path; the bulk path also hands over to
    it whenever it meets anything it does not know (so a newer ``rosbags`` or an odd
    file costs speed, not correctness). A failure of the bag library or of the file's
    structure then becomes a :class:`BagError` naming the file.
    """
    path = Path(path)
    try:
        if bulk:
            try:
                return _bulk(path, topic, progress_enabled(progress, 0))
            except (BagError, ImportError, MemoryError):
                raise
            except Exception:  # Untrusted, or a structure (or rosbags version) the bulk reader does not know
                pass
        return _per_message(path, topic, progress)
    except (BagError, ImportError, MemoryError):
        raise
    except Exception as error:  # the bag library's or the file structure's own errors
        text = " ".join(str(error).split())[:200] or type(error).__name__
        raise BagError(f"{path}: not a readable ROS bag ({text})") from None


def read_bag(path: str | Path, topic: str | None = None, rate: float | None = None, gaps: str = "error",
             progress: bool | None = None, *, freq: float | None = None) -> IMU:
    """The Imu messages of one topic of a bag, as an :class:`avar.IMU` (see the module notes).

    Parameters
    ----------
    path : str or Path
        ROS 1 ``.bag``; ROS 2 ``.db3`` or ``.mcap`` file, or a ROS 2 bag directory.
    topic : str, optional
        Required when the bag holds several Imu topics (the error lists them).
    rate : float, optional
        Sampling rate (Hz); default: from the header stamps.
    gaps : {"error", "ignore"}
        What to do with stamp steps longer than 1.5 median steps.
    progress : bool, optional
        A progress bar on stderr (default: a terminal and more than ~10^7 values).
    """
    rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=True)
    if rate is not None:
        rate = check_rate(rate, rate_name)
    path = Path(path)
    name, values, stamps, received = read_messages(path, topic, progress)
    if len(values) < 2:
        raise BagError(f"{path}: topic {name!r} holds {len(values)} message(s); at least 2 are needed")
    if rate is None:
        if not stamps.any():
            timing = rate_of(received, "bag receive time", "ns", gaps, what=f"{path} {name} (header stamps are 0)")
        else:
            timing = rate_of(stamps, "header.stamp", "ns", gaps, what=f"{path} {name}")
        rate = timing["rate"]
    return IMU(values, rate, gyro=[0, 1, 2], accel=[3, 4, 5], name=name, units=UNITS)
