"""Sweeps side by side: energy and step length against speed for several sweeps (other models,
gaits or settings), with human walking marked, and a table of their speed-free optima.

``gaitopt report SWEEP --compare OTHER`` adds this section to the report of ``SWEEP``: for
example the seven-link model's heel-toe sweep against the same adult with point feet, or a
design change against the original. Each sweep is drawn in its own colour, its variants in the
paper's line styles (:data:`gaitopt.viz.style.VARIANT_STYLES`); a star marks each variant's
speed-free optimum. Costs are compared as they are (N^2 m s per metre for the paper's cost):
they are comparable between sweeps of the same body and cost, not across bodies of different
mass.

Human walking, for reference: the energy per metre of people is least at about
:data:`~gaitopt.study.findings.HUMAN_OPTIMAL_SPEED_M_MIN` (80 m/min, 1.33 m/s) with steps of
about :data:`~gaitopt.study.findings.HUMAN_STEP_LENGTH` (0.75 m).
"""

from __future__ import annotations

import html
import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from gaitopt.gait.sequence.knots import knots_text
from gaitopt.study.findings import HUMAN_OPTIMAL_SPEED_M_MIN, HUMAN_STEP_LENGTH, optimal_row
from gaitopt.study.plan import SETTINGS_FILE
from gaitopt.study.summary import SUMMARY_FILE, VARIANTS, SummaryRow, read_summary, rows_of
from gaitopt.viz.style import VARIANT_LABELS, VARIANT_STYLES, new_figure

#: Colours of the compared sweeps, in order (the report's own sweep first).
SWEEP_COLORS: tuple[str, ...] = ("C0", "C3", "C2", "C1", "C4", "C5", "C6", "C7")


@dataclass(frozen=True)
class ComparedSweep:
    """One sweep of a comparison: a label (model, gait, grid), its rows and its folder."""

    label: str
    rows: tuple[SummaryRow, ...]
    path: Path


def load_compared_sweep(directory: str | os.PathLike[str]) -> ComparedSweep:
    """The rows of the sweep in ``directory`` and a label from its ``sweep.json`` (model name,
    gait and knots); raises :class:`gaitopt.study.summary.SummaryError` without a summary."""
    folder = Path(directory)
    rows = read_summary(folder / SUMMARY_FILE)
    return ComparedSweep(sweep_label(folder), tuple(rows), folder)


def sweep_label(folder: Path) -> str:
    """``model (gait, knots)`` from the sweep's settings, else the folder's name."""
    try:
        settings = json.loads((folder / SETTINGS_FILE).read_text())["settings"]
        options = settings.get("options", {})
        knots = knots_text(options.get("knots", ()))
        gait = ("custom sequence" if options.get("contact_sequence")
                else options.get("gait", "walk"))
        return f"{settings['model']['name']} ({gait}, {knots} knots)"
    except (OSError, ValueError, KeyError, TypeError):
        return folder.resolve().name


