"""``gaitopt stability``: Floquet multipliers of a saved gait (orbital stability)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click
import numpy as np
from rich.table import Table

from gaitopt.cli.base import UserError, cli, make_console
from gaitopt.fileio import write_text_atomic
from gaitopt.gait.gait_file import Gait, GaitFileError


def _gains(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        kp, kd = (float(p) for p in text.split(","))
    except ValueError:
        raise UserError(f"--pd: {text!r} must be two numbers 'KP,KD' (N m/rad, N m s/rad), "
                        "e.g. 300,30") from None
    if not (np.isfinite(kp) and np.isfinite(kd)) or kp < 0 or kd < 0:
        raise UserError(f"--pd: got {text!r}; allowed: finite gains KP >= 0, KD >= 0")
    return kp, kd


@cli.command("stability")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--pd", "pd", default=None,
              help="Joint-space PD tracking of the gait's knots, 'KP,KD' (N m/rad, N m s/rad; "
                   "torques unbounded). Default: the gait's torques open loop.")
@click.option("--newton", is_flag=True,
              help="Analyse at the fixed point of the simulated map found by Newton's method "
                   "(default: at the gait's own start state).")
@click.option("--about", type=click.Choice(["simulation", "gait"]), default="simulation",
              show_default=True,
              help="Linearize about the simulated step (checked by finite differences) or "
                   "about the gait's own knots (when the open-loop replay drifts off the "
                   "orbit: the optimizer's orbit).")
@click.option("--no-check", is_flag=True,
              help="Skip the finite-difference check of the monodromy (faster).")
@click.option("--json", "json_out", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Also write the report as JSON to this file.")
def stability_command(file: Path, pd: str | None, newton: bool, about: str, no_check: bool,
                      json_out: Path | None) -> None:
    """Floquet multipliers of a gait's step-to-step return map, and the verdict."""
    from gaitopt.analysis.return_map import StepSimulationError
    from gaitopt.analysis.stability import StabilityError, analyse_step, gait_start, step_from_gait

    gains = _gains(pd)
    try:
        gait = Gait.load(file)
        spec = step_from_gait(gait, pd=gains)
    except (GaitFileError, StabilityError) as exc:
        raise UserError(f"{file}: {exc}" if isinstance(exc, StabilityError) else str(exc)) \
            from None
    console = make_console()
    try:
        report = analyse_step(spec, gait_start(gait), fixed_point="newton" if newton else "start",
                              check=not no_check, about=about)  # type: ignore[arg-type]
    except (StepSimulationError, StabilityError) as exc:
        console.print(f"FAILED: {exc}. Try PD tracking (--pd KP,KD) or --about gait. "
                      "Nothing written.")
        sys.exit(1)
    table = Table(title=f"Floquet multipliers of {file} "
                  f"({'PD ' + pd if pd else 'open loop'}, at the {report.fixed_point})")
    for col in ("#", "modulus", "angle [deg]", "re", "im"):
        table.add_column(col, justify="right")
    for i, m in enumerate(report.multipliers):
        table.add_row(str(i + 1), f"{abs(m):.6g}", f"{np.degrees(np.angle(m)):.2f}",
                      f"{m.real:.6g}", f"{m.imag:.6g}")
    console.print(table)
    for r in report.removed:
        console.print(f"removed {r.count} directions: {r.name} ({r.reason})")
    for note in report.notes:
        console.print(f"note: {note}")
    console.print(f"fixed-point residual max|P(y) - y|: {report.residual:.3g} at the "
                  f"{report.fixed_point} (gait start: {report.start_residual:.3g})")
    if report.fd_agreement is not None:
        console.print(f"finite-difference check of the monodromy: {report.fd_agreement:.2g} "
                      "(relative)")
    console.print(f"spectral radius {report.spectral_radius:.6g}: {report.verdict.upper()} "
                  f"(margin {report.margin:g})")
    if json_out is not None:
        write_text_atomic(json_out, json.dumps(report.to_dict(), indent=2) + "\n")
        console.print(f"wrote {json_out}")
