"""Bulk decoding of Imu bags: identical to rosbags' message-by-message path, and hostile bags.

Bags are written for real with rosbags' writers (ROS 1 .bag, ROS 2 .db3 and .mcap); the
bulk decoder is checked against a plain ``struct`` reading of the serialized bytes and
against ``rosbags``' own deserialization (``read_messages(bulk=False)``).
"""

from __future__ import annotations

import functools
import struct
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("rosbags")

from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

import avar  # noqa: E402
from avar.io import bags  # noqa: E402
from avar.io.bag_decode import decode_imu  # noqa: E402
from avar.io.read import InputFileError  # noqa: E402

START = 1_700_000_000_000_000_000
FRAMES = ["", "a", "imu", "imu_link", "a_much_longer_frame_name_x"]  # CDR paddings 0..7 differ


def imu(store, values, stamp, frame, seq=0):
    t = store.types
    header = t["std_msgs/msg/Header"]
    time = t["builtin_interfaces/msg/Time"](sec=int(stamp) // 10**9, nanosec=int(stamp) % 10**9)
    ros1 = "seq" in header.__dataclass_fields__
    vec = t["geometry_msgs/msg/Vector3"]
    return t["sensor_msgs/msg/Imu"](
        header=header(seq=seq, stamp=time, frame_id=frame) if ros1 else header(stamp=time, frame_id=frame),
        orientation=t["geometry_msgs/msg/Quaternion"](x=0.1, y=0.2, z=0.3, w=0.9),
        orientation_covariance=np.arange(9.0), angular_velocity=vec(x=values[0], y=values[1], z=values[2]),
        angular_velocity_covariance=np.full(9, 2.0),
        linear_acceleration=vec(x=values[3], y=values[4], z=values[5]), linear_acceleration_covariance=np.ones(9))


def mixed(n=240, seed=0):
    """Two Imu topics with frame_ids of varying length, and a String topic between them."""
    rng = np.random.default_rng(seed)
    values = rng.standard_normal((n, 6)) * 1e3  # full float64 mantissas
    stamps = START + np.arange(n, dtype=np.int64) * 5_000_000 + rng.integers(0, 1000, n)
    frames = [FRAMES[i % len(FRAMES)] for i in range(n)]
    return values, stamps, frames


def write(kind, folder, n=240, big_endian=False, compress=False):
    values, stamps, frames = mixed(n)
    other, _, _ = mixed(n // 2, seed=1)
    if kind == "bag":
        store = get_typestore(Stores.ROS1_NOETIC)
        path = folder / "mixed.bag"
        writer = Writer1(path)
        if compress:
            writer.set_compression(Writer1.CompressionFormat.LZ4)
        ser = store.serialize_ros1
    else:
        store = get_typestore(Stores.ROS2_HUMBLE)
        path = folder / kind
        writer = Writer2(path, version=9, storage_plugin=StoragePlugin.SQLITE3 if kind == "db3" else StoragePlugin.MCAP)
        ser = functools.partial(store.serialize_cdr, little_endian=not big_endian)
    with writer:
        a = writer.add_connection("/imu/data", "sensor_msgs/msg/Imu", typestore=store)
        b = writer.add_connection("/imu/other", "sensor_msgs/msg/Imu", typestore=store)
        s = writer.add_connection("/chatter", "std_msgs/msg/String", typestore=store)
        for i in range(n):
            writer.write(a, int(stamps[i]) + 7, bytes(ser(imu(store, values[i], stamps[i], frames[i], i),
                                                           "sensor_msgs/msg/Imu")))
            writer.write(s, int(stamps[i]) + 9, bytes(ser(store.types["std_msgs/msg/String"](data="x" * (i % 13)),
                                                           "std_msgs/msg/String")))
            if i % 2:
                writer.write(b, int(stamps[i]) + 8, bytes(ser(imu(store, other[i // 2], stamps[i], "b"),
                                                               "sensor_msgs/msg/Imu")))
    return path, values, stamps


def reference(raw: bytes, cdr: bool):
    """A plain reading of one serialized Imu message with struct (the layout, field by field)."""
    e = ("<" if raw[1] == 1 else ">") if cdr else "<"
    sec, nsec, size = struct.unpack_from(e + ("iII" if cdr else "III"), raw, 4)
    first = 4 + -(-(12 + size) // 8) * 8 if cdr else 16 + size
    gyro = struct.unpack_from(e + "3d", raw, first + 32 + 72)
    accel = struct.unpack_from(e + "3d", raw, first + 32 + 72 + 24 + 72)
    return (*gyro, *accel), sec * 10**9 + nsec


@pytest.mark.parametrize("cdr,big", [(False, False), (True, False), (True, True)])
def test_decode_matches_a_struct_reading_for_every_frame_length(cdr, big):
    store = get_typestore(Stores.ROS2_HUMBLE if cdr else Stores.ROS1_NOETIC)
    values, stamps, _ = mixed(64)
    frames = ["x" * k for k in range(64)]  # every padding, every length
    msgs = [bytes(store.serialize_cdr(imu(store, v, t, f), "sensor_msgs/msg/Imu", little_endian=not big) if cdr
                  else store.serialize_ros1(imu(store, v, t, f), "sensor_msgs/msg/Imu"))
            for v, t, f in zip(values, stamps, frames)]
    buf = b"".join(b"\xaa" * 3 + m for m in msgs)  # 3 junk bytes before each message
    starts = np.cumsum([3] + [len(m) + 3 for m in msgs[:-1]])
    got, got_stamps = decode_imu(buf, starts, [len(m) for m in msgs], cdr=cdr)
    want = [reference(m, cdr) for m in msgs]
    assert got.tolist() == [list(w[0]) for w in want] == values.tolist()
    assert got_stamps.tolist() == [w[1] for w in want] == stamps.tolist()


def test_decode_refuses_a_layout_it_cannot_trust():
    store = get_typestore(Stores.ROS2_HUMBLE)
    values, stamps, _ = mixed(2)
    msg = bytes(store.serialize_cdr(imu(store, values[0], stamps[0], "ab"), "sensor_msgs/msg/Imu"))
    assert decode_imu(msg, [0], [len(msg)], cdr=True) is not None
    assert decode_imu(msg + b"\0" * 8, [0], [len(msg) + 8], cdr=True) is None  # longer than its frame_id implies
    assert decode_imu(b"\0\x03" + msg[2:], [0], [len(msg)], cdr=True) is None  # XCDR2 encapsulation
    assert decode_imu(msg, [0], [len(msg) + 1], cdr=True) is None  # runs past the buffer


@pytest.mark.parametrize("kind,big,compress", [("bag", False, False), ("bag", False, True), ("db3", False, False),
                                               ("mcap", False, False), ("mcap", True, False), ("db3", True, False)])
def test_bulk_equals_message_by_message(tmp_path, kind, big, compress, monkeypatch):
    path, values, stamps = write(kind, tmp_path, big_endian=big, compress=compress)
    slow = bags.read_messages(path, "/imu/data", bulk=False)
    slow_other = bags.read_messages(path, "/imu/other", bulk=False)
    calls = []
    monkeypatch.setattr(bags, "_per_message", lambda *a: calls.append(a) or pytest.fail("fell back"))
    fast = bags.read_messages(path, "/imu/data")
    assert not calls
    assert fast[0] == slow[0] == "/imu/data"
    for a, b in zip(fast[1:], slow[1:]):
        assert a.dtype == b.dtype and a.shape == b.shape
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(fast[1], values)  # bit for bit
    np.testing.assert_array_equal(fast[2], stamps)
    np.testing.assert_array_equal(fast[3], stamps + 7)  # receive times
    other = bags.read_messages(path, "/imu/other")
    for a, b in zip(other[1:], slow_other[1:]):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match=r"topic '/chatter' carries \['std_msgs/msg/String'\]"):
        bags.read_messages(path, "/chatter")


def test_empty_topic_names_file_and_topic(tmp_path):
    store = get_typestore(Stores.ROS1_NOETIC)
    path = tmp_path / "empty.bag"
    with Writer1(path) as writer:
        writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=store)
    with pytest.raises(InputFileError, match=rf"^{path}: topic '/imu' holds 0 message\(s\); at least 2"):
        avar.read(path)


@pytest.mark.parametrize("kind", ["bag", "mcap", "db3"])
def test_truncated_and_random_bags_name_the_file(tmp_path, kind):
    path, _, _ = write(kind, tmp_path, n=60)
    file = path if kind == "bag" else next(path.glob(f"*.{kind}"))
    data = file.read_bytes()
    cut = tmp_path / f"cut.{kind}"
    cut.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(InputFileError, match=rf"^{cut}: "):
        avar.read(cut, topic="/imu/data")
    noise = tmp_path / f"noise.{kind}"
    noise.write_bytes(np.random.default_rng(0).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    with pytest.raises(InputFileError, match=rf"^{noise}: not a readable ROS bag"):
        avar.read(noise)


@pytest.mark.parametrize("count", [3, 10**11])
@pytest.mark.parametrize("bulk", [True, False])
def test_metadata_that_lies_about_the_count_is_not_believed(tmp_path, count, bulk):
    path, values, _ = write("db3", tmp_path, n=60)
    meta = path / "metadata.yaml"
    text = meta.read_text()
    assert "message_count: 60" in text
    meta.write_text(text.replace("message_count: 60", f"message_count: {count}"))
    got = bags.read_messages(path, "/imu/data", bulk=bulk)
    np.testing.assert_array_equal(got[1], values)


def test_cli_gives_one_line_and_exit_1_for_a_random_bag(tmp_path):
    noise = tmp_path / "noise.bag"
    noise.write_bytes(bytes(range(256)) * 20)
    out = subprocess.run([sys.executable, "-m", "avar", "compute", str(noise)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 1
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and str(noise) in lines[0] and "Traceback" not in out.stderr, out.stderr


def sql_reference(path, topic):
    """The same rows by plain SQL, as rosbags queries them (timestamp order, ties by row)."""
    import sqlite3

    with sqlite3.connect(path) as db:
        (tid,) = db.execute("SELECT id FROM topics WHERE name=?", (topic,)).fetchone()
        return db.execute("SELECT timestamp, data FROM messages WHERE topic_id=? ORDER BY timestamp, id",
                          (tid,)).fetchall()


def test_sqlite_btree_reader_equals_sql_on_a_two_level_tree(tmp_path, monkeypatch):
    from avar.io import bag_sqlite

    store = get_typestore(Stores.ROS2_HUMBLE)
    n = 6000  # about 500 leaf pages of 4 KiB: the root's children are interior pages
    values, stamps, _ = mixed(n, seed=4)
    stamps[100:110] = stamps[100]  # equal receive times keep their row order
    with Writer2(tmp_path / "big", version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        a = writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=store)
        s = writer.add_connection("/s", "std_msgs/msg/String", typestore=store)
        for i in range(n):
            writer.write(a, int(stamps[i]), bytes(store.serialize_cdr(imu(store, values[i], stamps[i], "f" * (i % 9)),
                                                                      "sensor_msgs/msg/Imu")))
            if i % 3 == 0:
                writer.write(s, int(stamps[i]), bytes(store.serialize_cdr(
                    store.types["std_msgs/msg/String"](data="y" * (i % 50)), "std_msgs/msg/String")))
    path = next((tmp_path / "big").glob("*.db3"))
    data = path.read_bytes()
    page = int.from_bytes(data[16:18], "big")
    import sqlite3

    with sqlite3.connect(path) as db:
        root = bag_sqlite.check_schema(db)
    first_child = int.from_bytes(data[(root - 1) * page + 12 + 0:(root - 1) * page + 14], "big")
    child = int.from_bytes(data[(root - 1) * page + first_child:(root - 1) * page + first_child + 4], "big")
    assert data[(root - 1) * page] == 0x05 and data[(child - 1) * page] == 0x05  # two interior levels
    rows = sql_reference(path, "/imu")
    used = []
    original = bag_sqlite.read_messages
    monkeypatch.setattr(bag_sqlite, "read_messages", lambda *a: used.append(1) or original(*a))
    name, got, got_stamps, received = bags.read_messages(path, "/imu")
    assert used == [1]
    assert received.tolist() == [r[0] for r in rows]
    want = [reference(r[1], cdr=True) for r in rows]
    assert got.tolist() == [list(w[0]) for w in want]
    assert got_stamps.tolist() == [w[1] for w in want]


def test_sqlite_rows_on_overflow_pages_fall_back_to_sql(tmp_path, monkeypatch):
    from avar.io import bag_sqlite

    store = get_typestore(Stores.ROS2_HUMBLE)
    values, stamps, _ = mixed(20, seed=6)
    with Writer2(tmp_path / "long", version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        a = writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=store)
        for i in range(20):
            frame = "z" * (6000 if i == 7 else 3)  # one message larger than a page
            writer.write(a, int(stamps[i]), bytes(store.serialize_cdr(imu(store, values[i], stamps[i], frame),
                                                                      "sensor_msgs/msg/Imu")))
    path = next((tmp_path / "long").glob("*.db3"))
    refused = []
    original = bag_sqlite.read_messages

    def spy(*args):
        try:
            return original(*args)
        except bag_sqlite.Untrusted as error:
            refused.append(str(error))
            raise

    monkeypatch.setattr(bag_sqlite, "read_messages", spy)
    got = bags.read_messages(path, "/imu")
    assert refused == ["overflow"]
    np.testing.assert_array_equal(got[1], values)
    np.testing.assert_array_equal(got[2], stamps)


@pytest.mark.parametrize("kind", ["bag", "db3", "mcap"])
def test_an_untrusted_layout_falls_back_to_rosbags_with_the_same_values(tmp_path, kind, monkeypatch):
    path, values, stamps = write(kind, tmp_path, n=50)
    assert bags.imu_topics(path) == ["/imu/data", "/imu/other"]
    monkeypatch.setattr(bags, "decode_imu", lambda *a, **k: None)  # as for a layout the decoder refuses
    name, got, got_stamps, received = bags.read_messages(path, "/imu/data")
    np.testing.assert_array_equal(got, values)
    np.testing.assert_array_equal(got_stamps, stamps)
    np.testing.assert_array_equal(received, stamps + 7)
