"""A figure of people's sagittal joint angles over one stride, several gaits overlaid.

Input: ``(label, gait)`` pairs. Panels: hip flexion, knee flexion and ankle dorsiflexion (deg)
of leg 1 against % of its stride, heel strike at 0 (definitions:
:mod:`gaitopt.analysis.joint_angles`), each gait's toe-off as a dotted vertical line; a fourth
panel compares the four measures (:func:`gaitopt.analysis.joint_angles.people_measures`) of
every gait with the published values of people (grey bands for a range, black lines for an
"about" value). The knee panel also draws people's stance peak (15-20 deg, over the first half
of stance) and swing peak (about 60 deg) as bands over the stride, since the sources give
peaks, not curves.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from gaitopt.analysis.joint_angles import (
    MEASURES,
    PEOPLE,
    joint_angle_stride,
    people_measures,
)
from gaitopt.gait.record.file import Gait
from gaitopt.viz.style import gait_style, new_figure

#: Short labels of the measures on the fourth panel.
SHORT_LABELS: dict[str, str] = {
    "stance_knee_flexion": "stance knee\nflexion peak",
    "swing_knee_flexion": "swing knee\nflexion peak",
    "hip_excursion": "hip\nexcursion",
    "ankle_excursion": "ankle\nexcursion",
}
PEOPLE_BAND = {"color": "0.82", "zorder": 0}


def joint_angles_figure(curves: Sequence[tuple[str, Gait]], *,
                        title: str = "sagittal joint angles over one stride") -> Figure:
    """Hip, knee and ankle angles (deg) over one stride per gait, and the four measures
    against people's (module docstring)."""
    if not curves:
        raise ValueError("no gaits to plot")
    fig = new_figure(9.0, 6.5)
    axes = fig.subplots(2, 2)
    ax_hip, ax_knee, ax_ankle, ax_bar = axes.ravel()
    strides = [(label, joint_angle_stride(gait)) for label, gait in curves]
    for i, (label, a) in enumerate(strides):
        style = gait_style(i)
        for ax, y in ((ax_hip, a.hip), (ax_knee, a.knee), (ax_ankle, a.ankle)):
            ax.plot(a.percent, y, label=label, **style)
            ax.axvline(a.stance_end, color=style["color"], linewidth=0.8, linestyle=":")
    low, high = PEOPLE["stance_knee_flexion"]
    ax_knee.axhspan(low, high, **PEOPLE_BAND, label=f"people: stance peak {low:g}-{high:g}°")
    swing = PEOPLE["swing_knee_flexion"][0]
    ax_knee.axhline(swing, color="k", linewidth=1.0, linestyle=(0, (6, 3)),
                    label=f"people: swing peak about {swing:g}°")
    ax_knee.legend(fontsize=7, loc="upper left", frameon=False)
    for ax, name in ((ax_hip, "hip flexion  [deg]"), (ax_knee, "knee flexion  [deg]"),
                     (ax_ankle, "ankle dorsiflexion  [deg]")):
        ax.set_ylabel(name)
        ax.set_xlim(0.0, 100.0)
        ax.set_xlabel("% of stride (heel strike at 0; dotted: toe-off)")
        ax.grid(alpha=0.3)
    ax_hip.set_title(f"hip: people's excursion about {PEOPLE['hip_excursion'][0]:g}°",
                     fontsize=8)
    ax_ankle.set_title(f"ankle: people's excursion about {PEOPLE['ankle_excursion'][0]:g}°",
                       fontsize=8)
    x = np.arange(len(MEASURES))
    width = 0.8 / len(strides)
    for j, name in enumerate(MEASURES):
        low, high = PEOPLE[name]
        if high > low:
            ax_bar.fill_between([j - 0.45, j + 0.45], low, high, **PEOPLE_BAND)
        else:
            ax_bar.plot([j - 0.45, j + 0.45], [low, low], color="k", linewidth=1.5)
    for i, (label, a) in enumerate(strides):
        m = people_measures(a)
        ax_bar.bar(x - 0.4 + width * (i + 0.5), [m[n] for n in MEASURES], width,
                   color=gait_style(i)["color"], label=label)
    ax_bar.set_xticks(x, [SHORT_LABELS[n] for n in MEASURES], fontsize=7)
    ax_bar.set_ylabel("deg")
    ax_bar.set_title("measures; people: grey band (range) or black line (about)", fontsize=8)
    ax_bar.grid(alpha=0.3, axis="y")
    handles, labels = ax_hip.get_legend_handles_labels()
    legend = fig.legend(handles, labels, loc="outside lower center", fontsize=8,
                        ncols=min(len(labels), 3), frameon=False)
    legend.set_gid("gaits")
    fig.suptitle(title, fontsize=10)
    return fig
