"""``python -m gaitopt.cli``: the same as the ``gaitopt`` command (and ``python -m gaitopt``)."""

import sys

from gaitopt.cli import main

sys.exit(main())
