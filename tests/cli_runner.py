"""Run the command line in-process, as the CLI tests do."""

from __future__ import annotations

from avar.cli.main import main


def cli(capsys, *args) -> tuple[int, str, str]:
    """``avar ARGS...`` in this process: the exit code and what it wrote to stdout and stderr."""
    try:
        code = main([str(a) for a in args])
    except SystemExit as stop:  # argparse's own usage errors
        code = stop.code
    out, err = capsys.readouterr()
    return code, out, err
