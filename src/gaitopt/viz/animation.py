"""Animations of a gait: the stick figure walking several steps over the ground, with the
ground's contact forces on the tips drawn as arrows, at real-time speed.

Frame k shows time t_k = k / fps (s) of the walk, for t_k <= steps * step_time, so the movie
plays in real time: an mp4 at ``fps`` frames per second; a GIF whose frame delays (which GIF
stores in 1/100 s) are rounded cumulatively, so the total duration is exact to 10 ms even when
1/fps is not a multiple of 10 ms. Poses are interpolated linearly between the gait's dense
samples; contact forces linearly between knots of the phase the time falls in.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.animation import FFMpegWriter
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrow
from numpy.typing import NDArray
from PIL import Image

from gaitopt.gait.record.file import Gait
from gaitopt.gait.record.interpolation import phase_forces_at
from gaitopt.robot.symmetry import swap_names
from gaitopt.viz.stick import draw_pose, pose_at, pose_segments
from gaitopt.viz.style import LEG_COLORS, new_figure

SUFFIXES = (".gif", ".mp4")
FORCE_ARROW_PER_WEIGHT = 0.35  # m of arrow for a force equal to the robot's weight


@dataclass(frozen=True)
class AnimationInfo:
    """What was written: the file, its number of frames, frame rate and duration (s)."""

    path: Path
    frames: int
    fps: float
    duration_s: float


def frame_times(duration_s: float, fps: float) -> NDArray[np.float64]:
    """t_k = k / fps for k = 0, 1, ... while t_k <= duration_s (tolerance 1e-9 s)."""
    n = int(math.floor(duration_s * fps + 1e-9)) + 1
    return np.arange(n) / fps


def gif_delays_ms(n_frames: int, fps: float) -> list[int]:
    """Per-frame delays (ms, multiples of 10) whose running sum tracks k / fps to 10 ms."""
    ends = np.round(np.arange(1, n_frames + 1) / fps * 100.0).astype(int) * 10
    return np.diff(np.concatenate([[0], ends])).tolist()


def contact_forces_at(gait: Gait, t: float) -> dict[str, NDArray[np.float64]]:
    """Contact forces (2,) N on the tips in contact at time ``t`` (s) within the step."""
    for phase in gait.phases:
        if phase.t[0] - 1e-12 <= t <= phase.t[-1] + 1e-12:
            return {c: f[0] for c, f in phase_forces_at(phase, np.array([t])).items()}
    return {}


def animate_gait(gait: Gait, path: str | os.PathLike[str], *, steps: int = 4,
                 fps: int = 30, dpi: int = 100, forces: bool = True) -> AnimationInfo:
    """Write an animation of ``steps`` steps of ``gait`` to ``path`` (.gif or .mp4).

    Real-time: frame k is the pose at t = k / fps s. Contact forces (ground on tip) are arrows
    from the tips, a body weight drawn as :data:`FORCE_ARROW_PER_WEIGHT` m.
    """
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in SUFFIXES:
        raise ValueError(f"{target}: unsupported animation file type {target.suffix!r}; use "
                         f"one of {', '.join(SUFFIXES)}")
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise ValueError(f"steps: expected an integer >= 1, got {steps!r}")
    if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= 120:
        raise ValueError(f"fps: expected an integer in [1, 120], got {fps!r}")
    stride = gait.stride_samples(steps)
    period, shift = gait.step_time, gait.step_length
    times = frame_times(steps * period, fps)
    weight = gait.model.total_mass * math.hypot(*gait.model.gravity)
    scale = FORCE_ARROW_PER_WEIGHT / weight

    xs = np.concatenate([p[:, 0] for p in stride.points.values()])
    ys = np.concatenate([p[:, 1] for p in stride.points.values()])
    y_lo, y_hi = -0.12, float(ys.max()) + 0.12
    x_lo, x_hi = float(xs.min()) - 0.3, float(xs.max()) + 0.3
    if x_hi - x_lo < 1.6 * (y_hi - y_lo):  # at least a landscape view
        pad = (1.6 * (y_hi - y_lo) - (x_hi - x_lo)) / 2
        x_lo, x_hi = x_lo - pad, x_hi + pad
    window = min(x_hi - x_lo, 2.5 * (y_hi - y_lo))  # follow the hip when the walk is long
    height_in = 4.0
    width_in = 2 * round(height_in * window / (y_hi - y_lo) * dpi / 2) / dpi
    fig = new_figure(max(width_in, 2.0), height_in)
    fig.set_layout_engine("none")
    fig.set_dpi(dpi)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_aspect("equal")
    ax.set_ylim(y_lo, y_hi)
    ax.axis("off")
    ax.axhline(0.0, color="0.25", linewidth=1.5)
    for x in np.arange(math.floor(x_lo * 10) / 10, x_hi, 0.1):
        ax.plot([x, x - 0.03], [0.0, -0.03], color="0.5", linewidth=0.8)
    pose0 = pose_at(stride, 0.0)
    lines = draw_pose(ax, pose0, linewidth=3.0)
    arrows: dict[str, FancyArrow] = {}
    for leg, color in ((c.name, LEG_COLORS[0 if c.name.endswith("_1") else 1])
                       for c in gait.model.contacts):
        arrows[leg] = FancyArrow(0, 0, 0, 0, width=0.008, head_width=0.03, head_length=0.03,
                                 length_includes_head=True, color=color, alpha=0.8, zorder=5)
        ax.add_patch(arrows[leg])
    label = ax.text(0.01, 0.98, "", transform=ax.transAxes, va="top", fontsize=9)
    names = swap_names(gait.model)

    def draw(t: float) -> None:
        pose = pose_at(stride, t)
        for part, xy in pose_segments(pose).items():
            lines[part].set_data(xy[:, 0], xy[:, 1])
        k = min(int(t // period), steps - 1)
        local = contact_forces_at(gait, t - k * period) if forces else {}
        on_ground = {(names.get(c, c) if k % 2 else c): f for c, f in local.items()}
        for leg, arrow in arrows.items():
            f = on_ground.get(leg)
            arrow.set_visible(f is not None)
            if f is not None:
                tip = pose[leg]
                arrow.set_data(x=tip[0], y=tip[1], dx=f[0] * scale, dy=f[1] * scale)
        centre = float(np.clip(pose["hip"][0], x_lo + window / 2, x_hi - window / 2))
        ax.set_xlim(centre - window / 2, centre + window / 2)
        label.set_text(f"t = {t:5.2f} s   step {k + 1}/{steps}   "
                       f"{gait.speed * 60:.1f} m/min, step {shift:.3f} m   (real time)")

    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.tmp{suffix}")  # same suffix: same encoder
    try:
        if suffix == ".gif":
            _write_gif(tmp, fig, draw, times, fps)
        else:
            _write_mp4(tmp, fig, draw, times, fps, dpi)
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)
    return AnimationInfo(path=target, frames=len(times), fps=float(fps),
                         duration_s=len(times) / fps)


def _write_gif(path: Path, fig: Figure, draw: Callable[[float], None],
               times: NDArray[np.float64], fps: int) -> None:
    images = []
    for t in times:
        draw(float(t))
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())  # type: ignore[attr-defined]
        images.append(Image.fromarray(rgba[:, :, :3].copy()).quantize(colors=64))
    images[0].save(path, save_all=True, append_images=images[1:],
                   duration=gif_delays_ms(len(images), fps), loop=0, optimize=False)


def _write_mp4(path: Path, fig: Figure, draw: Callable[[float], None],
               times: NDArray[np.float64], fps: int, dpi: int) -> None:
    import imageio_ffmpeg

    with matplotlib.rc_context({"animation.ffmpeg_path": imageio_ffmpeg.get_ffmpeg_exe()}):
        writer = FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
        with writer.saving(fig, str(path), dpi):
            for t in times:
                draw(float(t))
                writer.grab_frame()
