"""The ``gaitopt`` command group and what every subcommand shares.

Errors the user can fix (a bad model file, a bad option) are printed as one clear line
(``Error: ...``) on stderr and exit with status 2; they never show a traceback. A subcommand
signals one by raising :class:`UserError`, or any exception type listed in
:data:`USER_ERRORS` (converted by the ``cli`` group), e.g. :class:`~gaitopt.robot.ModelError`.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar, get_args

import click

from gaitopt import __version__
from gaitopt.gait.options.gait_options import ControlModel, CostName, Formulation
from gaitopt.robot import ModelError

if TYPE_CHECKING:
    from rich.console import Console

    from gaitopt.study.executors import Backend

#: Exception types that are the user's to fix: shown as one line, exit status 2.
USER_ERRORS: tuple[type[Exception], ...] = (ModelError,)

#: Width of tables when the output is not a terminal (a pipe, a file, a CI log).
PIPE_WIDTH = 120


class UserError(click.ClickException):
    """An error in what the user asked for: printed as one message, exit status 2."""

    exit_code = 2

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))


class _Group(click.Group):
    """A click group that turns :data:`USER_ERRORS` into :class:`UserError` and imports each
    command's module only when that command is looked up (:attr:`lazy_commands`: command name
    -> module, whose import registers it on the group), so that ``gaitopt solve`` does not
    import what ``study``, ``report`` or ``stability`` need."""

    #: Command name -> the module that defines (and registers) it.
    lazy_commands: dict[str, str]

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.lazy_commands = {}

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*super().list_commands(ctx), *self.lazy_commands})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in self.lazy_commands:
            importlib.import_module(self.lazy_commands[cmd_name])
        return super().get_command(ctx, cmd_name)

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except USER_ERRORS as exc:
            raise UserError(str(exc)) from None


# -- option values shared by the commands ----------------------------------------------------

def parse_free_or_value(text: str, option: str, unit: str, quantity: str) -> float | None:
    """``free`` -> None, else a number with an optional unit suffix (``0.1m``, ``0.6s``)."""
    if text.strip().lower() == "free":
        return None
    try:
        return float(text.strip().removesuffix(unit))
    except ValueError:
        raise UserError(f"{option}: {text!r} is not a {quantity} in {unit} or 'free'") from None


def parse_pair(text: str, option: str) -> tuple[float, float]:
    """Two numbers ``LO,HI`` (a usage error otherwise)."""
    parts = text.split(",")
    try:
        lo, hi = (float(v) for v in parts)
    except ValueError:
        raise click.BadParameter(f"expected two numbers LO,HI, got {text!r}",
                                 param_hint=option) from None
    return lo, hi


def parse_phase_knots(text: str) -> tuple[int, ...] | dict[str, int]:
    """``--knots`` of a solve: counts ``16,6`` (single, double support; or one per phase of
    the step) or counts by phase name ``single_support=16,double_support=6`` (a usage error
    otherwise; the names are checked against the step's phases with the other options)."""
    parts = [p.strip() for p in text.split(",")]
    try:
        if all("=" in p for p in parts):
            named = {k.strip(): int(v) for k, v in (p.split("=", 1) for p in parts)}
            if len(named) == len(parts) and all(named):
                return named
        elif not any("=" in p for p in parts) and len(parts) >= 2:
            return tuple(int(p) for p in parts)
    except ValueError:
        pass
    raise UserError(f"--knots: {text!r} must be integers 'single,double' (e.g. 16,6; or one "
                    "per phase) or counts by phase name, e.g. "
                    "single_support=16,double_support=6")


def parse_knots(text: str) -> tuple[int, int]:
    """``single,double`` knot counts (a usage error otherwise)."""
    parts = text.split(",")
    try:
        values = tuple(int(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 2:
        raise UserError(f"--knots: {text!r} must be two integers 'single,double', e.g. 8,5")
    return (values[0], values[1])


# -- options used by several commands (defined once) --------------------------------------------

F = TypeVar("F", bound=Callable[..., Any])


def model_option(f: F) -> F:
    """``--model NAME_OR_FILE`` (parameter ``model_name``): a built-in model or a model file."""
    return click.option("--model", "model_name", default="five-link", show_default=True,
                        help="Built-in model name or model file.")(f)


def knots_option(f: F) -> F:
    """``--knots SINGLE,DOUBLE`` of a study (text or None: the default grid; see
    :func:`grid_choice`)."""
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.options.model_defaults import MULTI_PHASE_KNOTS

    return click.option("--knots", default=None,
                        help="Grid points per phase: single support, double support [default: "
                             f"{','.join(map(str, GaitOptions().knots))}; "
                             f"{','.join(map(str, MULTI_PHASE_KNOTS))} for steps of more than "
                             "two phases, e.g. the heel-toe walk].")(f)


def phase_knots_option(f: F) -> F:
    """``--knots SINGLE,DOUBLE``, one count per phase or ``--knots PHASE=N,...`` of a solve
    (text or None: the default grid; see :func:`grid_choice` with ``by_phase``)."""
    from gaitopt.gait.options.gait_options import GaitOptions
    from gaitopt.gait.options.model_defaults import MULTI_PHASE_KNOTS

    return click.option("--knots", default=None,
                        help="Grid points per phase: single support, double support (e.g. "
                             "16,6), one per phase, or by phase name (e.g. "
                             "single_support=16,double_support=6; the heel-toe walk's "
                             "foot_flat, heel_off, double_support, heel_rocker) [default: "
                             f"{','.join(map(str, GaitOptions().knots))}; "
                             f"{','.join(map(str, MULTI_PHASE_KNOTS))} for steps of more than "
                             "two phases, e.g. the heel-toe walk].")(f)


def paper_grid_option(f: F) -> F:
    """``--paper-grid``: the paper's 8 + 5 knots and control model (:func:`grid_choice`)."""
    return click.option("--paper-grid", is_flag=True,
                        help="The paper's setting: 8+5 knots, its control model "
                             "(continuous, periodic controls) and its NLP (compressed "
                             "Hermite-Simpson); its cost is about 13 % above the converged "
                             "one.")(f)


def knot_spacing_option(help: str) -> Callable[[F], F]:
    """``--knot-spacing uniform|cosine`` with this help text (None when not given: the
    :class:`~gaitopt.gait.options.gait_options.GaitOptions` default, uniform with ``--paper-grid``;
    see :func:`grid_choice`)."""
    from gaitopt.gait.options.gait_options import KNOT_SPACINGS, GaitOptions

    return click.option("--knot-spacing", type=click.Choice(list(KNOT_SPACINGS)),
                        default=None,
                        help=f"{help} [default: {GaitOptions().knot_spacing}; uniform with "
                             "--paper-grid]")


def resting_power_option(f: F) -> F:
    """``--resting-power`` in W/kg (None: the metabolic cost's default)."""
    return click.option("--resting-power", type=float, default=None,
                        help="Resting power of the metabolic cost, W/kg [default: 1.2].")(f)


def min_knee_flexion_option(f: F) -> F:
    """``--min-knee-flexion`` in rad (None: the option's default)."""
    return click.option("--min-knee-flexion", type=click.FloatRange(min=0.0), default=None,
                        help="Smallest knee bend (rad) of a leg on the ground [default: 0.1; "
                             "0 lets the stance knee straighten, with --formulation full].")(f)


def formulation_option(help: str, default: str | None = "reduced") -> Callable[[F], F]:
    """``--formulation reduced|full`` with this help text (``default`` None: the command
    chooses, and says how in ``help``)."""
    return click.option("--formulation", type=click.Choice(get_args(Formulation)),
                        default=default, show_default=default is not None, help=help)


def cost_option(help: str) -> Callable[[F], F]:
    """``--cost paper|work|metabolic`` with this help text."""
    return click.option("--cost", type=click.Choice(get_args(CostName)), default="paper",
                        show_default=True, help=help)


def control_model_option(help: str) -> Callable[[F], F]:
    """``--control-model paper|jumps`` with this help text (None: the default, see
    :func:`grid_choice`)."""
    from gaitopt.gait.options.gait_options import GaitOptions

    return click.option("--control-model", type=click.Choice(get_args(ControlModel)),
                        default=None,
                        help=f"{help} [default: {GaitOptions().control_model}]")


def grid_choice(knots: str | None, control_model: str | None,
                paper_grid: bool, knot_spacing: str | None = None, *,
                by_phase: bool = False) -> dict[str, Any]:
    """The ``knots``, ``control_model`` and ``knot_spacing`` of ``--knots``,
    ``--control-model``, ``--knot-spacing`` and ``--paper-grid`` (the paper's 8 + 5 uniform
    knots, control model and compressed transcription, ``GaitOptions.paper``); unset ones
    keep the :class:`~gaitopt.gait.options.gait_options.GaitOptions` defaults. ``--paper-grid`` with
    ``--knots``, ``--control-model`` or cosine knots is a usage error. ``by_phase`` (a solve):
    ``--knots`` also by phase name or one count per phase (:func:`parse_phase_knots`); else
    (a study's sweeps, whose grids are pairs) ``single,double``."""
    from gaitopt.gait.options.gait_options import PAPER_GRID

    if paper_grid:
        given = [o for o, v in (("--knots", knots), ("--control-model", control_model)) if v]
        if knot_spacing is not None and knot_spacing != PAPER_GRID["knot_spacing"]:
            given.append(f"--knot-spacing {knot_spacing}")
        if given:
            raise UserError(f"--paper-grid sets the knots (8,5, uniform) and the control "
                            f"model (paper); do not combine it with {' or '.join(given)}")
        return dict(PAPER_GRID)
    out: dict[str, Any] = {}
    if knots is not None:
        out["knots"] = parse_phase_knots(knots) if by_phase else parse_knots(knots)
    if control_model is not None:
        out["control_model"] = control_model
    if knot_spacing is not None:
        out["knot_spacing"] = knot_spacing
    return out


def make_console() -> Console:
    """A rich console on stdout; at least :data:`PIPE_WIDTH` columns when not a terminal
    (unless ``COLUMNS`` says otherwise), so piped tables are not squeezed to 80 columns.

    Markup is off: text such as ``[kg]`` or ``[-2, 2]`` is printed as it is.
    """
    from rich.console import Console  # here: a command that prints nothing never loads rich

    console = Console(markup=False, highlight=False)
    if not console.is_terminal and "COLUMNS" not in os.environ:
        console = Console(markup=False, highlight=False, width=max(console.width, PIPE_WIDTH))
    return console


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="gaitopt")
def cli() -> None:
    """gaitopt: energy-optimal walking gaits for planar multibody bipeds."""


class SharedBackend:
    """The one executor of a study's sweeps (``gaitopt study --costs``, ``--walk-run``): made
    on first use (:meth:`get`; a :class:`~gaitopt.study.executors.BackendError` becomes a
    :class:`UserError`), closed on leaving the ``with`` block: after the points it runs, or,
    on an error or Ctrl-C, without waiting for them (local worker processes are ended)."""

    def __init__(self, workers: int | None, scheduler: str | None) -> None:
        self.workers, self.scheduler = workers, scheduler
        #: The executor, once made (None before, and after :meth:`close_now`).
        self.backend: Backend | None = None

    def get(self) -> Backend:
        """The executor, made now if not yet."""
        from gaitopt.study.driver import make_backend
        from gaitopt.study.executors import BackendError

        if self.backend is None:
            try:
                self.backend = make_backend(workers=self.workers, scheduler=self.scheduler)
            except BackendError as exc:
                raise UserError(str(exc)) from None
        return self.backend

    def close_now(self) -> None:
        """Close the executor without waiting for its running points (Ctrl-C)."""
        if self.backend is not None:
            self.backend.close(wait=False)
            self.backend = None

    def __enter__(self) -> SharedBackend:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *_: object) -> None:
        if exc_type is not None:
            self.close_now()
        elif self.backend is not None:
            self.backend.close()
            self.backend = None
