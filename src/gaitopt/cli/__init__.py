"""The ``gaitopt`` command line: the group with every command family registered, and ``main``.

What every command shares (the group, :class:`UserError`, the console, the option types and
the options used by several commands) is in :mod:`gaitopt.cli.base`. Each other module holds
one command family and registers its subcommands on the group when imported, which happens
when one of its commands is looked up (:data:`COMMANDS`):
:mod:`~gaitopt.cli.model` (``model show|export|import``), :mod:`~gaitopt.cli.gait`
(``solve``, ``verify``), :mod:`~gaitopt.cli.stability` (``stability``),
:mod:`~gaitopt.cli.study` (``sweep``, ``study``) and :mod:`~gaitopt.cli.report`
(``report``, ``animate``).
"""

from __future__ import annotations

from collections.abc import Sequence

from gaitopt.cli.base import PIPE_WIDTH, USER_ERRORS, UserError, cli, make_console

#: Each command and the module that registers it, imported when the command is looked up
#: (``gaitopt solve`` imports neither the study's nor the figures' modules).
COMMANDS: dict[str, str] = {
    "model": "gaitopt.cli.model",
    "solve": "gaitopt.cli.gait",
    "verify": "gaitopt.cli.gait",
    "stability": "gaitopt.cli.stability",
    "sweep": "gaitopt.cli.study",
    "study": "gaitopt.cli.study",
    "report": "gaitopt.cli.report",
    "animate": "gaitopt.cli.report",
}
cli.lazy_commands.update(COMMANDS)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``gaitopt`` console script; returns the exit status."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="gaitopt",
                 standalone_mode=True)
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return 0


__all__ = ["PIPE_WIDTH", "USER_ERRORS", "UserError", "cli", "main", "make_console"]
