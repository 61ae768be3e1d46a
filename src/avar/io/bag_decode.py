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

import numpy as np

#: Bytes from the first float64 (orientation.x) to the end of the message.
FLOATS = 296
GYRO, ACCEL = 104, 200
BLOCK = 1 << 16  # rows gathered at once (bounded temporary memory)


def _u32(buf: np.ndarray, pos: np.ndarray, big: np.ndarray | None = None) -> np.ndarray:
    """The uint32 at each byte position of ``buf`` (little endian, or big where ``big``)."""
    raw = buf[pos[:, None] + np.arange(4)]
    little = raw.view("<u4").reshape(len(pos))
    if big is None or not big.any():
        return little
    return np.where(big, raw.view(">u4").reshape(len(pos)), little)


def _record(big: bool, cdr: bool) -> np.dtype:
    e = ">" if big else "<"
    return np.dtype([("sec", e + ("i4" if cdr else "u4")), ("nsec", e + "u4"), ("v", e + "f8", (6,))])


def _gather(buf: np.ndarray, starts: np.ndarray, first: int, record: np.dtype) -> np.ndarray:
    """Stamp (bytes 4-12), gyro and accel of messages starting at ``starts`` with floats at ``first``.

    Runs of evenly spaced messages (the usual case: one topic's records back to back)
    are read through strided views; scattered ones are gathered byte by byte.
    """
    n = len(starts)
    out = np.empty(n, record)
    steps = np.diff(starts)
    step = int(np.median(steps)) if n > 1 else 1
    heads = np.concatenate([[0], np.flatnonzero(steps != step) + 1, [n]]) if n > 1 else np.array([0, n])
    if step > 0 and len(heads) < n // 8:
        base = record["v"].base
        fields = np.dtype({"names": ["sec", "nsec", "g", "a"],
                           "formats": [record["sec"], record["nsec"], (base, 3), (base, 3)],
                           "offsets": [4, 8, first + GYRO, first + ACCEL], "itemsize": first + ACCEL + 24})
        for lo, hi in zip(heads[:-1], heads[1:]):
            view = np.ndarray((hi - lo,), fields, buffer=buf, offset=int(starts[lo]), strides=(step,))
            part = out[lo:hi]
            part["sec"], part["nsec"] = view["sec"], view["nsec"]
            part["v"][:, :3], part["v"][:, 3:] = view["g"], view["a"]
        return out
    columns = np.concatenate([np.arange(4, 12), first + GYRO + np.arange(24), first + ACCEL + np.arange(24)])
    raw = out.view(np.uint8).reshape(n, 56)
    for lo in range(0, n, BLOCK):
        raw[lo:lo + BLOCK] = buf[starts[lo:lo + BLOCK, None] + columns]
    return out


def decode_imu(buf, starts, lengths, cdr: bool) -> tuple[np.ndarray, np.ndarray] | None:
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
    (values, stamps) or None when the layout cannot be trusted (see the module notes).

    Examples
    --------
    >>> import numpy as np
    >>> body = np.zeros(37, "<f8"); body[13:16] = [0.5, -1.0, 2.0]; body[25:28] = [0.0, 0.0, 9.81]
    >>> msg = np.array([7, 12, 500], "<u4").tobytes() + b"\\x02\\x00\\x00\\x00ab" + body.tobytes()
    >>> values, stamps = decode_imu(msg, [0], [len(msg)], cdr=False)
    >>> values.tolist(), stamps.tolist()
    ([[0.5, -1.0, 2.0, 0.0, 0.0, 9.81]], [12000000500])
    """
    buf = np.frombuffer(buf, np.uint8) if not isinstance(buf, np.ndarray) else buf
    starts = np.asarray(starts, np.int64)
    lengths = np.asarray(lengths, np.int64)
    n = len(starts)
    values, stamps = np.empty((n, 6)), np.empty(n, np.int64)
    if n == 0:
        return values, stamps
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
    for key in np.unique(keys):
        rows = np.flatnonzero(keys == key)
        record = _record(bool(key % 2), cdr)
        fields = _gather(buf, starts[rows], int(key // 2), record)
        values[rows] = fields["v"]
        stamps[rows] = fields["sec"].astype(np.int64) * 1_000_000_000 + fields["nsec"]
    return values, stamps
