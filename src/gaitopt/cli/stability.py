"""``gaitopt stability``: Floquet multipliers of a saved gait (orbital stability)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import click
import numpy as np
from rich.console import Console
from rich.table import Table

from gaitopt.analysis.stability import StabilityError
from gaitopt.cli.base import UserError, cli, make_console
from gaitopt.fileio import write_text_atomic
from gaitopt.gait.record.file import Gait, GaitFileError


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


def resolve_gains(text: str, gait: Gait, console: Console) -> tuple[tuple[float, float], float]:
    """``--pd KP,KD`` or ``--pd auto`` for ``gait``: the gains and the spectral radius of the
    return map with them (``auto``: the search of :mod:`gaitopt.analysis.pd_search`, a line
    per evaluation). Shared by ``gaitopt stability`` and ``gaitopt simulate``."""
    from gaitopt.analysis.pd_search import (
        KD_BOX,
        KD_GRID,
        KP_BOX,
        KP_GRID,
        search_gains,
        spectral_radius,
    )

    if text.strip().lower() == "auto":
        console.print(f"--pd auto: searching the PD gains that minimise the spectral radius of "
                      f"the return map ({len(KP_GRID)} x {len(KD_GRID)} log grid, kp "
                      f"{min(KP_GRID):g}..{max(KP_GRID):g}, kd {min(KD_GRID):g}..{max(KD_GRID):g}"
                      f", then a local refinement in kp {KP_BOX[0]:g}..{KP_BOX[1]:g}, kd "
                      f"{KD_BOX[0]:g}..{KD_BOX[1]:g}; a line per evaluation)", soft_wrap=True)
        try:
            found = search_gains(gait, progress=lambda line: console.print(line))
        except StabilityError as exc:
            raise UserError(str(exc)) from None
        console.print(f"--pd auto: PD {found.pd[0]:.4g},{found.pd[1]:.4g}, spectral radius "
                      f"{found.spectral_radius:.4g} ({'stable' if found.stable else 'UNSTABLE'}; "
                      f"{len(found.evaluations)} evaluations)", soft_wrap=True)
        return found.pd, found.spectral_radius
    gains = _gains(text)
    assert gains is not None
    try:
        rho = spectral_radius(gait, gains)
    except StabilityError as exc:
        raise UserError(str(exc)) from None
    console.print(f"return map with PD {gains[0]:.4g},{gains[1]:.4g}: spectral radius {rho:.4g}",
                  soft_wrap=True)
    return gains, rho


@cli.command("stability")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--pd", "pd", default=None,
              help="Joint-space PD tracking of the gait's knots, 'KP,KD' (N m/rad, N m s/rad; "
                   "torques unbounded), or 'auto': the gains that minimise the spectral radius "
                   "(a search). Default: the gait's torques open loop.")
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
    from gaitopt.analysis.stability import analyse_step, gait_start, step_from_gait

    console = make_console()
    try:
        gait = Gait.load(file)
        if pd is not None and pd.strip().lower() == "auto":
            if not gait.success:
                raise StabilityError(f"the gait's solve did not converge (status "
                                     f"{gait.status!r}): its trajectories are not a gait")
            gains: tuple[float, float] | None = resolve_gains(pd, gait, console)[0]
            pd = f"{gains[0]:.4g},{gains[1]:.4g}"  # type: ignore[index]
        else:
            gains = _gains(pd)
        spec = step_from_gait(gait, pd=gains)
    except (GaitFileError, StabilityError) as exc:
        raise UserError(f"{file}: {exc}" if isinstance(exc, StabilityError) else str(exc)) \
            from None
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
