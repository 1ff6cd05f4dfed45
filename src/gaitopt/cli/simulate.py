"""``gaitopt simulate``: replay a gait in MuJoCo with PD tracking (``docs/simulate.md``).

Exit status: 0 the robot walked every step asked; 1 it fell (the simulation's result);
2 a user error (bad file, option, MuJoCo missing); 3 refused before simulating: the return
map with the chosen gains is not stable (its spectral radius is printed), so time-indexed
tracking cannot keep the gait (``--tracking phase`` or ``--force`` simulate anyway).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import click
import numpy as np

from gaitopt.cli.base import UserError, cli, make_console
from gaitopt.cli.stability import resolve_gains
from gaitopt.gait.record.file import Gait, GaitFileError

#: Exit status of a refused simulation (no stabilising gains).
REFUSED = 3
#: Frames per second of ``--video`` (divides 100: exact GIF delays).
VIDEO_FPS = 25


@cli.command("simulate")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--steps", type=click.IntRange(min=1, max=1000), default=10, show_default=True,
              help="Steps to walk.")
@click.option("--pd", "pd", default="auto", show_default=True,
              help="PD gains 'KP,KD' (N m/rad, N m s/rad), or 'auto': those that minimise the "
                   "spectral radius of the return map (gaitopt stability --pd auto).")
@click.option("--tracking", type=click.Choice(["time", "phase"]), default="time",
              show_default=True,
              help="Index the reference by each phase's clock (the return map's controller) or "
                   "by the hip's forward position relative to the step's origin.")
@click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write a GIF of the simulation (MuJoCo's offscreen renderer, EGL).")
@click.option("--mjcf", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Simulate this MJCF file (matched to the gait's model by joint, body and "
                   "geom names) instead of gaitopt's export of the model.")
@click.option("--write-mjcf", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write the MJCF that is simulated to this file.")
@click.option("--solid-swing", is_flag=True,
              help="Swing points collide with the ground all the time (default: from the phase "
                   "that ends with their touchdown, once half a step ahead, as the return map).")
@click.option("--unbounded", is_flag=True,
              help="Do not clip the torques to the actuators' bounds (as the return map).")
@click.option("--force", is_flag=True,
              help="Simulate even when the return map with these gains is unstable.")
def simulate_command(file: Path, steps: int, pd: str, tracking: str, video: Path | None,
                     mjcf: Path | None, write_mjcf: Path | None, solid_swing: bool,
                     unbounded: bool, force: bool) -> None:
    """Replay a gait in MuJoCo: feed-forward torques plus PD tracking, step after step."""
    if video is not None:
        os.environ.setdefault("MUJOCO_GL", "egl")  # before MuJoCo is imported: headless
    from gaitopt.analysis.mujoco_model import MujocoModelError, import_mujoco
    from gaitopt.analysis.simulate import SimulationError, simulate_gait

    console = make_console()
    try:
        gait = Gait.load(file)
        import_mujoco()
    except (GaitFileError, MujocoModelError) as exc:
        raise UserError(str(exc)) from None
    if not gait.success:
        raise UserError(f"{file}: the gait's solve did not converge (status {gait.status!r}): "
                        "its trajectories are not a gait; solve it again")
    if video is not None and video.suffix.lower() != ".gif":
        raise UserError(f"--video {video}: allowed: a .gif file")
    console.print(f"{file}: {gait.model.name}, {gait.speed * 60:.2f} m/min, step "
                  f"{gait.step_length:.4f} m in {gait.step_time:.4f} s", soft_wrap=True)
    gains, rho = resolve_gains(pd, gait, console)
    assert gains is not None
    if tracking == "time":
        stable = rho < 1.0 - 1e-3
        if not stable and not force:
            what = ("no PD gains stabilise this gait: the best" if pd.strip().lower() == "auto"
                    else f"PD {gains[0]:g},{gains[1]:g} does not stabilise this gait: its")
            console.print(f"REFUSED: {what} spectral radius of the return map is {rho:.4g} "
                          f"(at PD {gains[0]:.4g},{gains[1]:.4g}) > 1: the gait's orbit is "
                          "unstable under time-indexed tracking, a replay leaves it; not "
                          "simulated. --tracking phase indexes the swing by the hip's forward "
                          "position (docs/simulate.md: it did not keep the five-link walk "
                          "without ankle torques); --force simulates anyway.", soft_wrap=True)
            sys.exit(REFUSED)
    else:
        console.print("tracking by phase (the hip's forward position): the return map's "
                      "spectral radius, computed for time-indexed tracking, does not apply")
    start = time.perf_counter()
    try:
        result = simulate_gait(gait, steps=steps, pd=gains, tracking=tracking,  # type: ignore[arg-type]
                               mjcf=None if mjcf is None else str(mjcf),
                               bounded=not unbounded, ghost_swing=not solid_swing,
                               progress=lambda line: console.print(line, soft_wrap=True))
    except (SimulationError, MujocoModelError) as exc:
        raise UserError(str(exc)) from None
    s = result.settings
    console.print(f"contact: {s['contact']}; model: {s['mjcf']}; swing points "
                  f"{'solid' if solid_swing else 'solid from their touchdown phase'}; torques "
                  f"{'clipped to their bounds' if not unbounded else 'unbounded'} (peak "
                  f"{result.peak_torque_ratio:.0%} of a bound)", soft_wrap=True)
    console.print(f"fall criteria: {s['fall_criteria']}", soft_wrap=True)
    console.print(f"tracking error of the joint angles: RMS {result.rms_error:.4f} rad "
                  f"({np.degrees(result.rms_error):.2f} deg), max {result.max_error:.4f} rad "
                  f"({np.degrees(result.max_error):.2f} deg)", soft_wrap=True)
    if result.steps:
        console.print(f"average speed over {result.steps} steps: {result.speed * 60:.2f} m/min "
                      f"(the gait's: {result.gait_speed * 60:.2f} m/min); mean step "
                      f"{np.mean(result.step_lengths):.4f} m in {np.mean(result.step_times):.4f} s "
                      f"(the gait's: {gait.step_length:.4f} m in {gait.step_time:.4f} s)",
                      soft_wrap=True)
    if write_mjcf is not None:
        from gaitopt.fileio import write_text_atomic

        write_text_atomic(write_mjcf, result.robot.mjcf)
        console.print(f"wrote {write_mjcf}")
    if video is not None:
        _video(console, result, video)
    console.print(f"simulated in {time.perf_counter() - start:.1f} s")
    if result.fell:
        console.print(f"FELL after {result.steps} of {result.steps_asked} steps: "
                      f"{result.fall_reason}", soft_wrap=True)
        sys.exit(1)
    console.print(f"WALKED {result.steps} steps without falling (PD {gains[0]:.4g},"
                  f"{gains[1]:.4g}, {tracking}-indexed tracking)", soft_wrap=True)


def _video(console: object, result: object, path: Path) -> None:
    from gaitopt.analysis.mujoco_model import import_mujoco
    from gaitopt.viz.mujoco_video import write_gif

    mujoco = import_mujoco()
    robot = result.robot  # type: ignore[attr-defined]
    every = max(1, round(1.0 / VIDEO_FPS / 0.01))
    base = int(mujoco.mj_name2id(robot.mj, mujoco.mjtObj.mjOBJ_BODY, robot.model.base.name))
    try:
        frames = write_gif(mujoco, robot.mj, result.qpos[::every], path,  # type: ignore[attr-defined]
                           base_body=base, fps=VIDEO_FPS)
        how = "MuJoCo's offscreen renderer"
    except Exception as exc:  # no offscreen OpenGL: MuJoCo raises several types
        from gaitopt.viz.mujoco_video import write_stick_gif

        console.print(f"MuJoCo's offscreen renderer failed (MUJOCO_GL="  # type: ignore[attr-defined]
                      f"{os.environ.get('MUJOCO_GL')}: {' '.join(str(exc).split())}); drawing "
                      "the simulated trajectory as gaitopt's stick figure instead",
                      soft_wrap=True)
        frames = write_stick_gif(robot.model, result.q[::every], path,  # type: ignore[attr-defined]
                                 fps=VIDEO_FPS)
        how = "gaitopt's stick figure"
    console.print(f"video: {path} ({frames} frames at {VIDEO_FPS} fps, real time; "  # type: ignore[attr-defined]
                  f"{how})")
