"""The cost study's figure and report (docs/costs.md; the study is
:mod:`gaitopt.study.cost_study`).

``write_cost_report(study_dir, out_dir, compare=())`` reads ``costs.csv`` (and that of each
other cost study in ``compare``: their models drawn beside this study's, for example a model
with feet solved on another grid) and writes to ``out_dir``:

* ``report.html``: the answer (the case nearest to people's walk, per model), the figure, the
  table of every (model, case) optimum ranked by its distance from people's walk, and the
  findings of :mod:`gaitopt.study.cost_findings` per model; one self-contained file;
* ``resting_power.png`` / ``.svg``: the optimal speed and step length against the resting
  power of the metabolic cost, one line per model, the paper and work optima as horizontal
  lines, people's values (80 m/min, 0.75 m) and resting power (1.2-1.5 W/kg) marked.
"""

from __future__ import annotations

import html
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from gaitopt.fileio import write_text_atomic
from gaitopt.study.cost_findings import assess_cost_findings, physiological, ranked
from gaitopt.study.cost_study import HUMAN_RESTING_POWER
from gaitopt.study.cost_table import (
    COST_TABLE_FILE,
    CostRow,
    CostStudyError,
    read_cost_table,
)
from gaitopt.study.findings import (
    HUMAN_OPTIMAL_SPEED_M_MIN,
    HUMAN_STEP_LENGTH,
    Findings,
    findings_html,
)
from gaitopt.viz.report import html_page
from gaitopt.viz.style import new_figure, png_data_uri, save_figure

FIGURE_STEM = "resting_power"
_TIME_FREE_STYLES = {"paper": (0, (1, 1.5)), "work": (0, (4, 2))}


@dataclass(frozen=True)
class CostReportInfo:
    """What :func:`write_cost_report` wrote, the rows it read and the findings of each
    model."""

    html: Path
    figures: tuple[Path, ...]
    findings: dict[str, Findings]
    rows: tuple[CostRow, ...] = ()


def resting_power_figure(rows: Sequence[CostRow]) -> Figure:
    """Optimal speed (m/min) and step length (m) of the metabolic cost against its resting
    power (W/kg), a line per model; the paper and work optima as horizontal lines in the
    model's colour; people's speed, step and resting power marked (grey)."""
    fig = new_figure(10.0, 4.2)
    axes = fig.subplots(1, 2)
    models = list(dict.fromkeys(r.model for r in rows))
    for ax, column, human, label in (
            (axes[0], "speed_m_min", HUMAN_OPTIMAL_SPEED_M_MIN, "optimal speed  [m/min]"),
            (axes[1], "step_length", HUMAN_STEP_LENGTH, "optimal step length  [m]")):
        ax.axvspan(*HUMAN_RESTING_POWER, color="0.85", zorder=0,
                   label=f"people's resting power ({HUMAN_RESTING_POWER[0]:g}-"
                         f"{HUMAN_RESTING_POWER[1]:g} W/kg)")
        ax.axhline(human, color="0.4", linewidth=1.2, linestyle="--",
                   label=f"people: about {human:g} {'m/min' if column == 'speed_m_min' else 'm'}")
        for k, model in enumerate(models):
            color = f"C{k % 10}"
            metabolic = sorted((r for r in rows if r.model == model and r.cost == "metabolic"
                                and r.success), key=lambda r: r.resting_power)
            if metabolic:
                ax.plot([r.resting_power for r in metabolic],
                        [getattr(r, column) for r in metabolic], "o-", color=color,
                        label=f"{model} ({metabolic[0].formulation}): metabolic cost")
            for r in rows:
                if r.model == model and r.cost in _TIME_FREE_STYLES and r.success:
                    ax.axhline(getattr(r, column), color=color, linewidth=1.0,
                               linestyle=_TIME_FREE_STYLES[r.cost],
                               label=f"{model}: {r.cost} cost (no resting term)")
        powers = [r.resting_power for r in rows if r.cost == "metabolic" and r.success]
        ax.set_xlim(-0.1, 1.05 * max([HUMAN_RESTING_POWER[1], *powers]) + 0.1)
        ax.set_xlabel("resting power of the metabolic cost  [W/kg]")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0.0, top=max(1.15 * human, ax.get_ylim()[1]))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, loc="lower right")
    fig.suptitle("Speed-free optimum against the resting power (metabolic cost)", fontsize=10)
    return fig


def _fmt(x: float, spec: str) -> str:
    return "–" if not math.isfinite(x) else format(x, spec)


