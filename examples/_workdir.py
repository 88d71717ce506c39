"""Working directory of the examples: each example writes its files there and runs in it."""

import os
import sys
import tempfile
from pathlib import Path


def enter() -> Path:
    """Change into the directory named by the first command-line argument (created if
    needed; default: a new temporary directory) and return it."""
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="atomnav-example-"))
    path.mkdir(parents=True, exist_ok=True)
    os.chdir(path)
    return path
