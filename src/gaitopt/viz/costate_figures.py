"""The costates a gait record carries (:attr:`gaitopt.gait.record.parts.GaitPhase.costates`).

The costate ``lambda_j`` of state ``j`` is the sensitivity of the cost to that state at that
instant (cost per unit of the state; sign convention ``H = L + lambda^T f``,
:func:`gaitopt.ocp.costates`): one panel per phase, one line per state (the knots as dots,
joined), against time since the step's start (s). States of different units share a panel,
on a symmetric log scale (linear within +-1).
"""

from __future__ import annotations

from matplotlib.figure import Figure

from gaitopt.gait.record.file import Gait
from gaitopt.viz.style import EVENT_LINE, gait_style, new_figure


def costates_figure(gait: Gait) -> Figure:
    """One panel per phase with costates, each state's costate at the knots against time
    (s since the step's start). Raises ValueError when no phase has costates (a file written
    before they existed, or a transcription that gives none)."""
    phases = [ph for ph in gait.phases if ph.costates is not None]
    if not phases:
        raise ValueError("the gait has no costates (a file written before they were "
                         "recorded, or phases with states given by others)")
    t0 = gait.phases[0].t[0]
    fig = new_figure(7.5, 2.0 + 2.6 * len(phases))
    axes = fig.subplots(len(phases), 1, sharex=True, squeeze=False)[:, 0]
    for ax, ph in zip(axes, phases, strict=True):
        assert ph.costates is not None
        for j, name in enumerate(ph.state_names):
            ax.plot(ph.t - t0, ph.costates[:, j], marker="o", markersize=2.5, label=name,
                    color=f"C{j % 10}", linestyle=gait_style(j)["linestyle"])
        ax.axvline(ph.t[-1] - t0, **EVENT_LINE)
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_ylabel(f"{ph.name}\ncostate [cost / state unit]", fontsize=8)
        ax.set_gid(f"costates:{ph.name}")
        ax.legend(fontsize=6, ncols=2, loc="best", frameon=False)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time since the step's start [s]")
    fig.suptitle("costates at the knots (H = L + lambda^T f)", fontsize=10)
    return fig
