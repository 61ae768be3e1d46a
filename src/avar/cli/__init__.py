"""The ``avar`` command line; see :mod:`avar.cli.main`."""

from avar.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
