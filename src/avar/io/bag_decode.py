"""``sensor_msgs/msg/Imu`` messages decoded in bulk from their serialized bytes.

A message of one type has a fixed layout once the length of its ``header.frame_id``
is known, so the fields of many messages are read with NumPy at fixed offsets
instead of deserializing each message in Python.

ROS 1 serialization (little endian, no alignment)::

    0   uint32 seq
    4   uint32 stamp.sec, 8 uint32 stamp.nsec
    12  uint32 L, then L bytes of frame_id
    f = 16 + L: orientation (4 float64), its covariance (9), angular_velocity (3 float64)
        at f + 104, its covariance (9), linear_acceleration (3 float64) at f + 200,
        its covariance (9); the message is f + 296 bytes.

CDR (ROS 2): a 4-byte encapsulation header (``00 01`` little endian, ``00 00`` big
endian, then 2 option bytes), then ``int32 sec`` at 4, ``uint32 nanosec`` at 8, the
frame_id's ``uint32 L`` (counting its NUL) at 12 and its L bytes; the float64 fields
start at the next multiple of 8 counted from byte 4: ``f = 4 + 8 * ceil((12 + L) / 8)``,
and then follow the ROS 1 offsets above.

A message whose length is not the one its frame_id implies, or whose encapsulation is
not plain CDR, makes the whole batch untrusted (``None``): the caller decodes such
a bag message by message.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Bytes from the first float64 (orientation.x) to the end of the message.
FLOATS = 296
GYRO, ACCEL = 104, 200
BLOCK = 1 << 13  # messages read together


def words(buf: np.ndarray, dtype: str) -> np.ndarray:
    """A read-only view of ``buf`` holding, at every byte offset, the ``dtype`` value that starts there.

    ``words(buf, "<f8")[positions]`` gathers unaligned float64 at arbitrary offsets in one
    indexing operation (overlapping windows, no copy of ``buf``).

    >>> import numpy as np
    >>> buf = np.frombuffer(bytes([0, 1, 0, 0, 0, 2]), np.uint8)
    >>> words(buf, "<u4")[[1]].tolist(), words(buf, ">u2")[[4]].tolist()
    ([1], [2])
    """
    dt = np.dtype(dtype)
    if len(buf) < dt.itemsize:
        return np.empty(0, dt)
    windows = np.lib.stride_tricks.as_strided(buf, shape=(len(buf) - dt.itemsize + 1, dt.itemsize),
                                              strides=(1, 1), writeable=False)
    return windows.view(dt)[:, 0]


def _u32(buf: np.ndarray, pos: np.ndarray, big: np.ndarray | None = None) -> np.ndarray:
    """The uint32 at each byte position of ``buf`` (little endian, or big where ``big``)."""
    little = words(buf, "<u4")[pos]
    if big is None or not big.any():
        return little
    return np.where(big, words(buf, ">u4")[pos], little)


def _fields(buf: np.ndarray, starts: np.ndarray, first: int, big: bool, cdr: bool):
    """Gyro and accel (n, 6) and stamps of messages at ``starts`` whose floats begin at ``first``."""
    e = ">" if big else "<"
    floats, secs, nsecs = words(buf, e + "f8"), words(buf, e + ("i4" if cdr else "u4")), words(buf, e + "u4")
    values, stamps = np.empty((len(starts), 6)), np.empty(len(starts), np.int64)
    for lo in range(0, len(starts), BLOCK):  # a block's messages stay in the CPU's cache for all 8 reads
        at = starts[lo:lo + BLOCK]
        for k, offset in enumerate((GYRO, GYRO + 8, GYRO + 16, ACCEL, ACCEL + 8, ACCEL + 16)):
            values[lo:lo + BLOCK, k] = floats[at + (first + offset)]
        stamps[lo:lo + BLOCK] = secs[at + 4].astype(np.int64) * 1_000_000_000 + nsecs[at + 8]
    return values, stamps


class ImuMessages(NamedTuple):
    """The fields avar reads from serialized sensor_msgs/Imu messages (:func:`decode_imu`)."""

    #: (n, 6) float64: angular velocity x, y, z (rad/s), linear acceleration x, y, z (m/s^2).
    values: np.ndarray
    #: (n,) int64: header stamps (ns).
    stamps: np.ndarray


def decode_imu(buf, starts, lengths, cdr: bool) -> ImuMessages | None:
    """Gyro and accel (n, 6) float64 and header stamps (n,) int64 ns of serialized Imu messages.

    Parameters
    ----------
    buf : bytes-like or uint8 ndarray
        Bytes holding the messages.
    starts, lengths : array of int
        Offset and length (bytes) of each message in ``buf``.
    cdr : bool
        CDR (ROS 2) rather than ROS 1 serialization.

    Returns
    -------
    ImuMessages or None
        ``values`` and ``stamps``; None when the layout cannot be trusted (see the module notes).

    Examples
    --------
    >>> import numpy as np
    >>> body = np.zeros(37, "<f8"); body[13:16] = [0.5, -1.0, 2.0]; body[25:28] = [0.0, 0.0, 9.81]
    >>> msg = np.array([7, 12, 500], "<u4").tobytes() + b"\\x02\\x00\\x00\\x00ab" + body.tobytes()
    >>> decoded = decode_imu(msg, [0], [len(msg)], cdr=False)
    >>> decoded.values.tolist(), decoded.stamps.tolist()
    ([[0.5, -1.0, 2.0, 0.0, 0.0, 9.81]], [12000000500])
    """
    buf = np.frombuffer(buf, np.uint8) if not isinstance(buf, np.ndarray) else buf
    starts = np.asarray(starts, np.int64)
    lengths = np.asarray(lengths, np.int64)
    n = len(starts)
    values, stamps = np.empty((n, 6)), np.empty(n, np.int64)
    if n == 0:
        return ImuMessages(values, stamps)
    if lengths.min() < 16 + FLOATS or int((starts + lengths).max()) > len(buf) or starts.min() < 0:
        return None
    big = None
    if cdr:
        kind = buf[starts].astype(np.int64) * 256 + buf[starts + 1]
        if not np.all((kind == 0) | (kind == 1)):  # PL_CDR, XCDR2...: not this layout
            return None
        big = kind == 0
    size = _u32(buf, starts + 12, big).astype(np.int64)
    first = 4 + (12 + size + 7) // 8 * 8 if cdr else 16 + size
    if (cdr and size.min() < 1) or np.any(lengths != first + FLOATS):
        return None
    keys = first * 2 + (big if big is not None else 0)
    groups = np.unique(keys)
    if len(groups) == 1:  # one frame_id length and byte order: no regrouping
        return ImuMessages(*_fields(buf, starts, int(groups[0] // 2), bool(groups[0] % 2), cdr))
    for key in groups:
        rows = np.flatnonzero(keys == key)
        values[rows], stamps[rows] = _fields(buf, starts[rows], int(key // 2), bool(key % 2), cdr)
    return ImuMessages(values, stamps)