def comparison_figure(sweeps: Sequence[ComparedSweep]) -> Figure:
    """Cost (left) and step length (right) against speed, one colour per sweep and the paper's
    line style per variant; stars: speed-free optima; grey: human walking (speed of least
    energy per metre, and its step length)."""
    fig = new_figure(11.0, 4.6)
    cost_ax, step_ax = fig.subplots(1, 2)
    for k, sweep in enumerate(sweeps):
        color = SWEEP_COLORS[k % len(SWEEP_COLORS)]
        for variant in VARIANTS:
            fixed = rows_of(sweep.rows, variant, speed_mode="fixed")
            free = rows_of(sweep.rows, variant, speed_mode="free")
            label = f"{sweep.label}: {VARIANT_LABELS[variant]}"
            for ax, column in ((cost_ax, "cost"), (step_ax, "step_length")):
                if fixed:
                    ax.plot([r.speed_m_min for r in fixed], [getattr(r, column) for r in fixed],
                            color=color, linestyle=VARIANT_STYLES[variant]["linestyle"],
                            marker="o", markersize=2.5, linewidth=1.5,
                            label=label if ax is cost_ax else "_nolegend_",
                            gid=f"sweep{k}:{variant}")
                for r in free:
                    ax.plot([r.speed_m_min], [getattr(r, column)], marker="*", markersize=13,
                            linestyle="none", color=color, markeredgecolor="k",
                            markeredgewidth=0.6, label="_nolegend_",
                            gid=f"sweep{k}:optimum:{variant}")
    human = {"color": "0.4", "linewidth": 1.2, "linestyle": (0, (4, 2))}
    cost_ax.axvline(HUMAN_OPTIMAL_SPEED_M_MIN, label="people: least energy per metre", **human)
    step_ax.axvline(HUMAN_OPTIMAL_SPEED_M_MIN, **human)
    step_ax.axhline(HUMAN_STEP_LENGTH, **human)
    step_ax.plot([HUMAN_OPTIMAL_SPEED_M_MIN], [HUMAN_STEP_LENGTH], marker="D", color="0.3",
                 linestyle="none", label="people's walk")
    cost_ax.set_ylabel("cost (energy per metre)  [N² m s]")
    step_ax.set_ylabel("optimal step length  [m]")
    for ax in (cost_ax, step_ax):
        ax.set_xlabel("average forward speed v  [m/min]")
        ax.grid(alpha=0.3)
    cost_ax.legend(fontsize=7, loc="best")
    step_ax.legend(fontsize=7, loc="lower right")
    cost_ax.set_title("energy per metre against speed (★: speed-free optimum)", fontsize=10)
    step_ax.set_title("step length against speed", fontsize=10)
    return fig


def _cell(x: float, spec: str) -> str:
    return format(x, spec) if math.isfinite(x) else "-"


def comparison_table_html(sweeps: Sequence[ComparedSweep]) -> str:
    """The speed-free optimum (or the cheapest solved speed) of every variant of every sweep,
    with people's walk as the last row."""
    lines = ["<table><tr><th>sweep</th><th>variant</th><th>speed (m/min)</th>"
             "<th>step length (m)</th><th>cost (N² m s)</th><th>kind</th></tr>"]
    for sweep in sweeps:
        for variant in VARIANTS:
            row = optimal_row(list(sweep.rows), variant)
            if row is None:
                continue
            kind = "speed free" if row.speed_mode == "free" else "cheapest solved speed"
            lines.append(f"<tr><td>{html.escape(sweep.label)}</td><td>{variant}</td>"
                         f"<td>{_cell(row.speed_m_min, '.1f')}</td>"
                         f"<td>{_cell(row.step_length, '.3f')}</td>"
                         f"<td>{_cell(row.cost, '.1f')}</td><td>{kind}</td></tr>")
    lines.append(f"<tr><td>people (least energy per metre)</td><td>-</td>"
                 f"<td>{HUMAN_OPTIMAL_SPEED_M_MIN:.0f}</td><td>{HUMAN_STEP_LENGTH:.2f}</td>"
                 f"<td>-</td><td>measured</td></tr>")
    return "\n".join(lines) + "</table>"


def comparison_text(sweeps: Sequence[ComparedSweep]) -> list[str]:
    """One line per sweep and variant: its optimum against people's walk (for the terminal)."""
    out = []
    for sweep in sweeps:
        for variant in VARIANTS:
            row = optimal_row(list(sweep.rows), variant)
            if row is None:
                continue
            out.append(f"{sweep.label}, {variant}: {row.speed_m_min:.1f} m/min, "
                       f"{row.step_length:.3f} m, cost {row.cost:.1f} (people: "
                       f"{HUMAN_OPTIMAL_SPEED_M_MIN:.0f} m/min, {HUMAN_STEP_LENGTH:.2f} m)")
    return out


def comparison_caption(sweeps: Sequence[ComparedSweep]) -> str:
    names = "; ".join(f"{SWEEP_COLORS[k % len(SWEEP_COLORS)]}: {s.label} ({s.path})"
                      for k, s in enumerate(sweeps))
    return ("Sweeps compared (colour: sweep; line style: variant as in Fig. 3). "
            f"{names}. Grey: people's walk, least energy per metre at "
            f"{HUMAN_OPTIMAL_SPEED_M_MIN:.0f} m/min with {HUMAN_STEP_LENGTH:.2f} m steps.")


__all__ = ["ComparedSweep", "comparison_caption", "comparison_figure",
                      "comparison_table_html", "comparison_text", "load_compared_sweep",
                      "sweep_label"]
