"""The ``messages`` table of a ROS 2 ``.db3`` bag read straight from the SQLite file with NumPy.

Fetching a million rows through ``sqlite3`` costs a Python object per row; the table's
B-tree is simple enough to read in bulk instead (SQLite file format,
https://www.sqlite.org/fileformat2.html):

* the table's root page (from ``sqlite_master``) and its interior pages (type 0x05: a
  2-byte big-endian cell count at 3, the right-most child at 8, cell pointers at 12,
  each cell a 4-byte child page number) lead, level by level, to its leaf pages in
  rowid order;
* a leaf page (type 0x0D) holds cell pointers at 8; a cell is the payload length
  (varint), the rowid (varint) and the record: its header length (varint), one serial
  type per column (varints), then the values. rosbag2's ``messages(id INTEGER PRIMARY
  KEY, topic_id INTEGER, timestamp INTEGER, data BLOB)`` stores ``id`` as NULL (the
  rowid), two big-endian integers and the blob (serial type ``12 + 2 * length``).

Anything else (another schema, a payload spilling to overflow pages, an unknown page
type, a write-ahead log beside the file) raises :class:`Untrusted`; the caller then
uses plain SQL.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from avar.io.bag_decode import words

INT_SIZES = np.array([0, 1, 2, 3, 4, 6, 8, 8, 0, 0, -1, -1], np.int64)  # serial types 0..11
COLUMNS = [("id", "INTEGER", 1), ("topic_id", "INTEGER", 0), ("timestamp", "INTEGER", 0), ("data", "BLOB", 0)]


class Untrusted(Exception):
    """The file is not laid out as this reader expects."""


def _be(buf: np.ndarray, pos: np.ndarray, size: int) -> np.ndarray:
    """Unsigned big-endian integers of ``size`` bytes at ``pos``, as int64."""
    if size in (1, 2, 4, 8):
        return words(buf, f">u{size}")[pos].astype(np.int64)
    value = np.zeros(len(pos), np.int64)
    for k in range(size):
        value = (value << 8) | buf[pos + k]
    return value


def _varint(buf: np.ndarray, pos: np.ndarray, most: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """SQLite varints (big-endian, 7 bits a byte, high bit = more) at ``pos``: values and lengths."""
    value = buf[pos].astype(np.int64)
    done = value < 0x80
    if done.all():  # one byte each: the usual case of serial types and header lengths
        return value, np.ones(len(pos), np.int64)
    value &= 0x7F
    length = np.ones(len(pos), np.int64)
    last = len(buf) - 1
    for k in range(1, most):
        byte = buf[np.minimum(pos + k, last)].astype(np.int64)
        value = np.where(done, value, (value << 7) | (byte & 0x7F))
        length = np.where(done, length, k + 1)
        done |= byte < 0x80
        if done.all():
            break
    if not done.all():
        raise Untrusted("long varint")
    return value, length


def _signed(buf: np.ndarray, pos: np.ndarray, types: np.ndarray) -> np.ndarray:
    """Integer values of serial types 1-9 (big-endian two's complement; 8 and 9 are 0 and 1)."""
    out = np.zeros(len(pos), np.int64)
    for kind in np.unique(types):
        rows = types == kind
        if kind in (8, 9):
            out[rows] = kind - 8
        elif 1 <= kind <= 6:
            size = int(INT_SIZES[kind])
            value = _be(buf, pos[rows], size)
            if size < 8:
                value = np.where(value >= 1 << (8 * size - 1), value - (1 << (8 * size)), value)
            out[rows] = value
        else:
            raise Untrusted("not an integer")
    return out


def check_schema(db) -> int:
    """The root page of rosbag2's ``messages`` table, after checking its columns."""
    info = [(row[1], row[2].upper(), row[5]) for row in db.execute("PRAGMA table_info(messages)")]
    if info != COLUMNS:
        raise Untrusted("schema")
    (root,) = db.execute("SELECT rootpage FROM sqlite_master WHERE type='table' AND name='messages'").fetchone()
    return int(root)


def _leaves(buf: np.ndarray, root: int, page: int) -> np.ndarray:
    level = np.array([root], np.int64)
    for _ in range(64):
        start = (level - 1) * page
        if np.any(start + page > len(buf)) or np.any(level < 2):
            raise Untrusted("page number")
        kinds = buf[start]
        if np.all(kinds == 0x0D):
            return level
        if not np.all(kinds == 0x05):
            raise Untrusted("page type")
        cells = _be(buf, start + 3, 2)
        owner = np.repeat(start, cells)
        index = np.arange(len(owner)) - np.repeat(np.cumsum(cells) - cells, cells)
        children = _be(buf, owner + _be(buf, owner + 12 + 2 * index, 2), 4)
        counts = cells + 1
        last = np.cumsum(counts) - 1
        following = np.empty(counts.sum(), np.int64)
        inner = np.ones(len(following), bool)
        inner[last] = False
        following[inner], following[last] = children, _be(buf, start + 8, 4)
        level = following
    raise Untrusted("depth")


class Messages(NamedTuple):
    """Where the messages of a db3 bag lie in its bytes, in rowid order (:func:`read_messages`)."""

    #: Offset (bytes) of each message in the file.
    starts: np.ndarray
    #: Length (bytes) of each message.
    lengths: np.ndarray
    #: The bag's receive time of each message (int64 ns).
    timestamps: np.ndarray


def read_messages(buf: np.ndarray, root: int, page: int, reserved: int, topics: set[int]) -> Messages:
    """The :class:`Messages` of ``topics`` in rowid order, in ``buf``."""
    leaves = _leaves(buf, root, page)
    block = max(1, (4 << 20) // page)  # pages read together: their bytes stay in the CPU's cache
    parts = [_cells(buf, leaves[lo:lo + block], page, reserved, topics) for lo in range(0, len(leaves), block)]
    if not parts:
        return Messages(np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, np.int64))
    return Messages(*(np.concatenate(column) for column in zip(*parts)))


def _cells(buf: np.ndarray, leaves: np.ndarray, page: int, reserved: int, topics: set[int]):
    start = (leaves - 1) * page
    cells = _be(buf, start + 3, 2)
    owner = np.repeat(start, cells)
    index = np.arange(len(owner)) - np.repeat(np.cumsum(cells) - cells, cells)
    cell = owner + _be(buf, owner + 8 + 2 * index, 2)
    payload, n1 = _varint(buf, cell)
    if np.any(payload > page - reserved - 35):  # the rest would be on overflow pages
        raise Untrusted("overflow")
    _, n2 = _varint(buf, cell + n1, 9)
    record = cell + n1 + n2
    head, h0 = _varint(buf, record)
    t_id, h1 = _varint(buf, record + h0)
    t_topic, h2 = _varint(buf, record + h0 + h1)
    t_time, h3 = _varint(buf, record + h0 + h1 + h2)
    t_data, h4 = _varint(buf, record + h0 + h1 + h2 + h3)
    if (np.any(t_id != 0) or np.any(h0 + h1 + h2 + h3 + h4 != head) or np.any(t_topic > 9) or np.any(t_time > 9)
            or np.any(t_data < 12) or np.any(t_data % 2)):
        raise Untrusted("record")
    size_topic, size_time = INT_SIZES[t_topic], INT_SIZES[t_time]
    lengths = (t_data - 12) // 2
    if np.any(size_topic < 0) or np.any(size_time < 0) or np.any(head + size_topic + size_time + lengths != payload):
        raise Untrusted("record")
    topic = _signed(buf, record + head, t_topic)
    keep = np.isin(topic, list(topics))
    at_time = (record + head + size_topic)[keep]
    stamps = _signed(buf, at_time, t_time[keep])
    return at_time + size_time[keep], lengths[keep], stamps
