"""The raw bytes of a topic's messages, read in bulk from ROS 1 ``.bag``, ``.db3`` and ``.mcap`` files.

Each reader lists its :class:`Connection` s (``id, topic, msgtype``) and yields
:class:`Batch` es (``buf, starts, lengths, receive_ns``): a uint8 buffer and, for each message,
where its serialized bytes start, their length and the bag's receive time (ns). Batches come in
file order; :func:`avar.io.bags.read_bag` sorts by receive time (stably, as the
``rosbags`` readers do). Anything these readers do not understand (an unknown
compression, an unindexed file, records not where the index says) raises
:class:`Untrusted`, and the caller decodes the bag message by message with ``rosbags``.

* ROS 1: the bag header, connection and chunk-info records are read with ``rosbags``'
  record readers; the index after each chunk (12 bytes per message: receive time and
  offset) is read with NumPy, and the chunk is decompressed once.
* ``.mcap``: ``rosbags``' reader gives the chunk index; each chunk's message index
  (16 bytes per message: log time and offset) is read with NumPy.
* ``.db3``: the ``messages`` table's B-tree read from the file with NumPy
  (:mod:`avar.io.bag_sqlite`), else one SQL query in row order.
"""

from __future__ import annotations

import mmap
import os
import sqlite3
import struct
from io import BytesIO
from pathlib import Path
from typing import NamedTuple

import numpy as np

from avar.io.bag_decode import words

BATCH_BYTES = 32 << 20  # decompressed chunks decoded together


class Connection(NamedTuple):
    """A topic's connection (ROS 1) or channel (ROS 2) in a bag."""

    id: int
    topic: str
    msgtype: str


class Batch(NamedTuple):
    """Messages read in bulk: their bytes in ``buf`` and, per message, where they lie and when the
    bag received it."""

    #: uint8 buffer holding the messages.
    buf: np.ndarray
    #: Offset (bytes) of each message's serialized data in ``buf``.
    starts: np.ndarray
    #: Length (bytes) of each message's serialized data.
    lengths: np.ndarray
    #: The bag's receive time of each message (int64 ns).
    receive_ns: np.ndarray


class Untrusted(Exception):
    """The bulk reader cannot vouch for this file; read it message by message."""