def cost_table_html(rows: Sequence[CostRow]) -> str:
    """Every (model, case) optimum, nearest to people's walk first, people's row last."""
    head = ("<table><thead><tr><th>model</th><th>formulation</th><th>cost</th>"
            "<th>resting power [W/kg]</th><th>speed [m/min]</th><th>step length [m]</th>"
            "<th>step time [s]</th><th>cost value</th><th>distance from people's walk</th>"
            "<th>start (the other start's cost)</th><th>status</th></tr></thead><tbody>")
    body = []
    for r in ranked(rows):
        body.append(
            f"<tr class='{'ok' if r.success else 'failed'}'><td>{html.escape(r.model)}</td>"
            f"<td>{html.escape(r.formulation)}</td><td>{html.escape(r.cost)}</td>"
            f"<td>{_fmt(r.resting_power, 'g')}</td><td>{_fmt(r.speed_m_min, '.1f')}</td>"
            f"<td>{_fmt(r.step_length, '.3f')}</td><td>{_fmt(r.step_time, '.3f')}</td>"
            f"<td>{_fmt(r.cost_value, '.4g')}</td><td>{_fmt(r.human_distance, '.2f')}</td>"
            f"<td>{html.escape(r.start)} ({_fmt(r.other_cost_value, '.4g')})</td>"
            f"<td>{html.escape(r.status)}</td></tr>")
    lo, hi = HUMAN_RESTING_POWER
    body.append(f"<tr class='paper'><td>people</td><td></td><td>metabolic</td><td>{lo:g}-{hi:g}"
                f"</td><td>≈ {HUMAN_OPTIMAL_SPEED_M_MIN:g}</td><td>≈ {HUMAN_STEP_LENGTH:g}</td>"
                "<td></td><td></td><td>0</td><td></td><td></td></tr>")
    return head + "".join(body) + "</tbody></table>"


def answer_text(rows: Sequence[CostRow]) -> list[str]:
    """One sentence per model: its optimum nearest to people's walk among the cases with
    people's settings (and among all cases, when another is nearer)."""
    out = []
    for model in dict.fromkeys(r.model for r in rows):
        solved = ranked([r for r in rows if r.model == model and r.success])
        human = [r for r in solved if physiological(r)]
        if not human:
            out.append(f"{model}: no case with people's settings solved.")
            continue
        text = f"{model} ({human[0].formulation}): nearest to people's walk " + _where(human[0])
        if solved[0] is not human[0]:
            text += "; of all cases " + _where(solved[0])
        out.append(text + ".")
    return out


def _where(r: CostRow) -> str:
    bound = " (at its speed bound)" if "speed bound" in r.status else ""
    return (f"the {r.case} cost, {r.speed_m_min:.1f} m/min{bound} with {r.step_length:.3f} m "
            f"steps ({r.speed_m_min / HUMAN_OPTIMAL_SPEED_M_MIN:.0%} of people's speed, "
            f"{r.step_length / HUMAN_STEP_LENGTH:.0%} of their step)")


def study_rows(study_dir: str | os.PathLike[str],
               compare: Sequence[str | os.PathLike[str]] = ()) -> list[CostRow]:
    """The rows of ``study_dir/costs.csv`` followed by those of each study in ``compare``.

    Raises :class:`gaitopt.study.cost_table.CostStudyError` if a table is missing or invalid,
    or if a model's name appears in two of the studies (its rows could not be told apart)."""
    rows = read_cost_table(Path(study_dir) / COST_TABLE_FILE)
    for other in compare:
        more = read_cost_table(Path(other) / COST_TABLE_FILE)
        seen = {r.model for r in rows}
        twice = sorted({r.model for r in more} & seen)
        if twice:
            raise CostStudyError(f"{other}: model {', '.join(twice)} is in two of the compared "
                                 "cost studies; compare studies of different models")
        rows += more
    return rows


def write_cost_report(study_dir: str | os.PathLike[str], out_dir: str | os.PathLike[str], *,
                      compare: Sequence[str | os.PathLike[str]] = (),
                      svg: bool = True) -> CostReportInfo:
    """Write the cost study's report (module docstring) from ``study_dir/costs.csv`` and
    those of ``compare``.

    Raises :class:`gaitopt.study.cost_table.CostStudyError` if a table is missing or
    invalid, or if two studies hold the same model."""
    rows = study_rows(study_dir, compare)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    findings = dict(assess_cost_findings(rows))
    paths, png = save_figure(resting_power_figure(rows), out, FIGURE_STEM, svg=svg)
    sections = ["<h2>Answer</h2><ul>" + "".join(f"<li>{html.escape(t)}</li>"
                                                 for t in answer_text(rows)) + "</ul>"]
    sections.append("<h2>Optimal speed and step length against the resting power</h2>"
                    f"<figure><img alt='{FIGURE_STEM}' src='{png_data_uri(png)}'><figcaption>"
                    "Speed-free optimum of the metabolic cost against its resting power "
                    "(points), of the paper's and the work cost (horizontal lines); people's "
                    "speed and step (dashed grey) and resting power (grey band)."
                    "</figcaption></figure>")
    sections.append("<h2>Every optimum, nearest to people's walk first</h2>"
                    + cost_table_html(rows)
                    + "<p>Distance: sqrt((v / 80 m/min - 1)² + (L / 0.75 m - 1)²); 0 is "
                    "people's walk, 0.5 half their speed at their step, 1.41 standing still.</p>")
    for model, items in findings.items():
        sections.append(f"<h2>Findings: {html.escape(model)}</h2>"
                        + findings_html(items, heading="claim",
                                        anchor_prefix=f"finding-{model}-"))
    intro = ("<p>Which cost puts the optimal walk where people walk (about "
             f"{HUMAN_OPTIMAL_SPEED_M_MIN:g} m/min, {HUMAN_STEP_LENGTH:g} m steps)? The "
             "speed-free optimum of the paper's cost, the mechanical cost of transport (work) "
             "and the metabolic cost at several resting powers; formulas in docs/costs.md.</p>")
    page = html_page("gaitopt cost study", intro, sections)
    path = out / "report.html"
    write_text_atomic(path, page)
    return CostReportInfo(html=path, figures=tuple(paths), findings=findings,
                          rows=tuple(rows))
