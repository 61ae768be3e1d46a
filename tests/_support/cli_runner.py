"""Run the command line in-process, as the CLI tests do."""

from __future__ import annotations

from avar.cli.first_run import NOTICE_START
from avar.cli.main import main


def cli(capsys, *args) -> tuple[int, str, str]:
    """``avar ARGS...`` in this process: the exit code and what it wrote to stdout and stderr.

    The first-run notice (printed when numba compiles, i.e. when this process meets a
    kernel signature that numba's cache does not hold yet) depends on which tests ran
    before, so it is left out of stderr here; tests/cli/test_first_run.py checks it.
    """
    try:
        code = main([str(a) for a in args])
    except SystemExit as stop:  # argparse's own usage errors
        code = stop.code
    out, err = capsys.readouterr()
    err = "".join(line for line in err.splitlines(keepends=True) if not line.startswith(NOTICE_START))
    return code, out, err
