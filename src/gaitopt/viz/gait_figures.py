"""Figures of gaits, several overlaid (paper Figs. 5-8).

Input: a sequence of ``(label, gait)`` pairs and optionally one line style per pair (default
:data:`gaitopt.viz.style.GAIT_STYLES`). Time is normalized by each gait's step time (a step
spans 0..1, a double step 0..2), so gaits of different speeds share the axis. Thin grey
vertical lines mark the contact events: heel strike at t = T1/T, the next step's liftoff at
1, the next heel strike at 1 + T1/T.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from gaitopt.gait.record.file import Gait
from gaitopt.viz.stick import draw_pose_row
from gaitopt.viz.style import BOUND_LINE, EVENT_LINE, gait_style, new_figure

GaitCurves = Sequence[tuple[str, Gait]]


def _styles(curves: GaitCurves, styles: Sequence[Mapping[str, Any]] | None
            ) -> list[dict[str, Any]]:
    if not curves:
        raise ValueError("no gaits to plot")
    if styles is None:
        return [gait_style(i) for i in range(len(curves))]
    if len(styles) != len(curves):
        raise ValueError(f"{len(styles)} styles for {len(curves)} gaits")
    return [dict(s) for s in styles]


def _event_lines(ax: Axes, curves: GaitCurves, n_steps: int) -> None:
    fractions = sorted({round(g.parameters["single_support_time"] / g.step_time, 6)
                        for _, g in curves})
    for k in range(n_steps):
        if k > 0:
            ax.axvline(k, **EVENT_LINE)
        for f in fractions:
            ax.axvline(k + f, **EVENT_LINE)


def _legend(fig: Figure, ax: Axes) -> None:
    """One legend for the figure, below the axes (gid 'gaits' for tests)."""
    handles, labels = ax.get_legend_handles_labels()
    legend = fig.legend(handles, labels, loc="outside lower center", fontsize=7,
                        ncols=min(len(labels), 2), frameon=False)
    legend.set_gid("gaits")


def _finish(fig: Figure, axes: Sequence[Axes], title: str, xlabel: str) -> None:
    axes[-1].set_xlabel(xlabel)
    _legend(fig, axes[0])
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)


def hip_motion_figure(curves: GaitCurves, *,
                      styles: Sequence[Mapping[str, Any]] | None = None) -> Figure:
    """Paper Fig. 5: hip horizontal position (relative to its start, m) and velocity (m/s)
    over a double step (two steps, legs relabelled) against normalized time t/T, below
    small poses of the first gait at t/T = 0, 0.25, ..., 2 (as the paper's stick figures)."""
    sty = _styles(curves, styles)
    fig = new_figure(7.5, 6.5)
    ax_s, ax_x, ax_v = fig.subplots(3, 1, sharex=True, height_ratios=(0.8, 2, 2))
    first = curves[0][1]
    taus = np.linspace(0.0, 2.0, 9)
    draw_pose_row(ax_s, first.stride_samples(2), first.samples.t[0] + taus * first.step_time,
                  taus, scale=0.12)
    ax_s.set_aspect("equal", adjustable="box")
    ax_s.set_gid("sticks")
    ax_s.axis("off")
    ax_s.set_title(f"poses of: {curves[0][0]}", fontsize=7, loc="left")
    for (label, gait), style in zip(curves, sty, strict=True):
        s = gait.stride_samples(2)
        ix = gait.model.coordinate_names.index("x")
        tau = (s.t - s.t[0]) / gait.step_time
        ax_x.plot(tau, s.q[:, ix] - s.q[0, ix], label=label, **style)
        ax_v.plot(tau, s.qd[:, ix], label=label, **style)
    _event_lines(ax_x, curves, 2)
    _event_lines(ax_v, curves, 2)
    ax_x.set_ylabel("hip x − x(0)  [m]")
    ax_v.set_ylabel("hip forward velocity  [m/s]")
    _finish(fig, (ax_x, ax_v), "Fig. 5  hip horizontal position and velocity over a double step",
            "normalized time t / T (one step = 1)")
    return fig


def heights_figure(curves: GaitCurves, *,
                   styles: Sequence[Mapping[str, Any]] | None = None) -> Figure:
    """Paper Fig. 6: heights (m) of the hip and of each knee over a double step."""
    sty = _styles(curves, styles)
    fig = new_figure(7.5, 7.0)
    axes = fig.subplots(3, 1, sharex=True)
    names = ("hip", "knee_1", "knee_2")
    for (label, gait), style in zip(curves, sty, strict=True):
        s = gait.stride_samples(2)
        tau = (s.t - s.t[0]) / gait.step_time
        for ax, name in zip(axes, names, strict=True):
            ax.plot(tau, s.points[name][:, 1], label=label, **style)
    for ax, name in zip(axes, ("hip height  [m]", "knee of leg 1 height  [m]",
                               "knee of leg 2 height  [m]"), strict=True):
        _event_lines(ax, curves, 2)
        ax.set_ylabel(name, fontsize=9)
    _finish(fig, axes, "Fig. 6  hip and knee heights over a double step",
            "normalized time t / T (one step = 1; leg 1 stands in the first step)")
    return fig


def torques_figure(curves: GaitCurves, *, title: str = "joint torques with their bounds",
                   styles: Sequence[Mapping[str, Any]] | None = None) -> Figure:
    """Paper Figs. 7/8: each actuator's torque (N m) over one step against t/T, with the
    actuator's bounds from the model (dashed); dots mark the transcription's knots."""
    sty = _styles(curves, styles)
    # Every actuator of any gait, the model with most actuators first, in model order: a
    # gait without one (passive ankles, gaitopt.study.plan.passive_ankles) has no curve in
    # its panel.
    names: list[str] = []
    for _, gait in sorted(curves, key=lambda c: -len(c[1].model.actuators)):
        names += [a.name for a in gait.model.actuators if a.name not in names]
    ncols = (len(names) + 1) // 2
    fig = new_figure(3.0 * ncols + 1.0, 5.8)
    axes = np.atleast_1d(fig.subplots(2, ncols, sharex=True)).ravel()
    peak = np.zeros(len(names))
    for (label, gait), style in zip(curves, sty, strict=True):
        s = gait.samples
        tau = (s.t - s.t[0]) / gait.step_time
        own = {a.name: i for i, a in enumerate(gait.model.actuators)}
        for j, ax in enumerate(axes[: len(names)]):
            if names[j] not in own:
                continue
            i = own[names[j]]
            ax.plot(tau, s.u[:, i], label=label, **style)
            for phase in gait.phases:
                ax.plot((phase.t - s.t[0]) / gait.step_time, phase.u[:, i], linestyle="none",
                        marker="o", markersize=2.2, color=style.get("color"))
            peak[j] = max(peak[j], float(np.max(np.abs(s.u[:, i]))))
    for j, ax in enumerate(axes[: len(names)]):
        bounds = sorted({b for _, g in curves for a in g.model.actuators
                         if a.name == names[j] for b in a.limits})
        for b in bounds:
            ax.axhline(b, **BOUND_LINE)
        reach = max(abs(b) for b in bounds) if bounds else 0.0
        top = max(peak[j] * 1.15, 1.0)
        if reach > 0 and top >= 0.6 * reach:
            top = max(top, 1.08 * reach)
        ax.set_ylim(-top, top)
        ax.set_title(f"{names[j]}   (bounds {', '.join(f'{b:g}' for b in bounds)} N m)",
                     fontsize=9)
        ax.set_ylabel("torque  [N m]", fontsize=8)
        _event_lines(ax, curves, 1)
        ax.grid(alpha=0.3)
    for ax in axes[len(names):]:
        ax.set_visible(False)
    for ax in axes[-ncols:]:
        ax.set_xlabel("normalized time t / T")
    _legend(fig, axes[0])
    fig.suptitle(title, fontsize=10)
    return fig
