"""SIGTERM handled like Ctrl-C: what lets a polite kill (a batch scheduler's, ``kill PID``)
stop a ``gaitopt`` process as cleanly as Ctrl-C does.

With Python's default SIGTERM a process dies at once: a sweep's worker processes were left
running without a parent until their points ended (minutes for a cold solve with feet), and
the points they had returned but the driver had not yet written were lost. Where
:func:`terminate_as_interrupt` is installed (the ``gaitopt`` command's :func:`gaitopt.cli.main`),
SIGTERM raises :class:`Terminated`, a KeyboardInterrupt, so every place that stops cleanly on
Ctrl-C stops the same way: a sweep writes the points its workers returned and ends them, a
solve in progress stops (:func:`gaitopt.ocp.solver.interrupt_watch`), nothing half-written is
left (:mod:`gaitopt.fileio`), and the process exits with :data:`TERMINATED_STATUS`.
"""

from __future__ import annotations

import signal
import threading
from typing import Any

#: The exit status of a ``gaitopt`` process stopped by SIGTERM: 128 + 15, as a shell reports
#: a process killed by that signal (Ctrl-C exits with 130, 128 + SIGINT).
TERMINATED_STATUS = 128 + int(signal.SIGTERM)

_received = threading.Event()


class Terminated(KeyboardInterrupt):
    """SIGTERM where :func:`terminate_as_interrupt` is installed (module docstring)."""


def raise_terminated(signum: int, frame: Any) -> None:
    """The SIGTERM handler of :func:`terminate_as_interrupt`: notes the signal
    (:func:`terminated`) and raises :class:`Terminated`."""
    _received.set()
    raise Terminated


def terminate_as_interrupt() -> None:
    """Make SIGTERM stop this process like Ctrl-C (module docstring), and forget a SIGTERM
    noted before (each ``gaitopt`` command run in one process, as the tests do, asks
    :func:`terminated` about its own run). Call from the main thread."""
    _received.clear()
    signal.signal(signal.SIGTERM, raise_terminated)


def terminated() -> bool:
    """Whether SIGTERM came through :func:`raise_terminated` since
    :func:`terminate_as_interrupt` was last called."""
    return _received.is_set()
