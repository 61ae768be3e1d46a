"""The ``avar`` command line: the parser and the exit codes.

Subcommands (one module each): ``demo``, ``compute``, ``deviation``, ``fit``, ``report``, ``clock-report``, ``simulate``,
``datasets``.
Problems with the user's files end with a one-line message on stderr and exit
code 1; usage errors with exit code 2. Nothing here computes: the subcommands
read, call the library and write.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import threading
import warnings

from avar._validation import cap_text
from avar.cli import compute, datasets, demo, fit, warmup
from avar.cli.clock import clock_report, deviation
from avar.cli.common import InputFileError, UsageError, printable, resolve_aliases
from avar.cli.first_run import COMPILE_SECONDS, compile_notice
from avar.cli.imu import report, simulate
from avar.cli.outputs import remove_pending

SUBCOMMANDS = (demo, compute, deviation, fit, report, clock_report, simulate, datasets, warmup)
SCALE_OPTIONS = frozenset(f"--{name}{suffix}" for name, _ in fit.PROCESSES for suffix in ("", "-gyro", "-acc"))
#: Seconds between the main thread's checks for Ctrl-C while the worker runs.
WAIT_STEP = 0.1
NEGATIVE_VALUE = re.compile(r"^-\d[\d:,]*$")


class Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors (exit code 2)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    from avar import __version__

    parser = Parser(prog="avar", description="Allan variance and AVLR noise model estimation")
    parser.add_argument("--version", action="version", version=f"avar {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for subcommand in SUBCOMMANDS:
        subcommand.add_parser(commands)
    return parser


def _attach_negative_values(argv: list[str]) -> list[str]:
    """``--wn -3:2`` -> ``--wn=-3:2``, so that a negative scale is reported as one, not as a missing value."""
    out: list[str] = []
    for token in argv:
        if out and out[-1] in SCALE_OPTIONS and NEGATIVE_VALUE.match(token):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def _repeated_option(parser: argparse.ArgumentParser, command: str, argv: list[str]) -> str | None:
    """The first single-valued option given twice (argparse would silently keep the last)."""
    subparser = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    single = {option for action in subparser._actions if isinstance(action, argparse._StoreAction)
              for option in action.option_strings}
    seen: set[str] = set()
    for token in argv:
        if token == "--":
            break
        option = token.split("=", 1)[0]
        if option in single:
            if option in seen:
                return option
            seen.add(option)
    return None


def _quiet_stdout() -> None:
    """Point stdout at /dev/null, so that flushing it at exit does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def _run_interruptibly(handler, args: argparse.Namespace) -> tuple[int, threading.Thread]:
    """Run the subcommand in a worker thread while the main thread waits for Ctrl-C.

    The kernels release the GIL, so the main thread sees an interrupt within a
    fraction of a second even during a long computation; exceptions of the
    subcommand are raised here.
    """
    outcome: dict[str, object] = {}

    def target() -> None:
        try:
            outcome["code"] = handler(args)
        except BaseException as error:  # handed to the main thread
            outcome["error"] = error

    worker = threading.Thread(target=target, name="avar-command", daemon=True)
    worker.start()
    while worker.is_alive():
        worker.join(WAIT_STEP)
    if "error" in outcome:
        raise outcome["error"]  # type: ignore[misc]
    return outcome["code"], worker  # type: ignore[return-value]


def _interrupted() -> int:
    """One line and exit code 130; temporary files of an unfinished write are removed."""
    remove_pending()
    print("avar: interrupted", file=sys.stderr, flush=True)
    if threading.active_count() > 1:  # a kernel still runs in the worker: do not wait for it
        try:
            sys.stdout.flush()
        except (OSError, ValueError):
            pass
        os._exit(130)
    return 130


def _standard_streams() -> None:
    """Give closed standard streams (``avar ... >&-``, ``2>&-``) a /dev/null in their place.

    A closed descriptor 1 or 2 would otherwise be reused by the next file opened
    (an output would receive the printed table), and Python leaves ``sys.stdout``
    None (printing raises). The files are written all the same; what would have
    been printed is discarded.
    """
    try:
        import fcntl
    except ImportError:  # not a POSIX system
        return
    for fd, name in ((1, "stdout"), (2, "stderr")):
        try:
            usable = fcntl.fcntl(fd, fcntl.F_GETFL) & os.O_ACCMODE != os.O_RDONLY
        except OSError:  # closed
            usable = False
        if usable:
            continue
        try:
            opened = os.open(os.devnull, os.O_WRONLY)
        except OSError:
            continue
        if opened != fd:
            os.dup2(opened, fd)
            os.close(opened)
        setattr(sys, name, open(fd, "w", closefd=False))


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning of any library as one line of ours on stderr: no source line, no file path."""
    text = str(message).strip().splitlines()
    print(f"avar: warning: {printable(cap_text(text[0] if text else category.__name__))}", file=sys.stderr, flush=True)


def main(argv: list[str] | None = None) -> int:
    with warnings.catch_warnings():
        warnings.showwarning = show_warning
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    _standard_streams()
    argv = _attach_negative_values(list(sys.argv[1:] if argv is None else argv))
    parser = build_parser()
    args = parser.parse_args(argv)
    args.command_line = ["avar", *argv]  # as given, for outputs that record how they were made
    repeated = _repeated_option(parser, args.command, argv)
    if repeated:
        print(f"avar {args.command}: error: {repeated} is given twice; give it once "
              "(e.g. --wn 1:3,5 for several scales)", file=sys.stderr)
        return 2
    try:
        notes = resolve_aliases(args)
    except UsageError as error:
        print(f"avar {args.command}: error: {printable(error)}", file=sys.stderr)
        return 2
    for note in notes:
        print(f"avar {args.command}: {note}", file=sys.stderr)
    try:
        if args.command in COMPILE_SECONDS:  # the subcommands that run kernels: say so if they compile
            with compile_notice(args.command):
                code, _ = _run_interruptibly(args.handler, args)
        else:
            code, _ = _run_interruptibly(args.handler, args)
        return code
    except KeyboardInterrupt:
        return _interrupted()
    except BrokenPipeError:  # stdout piped into e.g. head, which closed it: files are already written
        _quiet_stdout()
        return 0
    except UsageError as error:
        print(f"avar {args.command}: error: {printable(error)}", file=sys.stderr)
        return 2
    except (InputFileError, ValueError, TypeError, OSError, MemoryError) as error:
        print(f"avar: error: {printable(cap_text(str(error) or type(error).__name__))}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
