"""Test configuration (doctests in src/ and tests/ alike).

Plots render headless. Nothing here reaches outside the repository: the data sets ship
inside the package.
"""

import os
import sys
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

# Shared test helpers (tests/reference.py) import as top-level modules.
sys.path.insert(0, str(Path(__file__).resolve().parent / "tests"))
