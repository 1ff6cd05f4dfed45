"""A gait in a notebook: its summary table, a figure, an animation.

:class:`~gaitopt.gait.gait_file.Gait` calls these from ``_repr_html_`` (Jupyter shows the
summary table when a gait is the value of a cell), :meth:`~gaitopt.gait.gait_file.Gait.plot`
and :meth:`~gaitopt.gait.gait_file.Gait.animate`. The gait record sits below ``viz/`` and
never imports this module: it finds it through :mod:`gaitopt.views` (this module is a
:class:`~gaitopt.views.GaitViews`), where the front door installs its loader; nothing here is
imported until a view is first asked for.
"""

from __future__ import annotations

import base64
import html
import os
import tempfile
import weakref
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from gaitopt.fileio import write_bytes_atomic
from gaitopt.viz.animation import animate_gait
from gaitopt.viz.costate_figures import costates_figure
from gaitopt.viz.gait_figures import heights_figure, hip_motion_figure, torques_figure
from gaitopt.viz.stick import stick_strip_figure
from gaitopt.viz.style import BOUND_LINE, EVENT_LINE, gait_style, new_figure

if TYPE_CHECKING:
    from gaitopt.gait.gait_file import Gait

#: Figure kinds of :func:`gait_figure`.
KINDS = ("overview", "torques", "hip", "heights", "poses", "costates")

_VERDICTS: weakref.WeakKeyDictionary[Gait, str] = weakref.WeakKeyDictionary()


def verify_verdict(gait: Gait) -> str:
    """``"passed (24 checks)"``, ``"FAILED: id, id"`` or why it was not run; computed once per
    gait object (about 0.2 s for the default gait)."""
    if gait in _VERDICTS:
        return _VERDICTS[gait]
    if not gait.success:
        verdict = "not run (the solve failed)"
    else:
        from gaitopt.analysis.verify import verify_gait

        try:
            report = verify_gait(gait)
        except ValueError as exc:  # e.g. state names of an unknown formulation
            verdict = f"not run ({exc})"
        else:
            verdict = (f"passed ({len(report.checks)} checks)" if report.passed
                       else f"FAILED: {', '.join(report.failed_ids)}")
    _VERDICTS[gait] = verdict
    return verdict


def summary_rows(gait: Gait, *, verify: bool = True) -> list[tuple[str, str]]:
    """The summary as ``(quantity, value)`` rows of text (SI units; speed also in m/min)."""
    p, s = gait.parameters, gait.solver
    phases = " + ".join(f"{ph.name} ({ph.t.size} knots)" for ph in gait.phases)
    rows = [
        ("model", str(gait.model_data.get("name", ""))),
        ("variant", _variant(gait)),
        ("speed", f"{p['speed'] * 60:.3f} m/min ({p['speed']:.4f} m/s)"),
        ("step length", f"{p['step_length']:.4f} m"),
        ("step time", f"{p['step_time']:.4f} s (single support {p['single_support_time']:.4f} s)"),
        ("liftoff impulse", f"{p['liftoff_impulse']:.4f} N s"),
        ("cost (energy per metre)", f"{gait.cost_value:.6g} N^2 m s"),
        ("solver", f"{gait.status} ({'converged' if gait.success else 'FAILED'}), "
                   f"{s['iterations']} iterations, {s['wall_time_s']:.2f} s"),
        ("largest constraint violation", f"{s['max_violation']:.3g}"),
        ("phases", phases),
    ]
    if verify:
        rows.append(("verify", verify_verdict(gait)))
    return rows


def _variant(gait: Gait) -> str:
    ankle, impulse = gait.options.get("ankle"), gait.options.get("impulse")
    if ankle is None or impulse is None:
        return "?"
    return {(True, True): "ankle+impulse", (True, False): "ankle",
            (False, True): "impulse", (False, False): "plain"}[(bool(ankle), bool(impulse))]


def summary_html(gait: Gait, *, verify: bool = True) -> str:
    """An HTML table of :func:`summary_rows` (what Jupyter shows for a gait)."""
    body = "".join(f"<tr><th style='text-align:left'>{html.escape(a)}</th>"
                   f"<td style='text-align:left'>{html.escape(b)}</td></tr>"
                   for a, b in summary_rows(gait, verify=verify))
    return f"<table><caption>gait</caption>{body}</table>"