def _u32(buf: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """The little-endian uint32 at each position, as int64."""
    return words(buf, "<u4")[pos].astype(np.int64)


def _mapped(bio) -> np.ndarray:
    """The whole file as a read-only uint8 array (no copy; pages are read as touched).

    Files up to 4 GiB are read ahead by the kernel in one go (``MAP_POPULATE``), which
    is much faster than faulting their pages in one by one; larger ones are left to
    demand paging so as not to crowd the page cache.
    """
    size = os.fstat(bio.fileno()).st_size
    flags = mmap.MAP_SHARED | (getattr(mmap, "MAP_POPULATE", 0) if size <= 4 << 30 else 0)
    return np.frombuffer(mmap.mmap(bio.fileno(), 0, flags=flags, prot=mmap.PROT_READ), np.uint8)


class Ros1Bag:
    """A ROS 1 bag's connections and its messages' raw bytes (see the module notes)."""

    def __init__(self, path: Path):
        from rosbags.rosbag1 import Reader
        from rosbags.rosbag1.reader import Header, RecordType

        self.path = path
        self._reader = reader = Reader(path)
        reader.bio = bio = path.open("rb")
        magic = bio.readline(64)
        if not magic.startswith(b"#ROSBAG V2.0"):
            bio.close()
            raise Untrusted("no '#ROSBAG V2.0' line at its start")
        header = Header.read(bio, RecordType.BAGHEADER)
        index_pos, conn_count = header.get_uint64("index_pos"), header.get_uint32("conn_count")
        chunk_count = header.get_uint32("chunk_count")
        if index_pos == 0:
            raise Untrusted("unindexed")
        bio.seek(index_pos)
        self.connections_raw = [reader.read_connection() for _ in range(conn_count)]
        self.chunk_infos = [reader.read_chunk_info() for _ in range(chunk_count)]
        self.connections = [Connection(c.id, c.topic, c.msgtype) for c in self.connections_raw]

    def close(self) -> None:
        self._reader.bio.close()

    def _index(self, ids: set[int]):
        """Per chunk holding ``ids``: the chunk record and the (time, offset) of their messages."""
        from rosbags.rosbag1.reader import Header, RecordType, read_uint32

        reader, bio = self._reader, self._reader.bio
        entry = np.dtype([("sec", "<u4"), ("nsec", "<u4"), ("offset", "<u4")])
        for info in sorted(self.chunk_infos, key=lambda c: c.pos):
            if not ids & set(info.connection_counts):
                continue
            bio.seek(info.pos)
            chunk = reader.read_chunk()
            found = []
            for _ in range(len(info.connection_counts)):
                header = Header.read(bio, RecordType.IDXDATA)
                conn, count = header.get_uint32("conn"), header.get_uint32("count")
                size = read_uint32(bio)
                if size != 12 * count:
                    raise Untrusted("index size")
                data = bio.read(size)
                if conn in ids:
                    found.append((conn, np.frombuffer(data, entry)))
            yield chunk, found

    @staticmethod
    def _records(buf, pos, conn, times):
        """Start and length of the data of the message records at ``pos`` (checked against the index)."""
        from rosbags.rosbag1.reader import Header

        if np.any(np.diff(pos) < 0):  # file order: (chunk, offset), as rosbags sorts its index
            order = np.argsort(pos, kind="stable")
            pos, conn, times = pos[order], conn[order], times[order]
        head = _u32(buf, pos)
        if len(pos) == 0 or np.any(head != head[0]) or int(pos.max() + 8 + head[0]) > len(buf):
            raise Untrusted("record headers differ")
        first = bytes(buf[pos[0] + 4:pos[0] + 4 + head[0]])
        fields = Header.read(BytesIO(struct.pack("<I", len(first)) + first))
        at_op, at_conn = first.find(b"op=") + 3, first.find(b"conn=") + 5
        if fields.get_uint8("op") != 2 or at_op < 3 or at_conn < 5:
            raise Untrusted("not message records")
        if np.any(buf[pos + 4 + at_op] != 2) or np.any(_u32(buf, pos + 4 + at_conn) != conn):
            raise Untrusted("not message records")
        lengths = _u32(buf, pos + 4 + head[0])
        return Batch(buf, pos + 8 + head[0], lengths, times)

    def batches(self, ids: set[int]):
        from rosbags.rosbag1.reader import Compression, decompressors

        plain = decompressors[Compression.NONE.value]
        bio = self._reader.bio
        whole = None
        mapped = ([], [], [])  # uncompressed chunks: read in place from the mapped file
        packed, base = ([], [], [], []), 0  # compressed ones: decompressed, then decoded together
        for chunk, found in self._index(ids):
            compressed = chunk.decompressor is not plain
            if compressed:
                bio.seek(chunk.datapos)
                raw = chunk.decompressor(bio.read(chunk.datasize))
            elif whole is None:
                whole = _mapped(bio)
            offset, into = (base, packed) if compressed else (chunk.datapos, mapped)
            for conn, entries in found:
                into[0].append(offset + entries["offset"].astype(np.int64))
                into[1].append(np.full(len(entries), conn, np.int64))
                into[2].append(entries["sec"].astype(np.int64) * 1_000_000_000 + entries["nsec"])
            if compressed:
                packed[3].append(raw)
                base += len(raw)
                if base >= BATCH_BYTES:
                    buf = np.frombuffer(b"".join(packed[3]), np.uint8)
                    yield self._records(buf, *(np.concatenate(part) for part in packed[:3]))
                    packed, base = ([], [], [], []), 0
        if packed[0]:
            buf = np.frombuffer(b"".join(packed[3]), np.uint8)
            yield self._records(buf, *(np.concatenate(part) for part in packed[:3]))
        if mapped[0]:
            yield self._records(whole, *(np.concatenate(part) for part in mapped))


class McapBag:
    """A ``.mcap`` file's channels and its messages' raw bytes (see the module notes)."""

    def __init__(self, path: Path):
        from rosbags.rosbag2.storage_mcap import McapReader

        self.path = path
        self._reader = reader = McapReader(path)
        reader.open()
        self.connections = [Connection(c.id, c.topic, c.msgtype) for c in reader.connections]
        if any(ch.message_encoding != "cdr" for ch in reader.channels.values()):
            self.close()
            raise Untrusted("not CDR")

    def close(self) -> None:
        self._reader.close()

    def batches(self, ids: set[int]):
        from rosbags.rosbag2.storage_mcap import decompress

        reader = self._reader
        bio = reader.bio
        if not reader.chunks:
            raise Untrusted("unchunked")
        record = np.dtype([("time", "<u8"), ("offset", "<u8")])
        whole, mapped = None, ([], [])  # uncompressed chunks: read in place from the mapped file
        for chunk in sorted(reader.chunks, key=lambda c: c.chunk_start_offset):
            mine = [cid for cid in ids if chunk.channel_count.get(cid, 0)]
            if not mine:
                continue
            records = chunk.chunk_start_offset + 9 + 40 + len(chunk.compression)
            if chunk.compression:
                bio.seek(chunk.chunk_start_offset + 9 + 24)
                (crc,) = struct.unpack("<I", bio.read(4))
                bio.seek(records)
                buf = np.frombuffer(decompress(bio.read(chunk.compressed_size), chunk.compression,
                                               chunk.uncompressed_size, crc), np.uint8)
                base, pos, times = 0, [], []
            else:
                whole = _mapped(bio) if whole is None else whole
                buf, base, (pos, times) = whole, records, mapped
            for cid in mine:
                bio.seek(chunk.message_index_offsets[cid])
                op, _, channel, size = struct.unpack("<BQHI", bio.read(15))
                if op != 0x07 or channel != cid or size % 16:
                    raise Untrusted("message index")
                entries = np.frombuffer(bio.read(size), record)
                if len(entries) and int(entries["offset"].max()) + 31 > chunk.uncompressed_size:
                    raise Untrusted("offsets")
                pos.append(base + entries["offset"].astype(np.int64))
                times.append(entries["time"].astype(np.int64))
            if chunk.compression:
                yield self._records(buf, np.concatenate(pos), np.concatenate(times))
        if mapped[0]:
            yield self._records(whole, np.concatenate(mapped[0]), np.concatenate(mapped[1]))

    @staticmethod
    def _records(buf, start, times):
        if np.any(np.diff(start) < 0):  # file order within the chunk, as rosbags reads it
            order = np.argsort(start, kind="stable")
            start, times = start[order], times[order]
        lengths = _u32(buf, start + 1) | (_u32(buf, start + 5) << 32)
        if np.any(buf[start] != 0x05) or np.any(lengths < 22):
            raise Untrusted("not message records")
        return Batch(buf, start + 31, lengths - 22, times)


class Db3Bag:
    """A ROS 2 ``.db3`` (sqlite3) file's topics and its messages' raw bytes (see the module notes)."""

    def __init__(self, path: Path):
        self.path = path
        if Path(f"{path}-wal").exists():
            raise Untrusted("write-ahead log")
        self._db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            rows = self._db.execute("SELECT id, name, type, serialization_format FROM topics").fetchall()
        except sqlite3.DatabaseError as error:
            self.close()
            raise Untrusted(str(error)) from None
        if any(row[3] != "cdr" for row in rows):
            self.close()
            raise Untrusted("not CDR")
        self.connections = [Connection(*row[:3]) for row in rows]

    def close(self) -> None:
        self._db.close()

    def batches(self, ids: set[int]):
        from avar.io import bag_sqlite

        try:
            root = bag_sqlite.check_schema(self._db)
            (page,) = self._db.execute("PRAGMA page_size").fetchone()
            with self.path.open("rb") as bio:
                buf = _mapped(bio)
            yield Batch(buf, *bag_sqlite.read_messages(buf, root, int(page), int(buf[20]), ids))
            return
        except bag_sqlite.Untrusted:
            pass
        marks = ",".join("?" * len(ids))
        rows = self._db.execute(f"SELECT timestamp, data FROM messages WHERE topic_id IN ({marks}) ORDER BY id",
                                sorted(ids)).fetchall()
        n = len(rows)
        times = np.fromiter((row[0] for row in rows), np.int64, n)
        data = [row[1] for row in rows]
        del rows
        lengths = np.fromiter(map(len, data), np.int64, n)
        starts = np.zeros(n, np.int64)
        np.cumsum(lengths[:-1], out=starts[1:])
        yield Batch(np.frombuffer(b"".join(data), np.uint8), starts, lengths, times)
