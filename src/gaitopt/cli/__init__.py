"""The ``gaitopt`` command line: the group with every command family registered, and ``main``.

What every command shares (the group, :class:`UserError`, the console, the option types and
the options used by several commands) is in :mod:`gaitopt.cli.base`. Each other module holds
one command family and registers its subcommands on the group when imported, which happens
when one of its commands is looked up (:data:`COMMANDS`):
:mod:`~gaitopt.cli.model` (``model show|export|import``), :mod:`~gaitopt.cli.gait`
(``solve``, ``verify``), :mod:`~gaitopt.cli.stability` (``stability``),
:mod:`~gaitopt.cli.simulate` (``simulate``),
:mod:`~gaitopt.cli.study` (``sweep``, ``study``) and :mod:`~gaitopt.cli.report`
(``report``, ``animate``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from gaitopt.cli.base import PIPE_WIDTH, USER_ERRORS, UserError, cli, make_console

#: Each command and the module that registers it, imported when the command is looked up
#: (``gaitopt solve`` imports neither the study's nor the figures' modules).
COMMANDS: dict[str, str] = {
    "model": "gaitopt.cli.model",
    "solve": "gaitopt.cli.gait",
    "verify": "gaitopt.cli.gait",
    "stability": "gaitopt.cli.stability",
    "simulate": "gaitopt.cli.simulate",
    "sweep": "gaitopt.cli.study",
    "study": "gaitopt.cli.study",
    "report": "gaitopt.cli.report",
    "animate": "gaitopt.cli.report",
}
cli.lazy_commands.update(COMMANDS)

#: Environment defaults of a ``gaitopt`` process (a value already set is kept). OpenBLAS,
#: which IPOPT's linear solver MUMPS calls, otherwise starts a thread per core whose waiting
#: only burns CPU on these small KKT systems: a full-coordinate ``gaitopt solve --knots
#: 40,10`` used 3.8-4.0 s of CPU (0.9-1.0 s of it system time) against 2.5-2.9 s with one
#: thread, at the same wall time (2.6-3.0 s); sweeps on two workers took the same time.
#: Set here, before the first solver loads the library, and inherited by sweep workers.
PROCESS_ENVIRONMENT: dict[str, str] = {"OPENBLAS_NUM_THREADS": "1"}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gaitopt`` console script; returns the exit status."""
    for name, value in PROCESS_ENVIRONMENT.items():
        os.environ.setdefault(name, value)
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="gaitopt",
                 standalone_mode=True)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return 0


__all__ = ["PIPE_WIDTH", "USER_ERRORS", "UserError", "cli", "main", "make_console"]
