"""Run ``avar`` as a real subprocess (``python -m avar``), optionally with a bounded address space."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path
from typing import NamedTuple

ROOT = Path(__file__).resolve().parents[2]


class Run(NamedTuple):
    """What one ``avar`` process did."""

    code: int
    stdout: str
    stderr: str
    seconds: float


def run_avar(*args, cwd: Path | None = None, env: dict[str, str] | None = None,
             address_space: int | None = None, timeout: float = 120.0) -> Run:
    """``python -m avar ARGS...``: its exit code, stdout, stderr (text) and wall time.

    ``address_space`` (bytes) caps the process with ``RLIMIT_AS``, so that a run which would
    allocate more dies of it (MemoryError) instead of swapping; ``env`` adds variables.
    """
    def limit() -> None:
        if address_space is not None:
            import resource

            resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    environment = {**os.environ, **(env or {})}
    environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "src"), environment.get("PYTHONPATH")]))
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "avar", *map(str, args)], capture_output=True, cwd=cwd,
                          env=environment, preexec_fn=limit, timeout=timeout)
    text = [stream.decode("utf-8", "backslashreplace") for stream in (done.stdout, done.stderr)]
    return Run(done.returncode, text[0], text[1], time.perf_counter() - started)
