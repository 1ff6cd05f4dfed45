"""A GIF of a MuJoCo simulation, rendered by MuJoCo's offscreen renderer (headless: the
caller sets ``MUJOCO_GL=egl`` before MuJoCo is imported; ``gaitopt simulate --video`` does).

The camera tracks the base body from the side (MuJoCo -y, looking along +y, so the robot
walks to the right as in gaitopt's figures), 3 m away. Frames are the simulation's states at
``fps`` frames per second of simulated time, so the GIF plays in real time (GIF delays are in
1/100 s: ``fps`` should divide 100).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image


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
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    images[0].save(target, save_all=True, append_images=images[1:],
                   duration=round(1000 / fps), loop=0, optimize=False)
    return len(images)
