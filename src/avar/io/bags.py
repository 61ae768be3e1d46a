"""ROS bags: ``sensor_msgs/msg/Imu`` topics of ROS 1 ``.bag`` and ROS 2 ``.db3``/``.mcap`` bags.

Read with the ``rosbags`` package (``pip install "avar[ros]"``), which needs no ROS
installation. A ROS 2 bag is given as its ``.db3``/``.mcap`` file or as its directory
(with ``metadata.yaml``). Each message gives one sample of six channels:

* ``angular_velocity.x/y/z`` -> gyroscope X, Y, Z (rad/s, as REP 103 and the message say);
* ``linear_acceleration.x/y/z`` -> accelerometer X, Y, Z (m/s^2).

The rate comes from the messages' ``header.stamp`` (exact integer nanoseconds), like a
time column: 1 / the mean step between gaps, with the jitter reported and gaps refused
unless ``gaps="ignore"``. Stamps that are all zero (a driver that does not fill them)
fall back to the bag's receive times, and the result says so.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from avar.imu import IMU
from avar.io.progress import progress_enabled
from avar.io.timecols import rate_of

IMU_TYPE = "sensor_msgs/msg/Imu"
UNITS = {"gyro": "rad/s", "accel": "m/s^2"}


def _reader(path: Path):
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ImportError(
            f"{path}: reading ROS bags needs the 'rosbags' package: pip install \"avar[ros]\""
        ) from None
    return AnyReader([path], default_typestore=get_typestore(Stores.LATEST))


def imu_topics(path: str | Path) -> list[str]:
    """The ``sensor_msgs/msg/Imu`` topics of a bag, sorted."""
    with _reader(Path(path)) as reader:
        return sorted({c.topic for c in reader.connections if c.msgtype == IMU_TYPE})


def _choose_topic(reader, path: Path, topic: str | None) -> list:
    imu = sorted({c.topic for c in reader.connections if c.msgtype == IMU_TYPE})
    if topic is None:
        if len(imu) != 1:
            found = f"its Imu topics are {imu}" if imu else "it has none"
            raise ValueError(f"{path}: give the sensor_msgs/msg/Imu topic to read (--topic / topic=); {found}")
        topic = imu[0]
    connections = [c for c in reader.connections if c.topic == topic]
    if not connections:
        raise ValueError(f"{path}: no topic {topic!r}; its Imu topics are {imu}")
    types = sorted({c.msgtype for c in connections})
    if types != [IMU_TYPE]:
        raise ValueError(f"{path}: topic {topic!r} carries {types}, not {IMU_TYPE}; its Imu topics are {imu}")
    return connections


def read_bag(path: str | Path, topic: str | None = None, freq: float | None = None, gaps: str = "error",
             progress: bool | None = None) -> IMU:
    """The Imu messages of one topic of a bag, as an :class:`avar.IMU` (see the module notes).

    Parameters
    ----------
    path : str or Path
        ROS 1 ``.bag``; ROS 2 ``.db3`` or ``.mcap`` file, or a ROS 2 bag directory.
    topic : str, optional
        Required when the bag holds several Imu topics (the error lists them).
    freq : float, optional
        Sampling rate (Hz); default: from the header stamps.
    gaps : {"error", "ignore"}
        What to do with stamp steps longer than 1.5 median steps.
    progress : bool, optional
        A progress bar on stderr (default: a terminal and more than ~10^7 values).
    """
    path = Path(path)
    with _reader(path) as reader:
        connections = _choose_topic(reader, path, topic)
        total = sum(c.msgcount for c in connections)
        messages = reader.messages(connections=connections)
        if progress_enabled(progress, 6 * total):
            from tqdm import tqdm

            messages = tqdm(messages, total=total, desc=f"reading {path.name}", unit="msg", file=sys.stderr,
                            leave=False)
        values = np.empty((total, 6))
        stamps = np.empty(total, dtype=np.int64)
        received = np.empty(total, dtype=np.int64)
        count = 0
        for connection, timestamp, raw in messages:
            msg = reader.deserialize(raw, connection.msgtype)
            w, a = msg.angular_velocity, msg.linear_acceleration
            values[count] = (w.x, w.y, w.z, a.x, a.y, a.z)
            stamps[count] = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
            received[count] = timestamp
            count += 1
        name = connections[0].topic
    values, stamps, received = values[:count], stamps[:count], received[:count]
    if freq is None:
        if not stamps.any():
            timing = rate_of(received, "bag receive time", "ns", gaps, what=f"{path} {name} (header stamps are 0)")
        else:
            timing = rate_of(stamps, "header.stamp", "ns", gaps, what=f"{path} {name}")
        freq = timing["freq"]
    return IMU(values, freq, gyro=[0, 1, 2], accel=[3, 4, 5], name=name, units=UNITS)
