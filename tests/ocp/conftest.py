"""Make the shared known-answer problems importable as ``problems``."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
