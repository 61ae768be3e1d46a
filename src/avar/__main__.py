"""``python -m avar``: the command line."""

import sys

from avar.cli import main

sys.exit(main())
