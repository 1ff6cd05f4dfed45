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

import logging
import os
import signal
import sys
import threading
from collections.abc import Sequence

from gaitopt.cli.base import PIPE_WIDTH, USER_ERRORS, UserError, cli, make_console
from gaitopt.interrupts import TERMINATED_STATUS, terminate_as_interrupt, terminated

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


def show_progress_log() -> logging.Handler:
    """Show gaitopt's INFO log records (e.g. that point libraries are being compiled,
    :data:`gaitopt.ocp.pointwise.LOG`) on stderr, one plain line each; the handler (added
    once per process)."""
    log = logging.getLogger("gaitopt")
    for handler in log.handlers:
        if getattr(handler, "gaitopt_progress", False):
            return handler
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(message)s"))
    handler.gaitopt_progress = True  # type: ignore[attr-defined]
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    return handler


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gaitopt`` console script; returns the exit status.

    SIGTERM stops the command as Ctrl-C does (:mod:`gaitopt.interrupts`: a sweep writes what
    its workers returned and ends them), and the status is then
    :data:`~gaitopt.interrupts.TERMINATED_STATUS` (143) where Ctrl-C's is 130."""
    for name, value in PROCESS_ENVIRONMENT.items():
        os.environ.setdefault(name, value)
    show_progress_log()
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.getsignal(signal.SIGTERM)
    if main_thread:
        terminate_as_interrupt()
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="gaitopt",
                 standalone_mode=True)
    except SystemExit as exc:
        status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        return TERMINATED_STATUS if terminated() and status != 0 else status
    finally:
        if main_thread:  # a caller's own handler (main() called from Python) comes back
            signal.signal(signal.SIGTERM, previous)
    return 0


__all__ = ["PIPE_WIDTH", "USER_ERRORS", "UserError", "cli", "main", "make_console"]
