"""``python -m gaitopt``: the same as the ``gaitopt`` command."""

import sys

from gaitopt.cli import main

sys.exit(main())