def gait_figure(gait: Gait, kind: str = "overview") -> Figure:
    """A figure of the gait: ``overview`` (joint angles, hip height and velocity, torques
    against time over one step), or one of the report's figures: ``torques`` (paper Figs.
    7-8), ``hip`` (Fig. 5), ``heights`` (Fig. 6), ``poses`` (stick figures over the step),
    ``costates`` (the recorded costates per phase, :mod:`gaitopt.viz.costate_figures`)."""
    label = f"{gait.speed * 60:.1f} m/min"
    if kind == "overview":
        return overview_figure(gait)
    if kind == "torques":
        return torques_figure([(label, gait)])
    if kind == "hip":
        return hip_motion_figure([(label, gait)])
    if kind == "heights":
        return heights_figure([(label, gait)])
    if kind == "poses":
        return stick_strip_figure(gait)
    if kind == "costates":
        return costates_figure(gait)
    raise ValueError(f"kind: got {kind!r}; allowed: {', '.join(KINDS)}")


def overview_figure(gait: Gait) -> Figure:
    """Three panels against time (s) over one step, knots as dots, the heel strike as a grey
    line: the joint and torso angles (rad); the hip height (m) and forward velocity (m/s);
    every actuator's torque (N m) with its bounds dashed."""
    model, s = gait.model, gait.samples
    fig = new_figure(7.5, 8.0)
    ax_q, ax_h, ax_u = fig.subplots(3, 1, sharex=True)
    t = s.t - s.t[0]
    names = model.coordinate_names
    for j, name in enumerate(names[2:], start=2):  # the angles: base angle and joints
        style = gait_style(j - 2)
        ax_q.plot(t, s.q[:, j], label=name, **style)
        for ph in gait.phases:
            ax_q.plot(ph.t - s.t[0], ph.q[:, j], "o", markersize=2.2, color=style["color"])
    ix = names.index("x")
    ax_h.plot(t, s.points["hip"][:, 1], label="hip height [m]", **gait_style(0))
    ax_h.plot(t, s.qd[:, ix], label="hip forward velocity [m/s]", **gait_style(1))
    for j, act in enumerate(model.actuators):
        style = gait_style(j)
        ax_u.plot(t, s.u[:, j], label=act.name, **style)
        for ph in gait.phases:
            ax_u.plot(ph.t - s.t[0], ph.u[:, j], "o", markersize=2.2, color=style["color"])
    for b in sorted({b for a in model.actuators for b in a.limits}):
        ax_u.axhline(b, **BOUND_LINE)
    peak = float(np.max(np.abs(s.u))) if s.u.size else 1.0
    ax_u.set_ylim(-1.15 * max(peak, 1.0), 1.15 * max(peak, 1.0))
    for ax, ylabel in ((ax_q, "angle [rad]"), (ax_h, "m, m/s"), (ax_u, "torque [N m]")):
        ax.axvline(gait.parameters["single_support_time"], **EVENT_LINE)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncols=3, loc="best")
    ax_u.set_xlabel("time in the step [s] (grey line: heel strike; dots: knots)")
    fig.suptitle(f"{gait.speed * 60:.1f} m/min, step {gait.step_length:.3f} m, cost "
                 f"{gait.cost_value:.4g} N^2 m s", fontsize=10)
    return fig


@dataclass(frozen=True)
class GifAnimation:
    """An animated GIF in memory: Jupyter shows it inline (``_repr_html_``); :meth:`save`
    writes it."""

    data: bytes
    frames: int
    duration_s: float

    def _repr_html_(self) -> str:
        b64 = base64.b64encode(self.data).decode("ascii")
        return f'<img src="data:image/gif;base64,{b64}" alt="gait animation"/>'

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the GIF atomically to ``path``."""
        target = Path(path)
        write_bytes_atomic(target, self.data)
        return target


def animate(gait: Gait, path: str | os.PathLike[str] | None = None, *, steps: int = 4,
            fps: int = 30) -> Path | GifAnimation:
    """:func:`gaitopt.viz.animation.animate_gait` to ``path`` (returns the path), or, without
    a path, a :class:`GifAnimation` to show inline."""
    if path is not None:
        return animate_gait(gait, path, steps=steps, fps=fps).path
    with tempfile.TemporaryDirectory() as tmp:
        info = animate_gait(gait, Path(tmp) / "gait.gif", steps=steps, fps=fps)
        return GifAnimation(info.path.read_bytes(), info.frames, info.duration_s)
