"""A GIF of a MuJoCo simulation, rendered by MuJoCo's offscreen renderer (headless: the
caller sets ``MUJOCO_GL=egl`` before MuJoCo is imported; ``gaitopt simulate --video`` does),
or, without an OpenGL context, drawn as gaitopt's stick figure (:func:`write_stick_gif`).

The camera tracks the base body from the side (MuJoCo -y, looking along +y, so the robot
walks to the right as in gaitopt's figures), 3 m away. Frames are the simulation's states at
``fps`` frames per second of simulated time, so the GIF plays in real time (GIF delays are in
1/100 s: ``fps`` should divide 100).
"""

from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from gaitopt.analysis.checks.samples import points_function
from gaitopt.fileio import write_bytes_atomic
from gaitopt.gait.record_points import point_names
from gaitopt.robot.model import RobotModel
from gaitopt.viz.stick import draw_pose
from gaitopt.viz.style import new_figure


def write_gif(mujoco: Any, mj: Any, qpos: NDArray[np.float64], path: str | os.PathLike[str],
              *, base_body: int, fps: int = 25, width: int = 480, height: int = 320) -> int:
    """Render the states ``qpos`` (N, nq) of ``mj`` (one per frame, at ``fps``) to the GIF
    ``path``; returns the number of frames. Raises ``RuntimeError`` (MuJoCo's) when no
    offscreen OpenGL context can be made."""
    data = mujoco.MjData(mj)
    renderer = mujoco.Renderer(mj, height, width)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    cam.trackbodyid = base_body
    cam.distance, cam.azimuth, cam.elevation = 3.0, 90.0, -5.0
    images = []
    try:
        for q in qpos:
            data.qpos[:] = q
            mujoco.mj_forward(mj, data)
            renderer.update_scene(data, camera=cam)
            images.append(Image.fromarray(renderer.render()).quantize(colors=64))
    finally:
        renderer.close()
    _save_gif(images, path, fps)
    return len(images)


def write_stick_gif(model: RobotModel, q: NDArray[np.float64], path: str | os.PathLike[str],
                    *, fps: int = 25, dpi: int = 80) -> int:
    """The fallback without an OpenGL context: gaitopt's stick figure
    (:func:`gaitopt.viz.stick.draw_pose`) of the simulated states ``q`` (N, nq) in gaitopt's
    coordinates (physical leg labels: leg 1 keeps its colour), one per frame at ``fps``, the
    view following the hip; returns the number of frames."""
    names = point_names(model)
    points = np.asarray(points_function(model, names).map(len(q))(np.asarray(q).T), float)
    points = points.reshape(2, len(q), len(names))  # (xy, frame, point)
    fig = new_figure(6.0, 3.0)
    fig.set_layout_engine("none")
    fig.set_dpi(dpi)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_aspect("equal")
    top = float(points[1].max()) + 0.1
    ax.set_ylim(-0.1, top)
    ax.axis("off")
    ax.axhline(0.0, color="0.25", linewidth=1.5)
    images = []
    for k in range(len(q)):
        pose = {n: points[:, k, j] for j, n in enumerate(names)}
        lines = draw_pose(ax, pose)
        hip = float(pose["hip"][0])
        ax.set_xlim(hip - (top + 0.1), hip + (top + 0.1))
        fig.canvas.draw()
        rgba = np.asarray(fig.canvas.buffer_rgba())  # type: ignore[attr-defined]
        images.append(Image.fromarray(rgba[:, :, :3].copy()).quantize(colors=32))
        for line in lines.values():
            line.remove()
    _save_gif(images, path, fps)
    return len(images)


def _save_gif(images: list[Image.Image], path: str | os.PathLike[str], fps: int) -> None:
    """Write ``images`` as a looping GIF at ``fps`` frames per second, atomically (a reader
    never sees a half-written file)."""
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:],
                   duration=round(1000 / fps), loop=0, optimize=False)
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    write_bytes_atomic(target, buffer.getvalue())
