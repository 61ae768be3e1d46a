"""``avar demo``: simulate a sensor, compute and fit its Allan variance, plot it."""

from __future__ import annotations

import argparse
import struct
from pathlib import Path

import numpy as np

from avar.cli.common import UsageError, format_table
from avar.cli.outputs import plan_outputs, report

DEMO_FREQ = 100.0
DEMO_N = 100_000
DEMO_SCALES = {"wn": range(1, 8), "rw": range(12, 16)}
#: PNG text chunk that marks a figure this command wrote (so a second run may replace it).
MARK_KEY, MARK_VALUE = "Software", "avar demo"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def png_text(path: Path) -> dict[str, str]:
    """The ``tEXt`` chunks of a PNG file before its image data ({} if it is not a PNG).

    >>> png_text(Path("no such file.png"))
    {}
    """
    text: dict[str, str] = {}
    try:
        with path.open("rb") as stream:
            if stream.read(8) != PNG_MAGIC:
                return text
            while True:
                head = stream.read(8)
                if len(head) < 8:
                    break
                length, kind = struct.unpack(">I4s", head)
                if kind in (b"IDAT", b"IEND"):
                    break
                body = stream.read(length)
                stream.read(4)  # CRC
                if kind == b"tEXt":
                    key, _, value = body.partition(b"\0")
                    text[key.decode("latin-1")] = value.decode("latin-1")
    except OSError:
        return {}
    return text


def is_own_figure(path: Path) -> bool:
    """Whether ``path`` is a figure an earlier ``avar demo`` wrote (its PNG carries our mark)."""
    return png_text(path).get(MARK_KEY, "").startswith(MARK_VALUE)


def simulate_demo_series(n: int = DEMO_N, seed: int = 2024) -> np.ndarray:
    """White noise (sigma2 = 1) plus a random walk (gamma2 = 1e-6), per sample."""
    from avar.models import RW, WN

    return (WN(sigma2=1.0) + RW(gamma2=1e-6)).simulate(n, seed=seed)


def run(args: argparse.Namespace) -> int:
    from avar.fit.avlr import avlr
    from avar.stability.allan.estimator import avar

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} is a file; give a directory for avar_demo.png")
    out.mkdir(parents=True, exist_ok=True)
    figure = out / "avar_demo.png"
    # Our own earlier figure is replaced; any other existing file is refused unless --force.
    force = args.force or (figure.is_file() and is_own_figure(figure))
    plan = plan_outputs(figure=str(figure), force=force, figure_option="--out")
    x = simulate_demo_series()
    result = avar(x, "mo", DEMO_FREQ)
    fit = avlr(result, **DEMO_SCALES)
    from avar import __version__

    written = plan.write(figure=lambda: fit.plot(decomp=True),
                         metadata={MARK_KEY: f"{MARK_VALUE} (avar {__version__})"})
    report(written, "\n".join([
        f"Simulated {DEMO_N} samples of white noise + random walk at {DEMO_FREQ:g} Hz",
        result.describe(),
        format_table(result.summary().reset_index()),  # with the Scale numbers the fit uses
        "",
        str(fit),
        "",
    ]))
    return 0


def add_parser(commands) -> None:
    demo = commands.add_parser(
        "demo", help="simulate a sensor, compute and fit its Allan variance, plot it",
        description=f"Simulate {DEMO_N} samples of white noise plus a random walk at {DEMO_FREQ:g} Hz, compute "
                    "their Allan variance, fit it by AVLR and write the figure avar_demo.png.")
    demo.add_argument("--out", default=".", metavar="DIR", help="directory for avar_demo.png (default: .)")
    demo.add_argument("--force", action="store_true",
                      help="replace an existing avar_demo.png that an earlier avar demo did not write (default: refuse)")
    demo.set_defaults(handler=run)
