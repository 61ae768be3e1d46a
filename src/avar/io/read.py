"""``avar.read``: a log file as a :class:`avar.Recording` or an :class:`avar.IMU`."""

from __future__ import annotations

import errno
import lzma
import os
import stat
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import MIN_SAMPLES
from avar._vocabulary import check_rate, renamed
from avar.imu import IMU
from avar.io.matlab import read_mat
from avar.io.npy import read_npy, read_npz
from avar.io.parquet import is_parquet, read_parquet
from avar.io.streams import CountingReader, compression_of, format_bytes, memory_limit, progress_enabled
from avar.io.text import Layout, clip, numeric_column, read_columns
from avar.io.timecols import rate_of, time_columns
from avar.recording import Recording

#: File suffixes read as ROS bags (a ROS 2 bag may also be its directory).
BAG_SUFFIXES = (".bag", ".db3", ".mcap")
#: Bytes per value of a typical text log (to decide on a progress bar before reading).
TEXT_BYTES_PER_VALUE = 10
GAP_POLICIES = ("error", "ignore")


class InputFileError(ValueError):
    """A file that cannot be read as numeric series (missing, malformed, bad values)."""


def check_path(path: Any) -> Path:
    """An existing regular file (or ROS 2 bag directory), with a message that says what is wrong."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name (str or Path), got {type(path).__name__}")
    path = Path(path)
    try:
        info = path.stat()
    except OSError as error:
        if error.errno == errno.ELOOP:
            raise InputFileError(f"{path}: a loop of symbolic links (each points, in the end, to itself)") from None
        if error.errno in (errno.ENOENT, errno.ENOTDIR):
            raise InputFileError(f"{path}: no such file") from None
        raise InputFileError(f"{path}: cannot be read ({error.strerror})") from None
    if stat.S_ISDIR(info.st_mode):
        if (path / "metadata.yaml").is_file():
            return path  # a ROS 2 bag directory
        raise InputFileError(f"{path}: is a directory, not a file")
    if not stat.S_ISREG(info.st_mode):
        raise InputFileError(f"{path}: not a regular file")
    return path


def _out_of_memory(source: Path) -> InputFileError:
    limit = memory_limit()
    return InputFileError(f"{source}: ran out of memory while reading it (at most {format_bytes(limit.size)}: "
                          f"{limit.meaning})")


def _text_columns(path: Path, progress: bool | None) -> tuple[dict[str, Any], Layout]:
    size = path.stat().st_size
    if not progress_enabled(progress, size / TEXT_BYTES_PER_VALUE):
        table, layout = read_columns(path)
    else:
        from tqdm import tqdm

        with path.open("rb") as raw, tqdm(total=size, desc=f"reading {path.name}", unit="B", unit_scale=True,
                                          file=sys.stderr, leave=False) as bar:
            table, layout = read_columns(path, raw=CountingReader(raw, bar))  # counts the file's (compressed) bytes
    return table, layout


def _selection(names: Sequence[str], times: list[str], columns: Any, gyro: Any, accel: Any, source: Path) -> list[str]:
    """The data columns: those asked for (never a time column), else all but the time columns."""
    def as_list(value: Any, role: str) -> list[str]:
        if value is None:
            return []
        items = [value] if isinstance(value, str) else list(value)
        if not all(isinstance(item, str) for item in items):
            raise TypeError(f"{role} must be a column name or a list of names, got {value!r}")
        return items

    columns, gyro, accel = as_list(columns, "columns"), as_list(gyro, "gyro"), as_list(accel, "accel")
    if columns and (gyro or accel):
        raise ValueError(
            "columns cannot be combined with gyro/accel: gyro and accel name the IMU's channels "
            f"(got columns={columns}, gyro={gyro}, accel={accel})"
        )
    wanted = columns or gyro + accel
    unknown = [name for name in wanted if name not in names]
    if unknown:
        raise InputFileError(f"{source}: unknown column(s) {clip(unknown)}; the file has {clip(list(names))}")
    timed = [name for name in wanted if name in times]
    if timed:
        raise InputFileError(f"{source}: column(s) {timed} are time columns; a time column is never data")
    repeated = sorted({name for name in wanted if wanted.count(name) > 1})
    if repeated:
        raise ValueError(f"column(s) {repeated} named twice")
    if not wanted:
        wanted = [name for name in names if name not in times]
    if not wanted:
        raise InputFileError(f"{source}: no data column besides the time column(s) {times}")
    return wanted


def _check_other_clocks(table: Any, times: list[str], rate: float, time_unit: Any, source: Path) -> None:
    """Two time columns that give different rates (100 Hz ``time``, 50 Hz ``timestamp``) are a
    conflict the user must settle (``time_column=`` or ``--rate``); one whose rate cannot be
    read (a whole-seconds ``sec`` column) is not a clock of the samples and is left alone."""
    for name in times[1:]:
        try:
            other = rate_of(table[name], name, time_unit, "ignore")["rate"]
        except ValueError:
            continue
        if abs(other - rate) > 0.01 * rate:
            raise InputFileError(
                f"{source}: the time columns {clip(times[0], 60)} ({rate:.6g} Hz) and {clip(name, 60)} "
                f"({other:.6g} Hz) disagree; name the clock of the samples (time_column=...) or pass the rate "
                "(rate=..., --rate)")


def read(
    path: str | os.PathLike,
    columns: str | Sequence[str] | None = None,
    *,
    rate: float | None = None,
    time_column: str | None = None,
    time_unit: str | None = None,
    gaps: str = "error",
    gyro: str | Sequence[str] | None = None,
    accel: str | Sequence[str] | None = None,
    topic: str | None = None,
    progress: bool | None = None,
    freq: float | None = None,
    nan_policy: str = "raise",
) -> Recording | IMU:
    """Read a log: a text table, a ``.npy`` array or ``.npz`` archive, a Parquet table, a MATLAB file, or a ROS bag.

    Parameters
    ----------
    path : str or Path
        CSV / TSV / semicolon-separated (decimal commas) / whitespace-separated text,
        with or without a header row (a ``# time gx gy`` comment line is a header);
        gzip/bzip2/xz compressed or not; ``.npy`` (plain or structured); ``.npz``
        (equal-length 1-D arrays named by their keys beside at most one array and
        the names of its columns; see :mod:`avar.io.npy`); Parquet (needs pyarrow,
        see :mod:`avar.io.parquet`); MATLAB ``.mat`` v4-v7 (:mod:`avar.io.matlab`);
        a ROS 1 ``.bag`` or ROS 2 ``.db3``/``.mcap``
        bag (see :func:`avar.io.bags.read_bag`; needs ``allanvar[ros]``).
    columns : str or list of str, optional
        Data columns to keep (default: all but the time columns). A time column is
        never data.
    rate : float, optional
        Sampling rate in Hz; default: from the time column, else 1 Hz.
    time_column : str, optional
        The column that times the samples (default: the first column named like a
        time, see :mod:`avar.io.timecols`).
    time_unit : {"s", "ms", "us", "ns"}, optional
        Unit of a numeric time column (default: from its name, e.g. ``t_ns``,
        ``timestamp (ms)``; else seconds, or the unit of epoch stamps by their size).
    gaps : {"error", "ignore"}
        Time steps longer than 1.5 median steps are gaps: refused (the message gives
        their count and the first row and time), or accepted with the samples treated
        as contiguous (``Recording.gaps_ignored``).
    gyro, accel : str or list of str, optional
        Gyroscope and accelerometer columns: the result is then an :class:`avar.IMU`.
    topic : str, optional
        The ``sensor_msgs/msg/Imu`` topic of a bag (optional when it holds one).
    progress : bool, optional
        Show a progress bar on stderr (default: when it is a terminal and the input
        holds more than ~10^7 values).
    nan_policy : {"raise", "omit"}
        NaN values and empty cells of the data columns: an error naming the first
        (``"raise"``), or kept as NaN (``"omit"``): gaps that ``avar.avar(...,
        nan_policy="omit")`` and the deviations skip. Infinite values are always an error.

    Returns
    -------
    Recording or IMU
        The rate is 1 / the mean time step between gaps (the median step finds the
        gaps; see :func:`avar._time_steps.analyze_steps`); ``Recording.rate_note()``
        says where it came from and the jitter.

    Raises
    ------
    InputFileError (a ValueError)
        A missing file or a directory, malformed tables, cells that are not numbers
        (with their row and line), unknown or time columns asked as data, gaps; an
        input whose data would take more memory than this process has (or than
        ``AVAR_MAX_INPUT_BYTES`` allows), said before anything is allocated.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> path = os.path.join(tempfile.mkdtemp(), "log.txt")
    >>> t = np.arange(1000) / 200.0
    >>> np.savetxt(path, np.column_stack([t, np.sin(t), np.cos(t)]), header="time gx gy")
    >>> rec = read(path)
    >>> rec.names, rec.n
    (('gx', 'gy'), 1000)
    >>> rec.rate_note()
    "at 200 Hz from time column 'time' (jitter ... rms)"
    """
    if nan_policy not in ("raise", "omit"):
        raise ValueError(f"nan_policy must be 'raise' (NaN and empty cells are an error) or 'omit' (kept as NaN, "
                         f"gaps the statistics skip), got {nan_policy!r}")
    if gaps not in GAP_POLICIES:
        raise ValueError(f"gaps must be one of {GAP_POLICIES}, got {gaps!r}")
    if time_unit is not None and time_unit not in ("s", "ms", "us", "ns"):
        raise ValueError(f"time_unit must be 's', 'ms', 'us' or 'ns', got {time_unit!r}")
    rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=True)
    rate = None if rate is None else check_rate(rate, rate_name)
    source = check_path(path)
    if source.suffix.lower() in BAG_SUFFIXES or source.is_dir():
        from avar.io.bags import read_bag

        if columns is not None or gyro is not None or accel is not None:
            raise ValueError("a bag's Imu topic gives the channels; columns, gyro and accel apply to tables only")
        try:
            return read_bag(source, topic=topic, rate=rate, gaps=gaps, progress=progress)
        except ValueError as error:
            raise InputFileError(str(error)) from None
        except Exception as error:  # the bag library's own errors: a corrupt or unknown bag
            if not type(error).__module__.startswith("rosbags"):
                raise
            raise InputFileError(f"{source}: not a readable ROS bag ({clip(str(error))})") from None
    if topic is not None:
        raise ValueError(f"topic applies to ROS bags ({', '.join(BAG_SUFFIXES)}); {source} is not one")
    if source.suffix.lower() in (".npy", ".npz", ".mat") or is_parquet(source):
        reader = {".npy": read_npy, ".npz": read_npz, ".mat": read_mat}.get(source.suffix.lower(), read_parquet)
        try:
            table, layout = reader(source), None
        except ValueError as error:
            raise InputFileError(str(error)) from None
        except MemoryError:  # what no declared size foretold
            raise _out_of_memory(source) from None
    else:
        try:
            table, layout = _text_columns(source, progress)
        except InputFileError:
            raise
        except ValueError as error:
            text = str(error) if len(str(error)) <= 400 else f"{str(error)[:400]}... (message cut)"
            raise InputFileError(text if text.startswith(str(source)) else f"{source}: {text}") from None
        except MemoryError:  # a line too long for the memory left, say
            raise _out_of_memory(source) from None
        except (EOFError, OSError, lzma.LZMAError) as error:  # the decompressor's: truncated or corrupt
            module = compression_of(source)
            if module is None:
                raise
            raise InputFileError(f"{source}: a damaged {module.__name__} file ({clip(str(error))})") from None
    names = list(table)
    times = time_columns(names)
    if time_column is not None:
        if time_column not in names:
            raise InputFileError(f"{source}: no time column {time_column!r}; the file has {clip(names)}")
        times = [time_column, *(name for name in times if name != time_column)]
    wanted = _selection(names, times, columns, gyro, accel, source)
    n = len(table[wanted[0]])
    if n < MIN_SAMPLES:
        raise InputFileError(f"{source}: {n} sample(s); the Allan variance needs at least {MIN_SAMPLES}")
    data = {}
    for name in wanted:
        try:
            values = (numeric_column(table[name], name, layout, source, gaps=nan_policy == "omit") if layout
                      else np.asarray(table[name]))
        except ValueError as error:
            raise InputFileError(str(error)) from None
        except Exception as error:  # the bag library's own errors: a corrupt or unknown bag
            if not type(error).__module__.startswith("rosbags"):
                raise
            raise InputFileError(f"{source}: not a readable ROS bag ({clip(str(error))})") from None
        bad = (np.isinf(values) if nan_policy == "omit" else ~np.isfinite(values)) if values.dtype.kind == "f" else None
        if layout is None and bad is not None and bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise InputFileError(f"{source}: column {name!r} has a{'n' if nan_policy == 'omit' else ' NaN or'} "
                                 f"infinite value in row {row + 1}")
        values = values.view()
        values.flags.writeable = False
        data[name] = values
    if rate is not None:
        timing = {"rate": rate, "rate_source": "given", "time_column": None}
    elif times:
        try:
            timing = rate_of(table[times[0]], times[0], time_unit, gaps)
        except ValueError as error:
            raise InputFileError(f"{source}: {error}") from None
        if time_column is None:
            _check_other_clocks(table, times, timing["rate"], time_unit, source)
    else:
        timing = {"rate": 1.0, "rate_source": "no time column: 1 Hz, sample numbers as time"}
    if gyro is not None or accel is not None:
        frame = pd.DataFrame(data, copy=False)
        return IMU(frame, timing["rate"], gyro=gyro, accel=accel, name=source.stem)
    return Recording(data, source=str(source), **timing)
