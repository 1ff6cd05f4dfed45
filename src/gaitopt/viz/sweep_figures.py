"""Figures of a speed sweep: energy per metre (paper Fig. 3) and step length (Fig. 4) against
speed, one line per variant, from the rows of ``summary.csv``.

Speeds are shown in m/min as in the paper. Only successful rows are drawn; fixed-speed rows
make the lines, the speed-free optimum of each variant is a star.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from gaitopt.study.summary import VARIANTS, SummaryRow, rows_of
from gaitopt.viz.style import VARIANT_LABELS, VARIANT_STYLES, new_figure

COST_LABEL = "cost J = (∫uᵀu dt + P²) / step length  [N² m s]"
HUMAN_LABEL = "human $E_m$ = 32/v + 0.005 v  [cal/kg/m]"


def human_energy(v_m_min: ArrayLike) -> NDArray[np.float64]:
    """Human walking energy per metre, E_m = 32/v + 0.005 v (cal/kg/m, v in m/min; paper
    eq. 6), minimal at v = 80 m/min."""
    v = np.asarray(v_m_min, dtype=float)
    return 32.0 / v + 0.005 * v


def _variant_lines(ax: Axes, rows: Sequence[SummaryRow], column: str) -> None:
    for variant in VARIANTS:
        fixed = rows_of(rows, variant, speed_mode="fixed")
        free = rows_of(rows, variant, speed_mode="free")
        failed = len(rows_of(rows, variant, success=False))
        if not fixed and not free:
            continue
        style = VARIANT_STYLES[variant]
        label = VARIANT_LABELS[variant] + (f" ({failed} failed)" if failed else "")
        if fixed:
            ax.plot([r.speed_m_min for r in fixed], [getattr(r, column) for r in fixed],
                    marker="o", markersize=2.5, linewidth=1.6, label=label,
                    gid=f"variant:{variant}", **style)
            label = "_nolegend_"
        for r in free:
            ax.plot([r.speed_m_min], [getattr(r, column)], marker="*", markersize=13,
                    linestyle="none", color=style["color"], markeredgecolor="k",
                    markeredgewidth=0.6, label=label, gid=f"optimum:{variant}")
            label = "_nolegend_"

def energy_figure(rows: Sequence[SummaryRow], *, log_scale: bool = False) -> Figure:
    """Paper Fig. 3: the cost (energy per metre) against speed for the four variants, with the
    human curve E_m(v) on a twin axis (right) for comparing shapes."""
    fig = new_figure(7.5, 4.8)
    ax = fig.add_subplot()
    _variant_lines(ax, rows, "cost")
    ax.set_xlabel("average forward speed v  [m/min]")
    ax.set_ylabel(COST_LABEL)
    if log_scale:
        ax.set_yscale("log")
    speeds = [r.speed_m_min for r in rows if r.success and np.isfinite(r.speed_m_min)]
    human = ax.twinx()
    if speeds:
        v = np.linspace(max(min(speeds), 1.0), max(max(speeds), 1.0) + 1e-9, 200)
        human.plot(v, human_energy(v), color="0.45", linewidth=1.2, linestyle=(0, (1, 1.5)),
                   label="human (paper eq. 6)")
    human.set_ylabel(HUMAN_LABEL, color="0.35")
    human.tick_params(axis="y", colors="0.35")
    handles, labels = ax.get_legend_handles_labels()
    h2, l2 = human.get_legend_handles_labels()
    ax.legend(handles + h2, labels + l2, fontsize=8, loc="upper center")
    ax.set_title("Fig. 3  energy per metre against speed (★: speed-free optimum)", fontsize=10)
    ax.grid(alpha=0.3)
    return fig


def step_length_figure(rows: Sequence[SummaryRow]) -> Figure:
    """Paper Fig. 4: the optimal step length against speed for the four variants."""
    fig = new_figure(7.5, 4.5)
    ax = fig.add_subplot()
    _variant_lines(ax, rows, "step_length")
    ax.set_xlabel("average forward speed v  [m/min]")
    ax.set_ylabel("optimal step length  [m]")
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title("Fig. 4  optimal step length against speed (★: speed-free optimum)",
                 fontsize=10)
    ax.grid(alpha=0.3)
    return fig
