"""Test configuration (doctests in src/ and tests/ alike).

``AVAR_DATA_DIR`` points at ``../shared/data`` beside the repository (unless
it is already set), so no test touches the network; plots render headless.
"""

import os
from pathlib import Path

SHARED_DATA = Path(__file__).resolve().parent.parent / "shared" / "data"

if not os.environ.get("AVAR_DATA_DIR"):
    os.environ["AVAR_DATA_DIR"] = str(SHARED_DATA)
os.environ.setdefault("MPLBACKEND", "Agg")
