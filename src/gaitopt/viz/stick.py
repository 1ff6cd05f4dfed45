"""Stick figures of the biped: one pose, and a strip of poses over a step.

A pose is drawn from the world points of the gait samples (m): torso from ``hip`` to
``torso_top``, leg i from ``hip`` through its points (``knee_i`` to ``tip_i``, or to the ankle
and the heel and toe of a foot); leg 1 dark blue, leg 2
orange (:data:`gaitopt.viz.style.LEG_COLORS`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from numpy.typing import NDArray

from gaitopt.gait.record.file import Gait, GaitSamples
from gaitopt.viz.style import LEG_COLORS, new_figure

Points = Mapping[str, NDArray[np.float64]]


def leg_points(points: Points, leg: str) -> list[str]:
    """The points of leg ``leg`` (``"1"`` or ``"2"``) in recorded order, from the hip out:
    every name ending in ``_<leg>`` (joints, then contact points)."""
    return [n for n in points if n.endswith(f"_{leg}")]


def pose_segments(points: Points, offset: float = 0.0) -> dict[str, NDArray[np.float64]]:
    """Polylines (k, 2) of the torso and both legs from one pose's points (each (2,)): leg
    i from the hip through its points (:func:`leg_points`); a leg ending in two contact
    points (a foot: heel and toe) is closed back to the joint before them (the ankle)."""
    shift = np.array([offset, 0.0])
    out = {"torso": np.array([points["hip"], points["torso_top"]]) + shift}
    for leg in ("1", "2"):
        names = leg_points(points, leg)
        if len(names) >= 4:
            names = names + [names[-3]]
        out[f"leg_{leg}"] = np.array([points["hip"]] + [points[n] for n in names]) + shift
    return out


def draw_pose(ax: Axes, points: Points, *, offset: float = 0.0, alpha: float = 1.0,
              linewidth: float = 2.2) -> dict[str, Line2D]:
    """Draw one pose on ``ax`` (x shifted by ``offset`` m); returns the lines by part."""
    colors = {"torso": "k", "leg_1": LEG_COLORS[0], "leg_2": LEG_COLORS[1]}
    lines = {}
    # leg 2 behind, leg 1 in front
    for part in ("leg_2", "torso", "leg_1"):
        xy = pose_segments(points, offset)[part]
        (lines[part],) = ax.plot(xy[:, 0], xy[:, 1], color=colors[part], alpha=alpha,
                                 linewidth=linewidth, solid_capstyle="round", marker="o",
                                 markersize=linewidth * 1.4, gid=part)
    return lines


def pose_at(samples: GaitSamples, t: float) -> dict[str, NDArray[np.float64]]:
    """The world points (2,) of a pose at time ``t`` (s), linear between samples."""
    return {name: np.array([np.interp(t, samples.t, p[:, 0]), np.interp(t, samples.t, p[:, 1])])
            for name, p in samples.points.items()}


def draw_pose_row(ax: Axes, samples: GaitSamples, times: NDArray[np.float64],
                  positions: NDArray[np.float64], *, scale: float,
                  linewidth: float = 1.2) -> None:
    """Small poses at ``times`` (s), each scaled by ``scale`` (axis units per metre) and
    placed with its hip above x = ``positions`` on a ground line at y = 0."""
    for t, x in zip(times, positions, strict=True):
        pose = pose_at(samples, float(t))
        hip_x = pose["hip"][0]
        small = {n: np.array([(p[0] - hip_x) * scale + x, p[1] * scale])
                 for n, p in pose.items()}
        draw_pose(ax, small, linewidth=linewidth)
    ax.axhline(0.0, color="0.3", linewidth=0.8)


def stick_strip_figure(gait: Gait, *, frames: int = 9, title: str | None = None) -> Figure:
    """A strip of ``frames`` poses evenly spaced in time over one step, side by side.

    Each pose is shifted horizontally so that its hip sits at a multiple of a fixed spacing
    (the real forward progress is given under each pose as the hip's x); the ground is drawn
    under each pose, with the tips on the ground marked.
    """
    if frames < 2:
        raise ValueError(f"frames: expected >= 2, got {frames}")
    s = gait.samples
    times = np.linspace(s.t[0], s.t[-1], frames)
    legs = leg_points(s.points, "1") + leg_points(s.points, "2")
    reach = max(float(np.ptp(np.concatenate([s.points[n][:, 0] - s.points["hip"][:, 0]
                                             for n in legs]))), 0.3)
    spacing = max(reach + 0.25, 0.55)
    height = float(np.max(s.points["torso_top"][:, 1])) + 0.1
    fig = new_figure(min(1.1 * frames * spacing + 0.6, 16.0), 3.2)
    ax = fig.add_subplot()
    t1 = gait.parameters["single_support_time"] + s.t[0]
    for i, t in enumerate(times):
        pose = pose_at(s, float(t))
        offset = i * spacing - float(pose["hip"][0])
        ax.plot([i * spacing - spacing / 2.2, i * spacing + spacing / 2.2], [0.0, 0.0],
                color="0.3", linewidth=1.0)
        draw_pose(ax, pose, offset=offset)
        phase = "single" if t < t1 - 1e-12 else "double"
        ax.text(i * spacing, -0.06, f"t/T={(t - s.t[0]) / gait.step_time:.2f}\n"
                f"hip {pose['hip'][0]:+.2f} m\n{phase}", ha="center", va="top", fontsize=6.5)
    ax.set_aspect("equal")
    ax.set_xlim(-spacing / 2, (frames - 1) * spacing + spacing / 2)
    ax.set_ylim(-0.3, height)
    ax.axis("off")
    speed = gait.speed * 60.0
    ax.set_title((title or f"one step at {speed:.1f} m/min, step length "
                  f"{gait.step_length:.3f} m") + "\nleg 1 (blue) stands, leg 2 (orange) "
                 "swings; single / double support", fontsize=9)
    return fig
