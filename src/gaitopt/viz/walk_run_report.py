"""The walk-run study's figure and report (docs/running.md; the study is
:mod:`gaitopt.study.walk_run`).

``write_walk_run_report(rows, transitions, out_dir)`` writes to ``out_dir``:

* ``walk_run.png`` / ``.svg``: cost against speed, one panel per (model, cost), one line per
  branch (converged points with the grid error estimate as an error bar, the cheapest at
  each speed ringed, failed points as crosses near the panel's bottom edge, a row per
  branch), the transition (the crossing, its grid-error interval shaded, the bracket
  dotted) and people's transition at the model's Froude number 0.5 (dashed grey);
* ``report.html``: the transitions, the figure, the table of every point and the findings of
  :mod:`gaitopt.study.walk_run_findings`; one self-contained file.
"""

from __future__ import annotations

import html
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from gaitopt.fileio import write_text_atomic
from gaitopt.study.findings import Findings, findings_html
from gaitopt.study.transition import HUMAN_TRANSITION_FROUDE
from gaitopt.study.walk_run import TransitionRow, WalkRunRow
from gaitopt.study.walk_run_findings import assess_walk_run
from gaitopt.viz.report import html_page
from gaitopt.viz.style import new_figure, png_data_uri, save_figure

FIGURE_STEM = "walk_run"
BRANCH_STYLES = {"walk": ("C0", "o", "-"), "heel-toe": ("C0", "o", "-"),
                 "walk-single-support": ("C2", "s", "--"), "run": ("C3", "^", "-")}
COST_LABELS = {"paper": "paper's cost  ∫u'u dt / L  [N² m s]",
               "metabolic": "metabolic cost of transport  [-]"}


@dataclass(frozen=True)
class WalkRunReportInfo:
    """What :func:`write_walk_run_report` wrote, and the findings by ``"<model> / <cost>"``."""

    html: Path
    figures: tuple[Path, ...]
    findings: Mapping[str, Findings]


def walk_run_figure(rows: Sequence[WalkRunRow], transitions: Sequence[TransitionRow]) -> Figure:
    """Cost against speed (m/min), a panel per (model, cost): see the module docstring."""
    models = list(dict.fromkeys(t.model for t in transitions))
    costs = list(dict.fromkeys(t.cost for t in transitions))
    fig = new_figure(5.5 * len(costs), 4.6 * len(models))
    axes = fig.subplots(len(models), len(costs), squeeze=False)
    for t in transitions:
        ax = axes[models.index(t.model)][costs.index(t.cost)]
        mine = [r for r in rows if r.model == t.model and r.cost == t.cost]
        for k, branch in enumerate(dict.fromkeys(r.branch for r in mine)):
            color, marker, line = BRANCH_STYLES.get(branch, ("C7", "o", "-"))
            pts = sorted((r for r in mine if r.branch == branch), key=lambda r: r.speed_m_min)
            ok = [r for r in pts if r.success and math.isfinite(r.cost_value)]
            failed = [r for r in pts if not r.success]
            ax.errorbar([r.speed_m_min for r in ok], [r.cost_value for r in ok],
                        yerr=[abs(r.cost_error) if math.isfinite(r.cost_error) else 0.0
                              for r in ok],
                        color=color, marker=marker, linestyle=line, markersize=4, capsize=2,
                        label=f"{branch} ({len(ok)}/{len(pts)} converged, x: failed)")
            best = [r for r in ok if r.cheapest]
            ax.plot([r.speed_m_min for r in best], [r.cost_value for r in best], linestyle="",
                    marker="o", markersize=11, markerfacecolor="none", markeredgecolor=color)
            if failed:
                ax.plot([r.speed_m_min for r in failed], [0.03 + 0.05 * k] * len(failed),
                        linestyle="", marker="x", markersize=7, color=color, clip_on=False,
                        transform=ax.get_xaxis_transform())
        if t.cost == "paper" and any(r.success and r.cost_value > 0 for r in mine):
            ax.set_yscale("log")
        tr = t.transition
        if tr.kind == "crossing":
            v = tr.speed * 60.0
            ax.axvspan(tr.interval[0] * 60.0, tr.interval[1] * 60.0, color="0.85", zorder=0)
            for b in tr.bracket:
                ax.axvline(b * 60.0, color="0.5", linestyle=":", linewidth=0.8)
            ax.axvline(v, color="k", linewidth=1.2,
                       label=f"transition {v:.1f} m/min (Froude {t.froude:.2f})")
        people = math.sqrt(HUMAN_TRANSITION_FROUDE * t.gravity * t.leg_length_m) * 60.0
        ax.axvline(people, color="0.4", linestyle="--", linewidth=1.0,
                   label=f"people's Froude {HUMAN_TRANSITION_FROUDE:g}: {people:.0f} m/min")
        ax.set_title(f"{t.model}: {t.cost} cost", fontsize=10)
        ax.set_xlabel("speed  [m/min]")
        ax.set_ylabel(COST_LABELS.get(t.cost, "cost"))
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=2)
    return fig


def _fmt(x: float, spec: str) -> str:
    return "–" if not math.isfinite(x) else format(x, spec)


def transitions_html(transitions: Sequence[TransitionRow]) -> str:
    """One row per (model, cost): the bracket, the crossing, its grid-error interval and
    their Froude numbers."""
    head = ("<table><thead><tr><th>model</th><th>cost</th><th>outcome</th>"
            "<th>bracket [m/min]</th><th>crossing [m/min]</th><th>grid error [m/min]</th>"
            "<th>Froude (interval)</th><th>leg length [m]</th><th>speeds skipped</th>"
            "</tr></thead><tbody>")
    body = []
    for t in transitions:
        tr = t.transition
        fr = t.froude
        lo, hi = (t.as_csv_dict()[k] for k in ("froude_low", "froude_high"))
        note = " (could leave the bracket)" if tr.leaves_bracket else ""
        body.append(
            f"<tr><td>{html.escape(t.model)}</td><td>{html.escape(t.cost)}</td>"
            f"<td>{html.escape(tr.kind)}</td>"
            f"<td>{_fmt(tr.bracket[0] * 60, 'g')}-{_fmt(tr.bracket[1] * 60, 'g')}</td>"
            f"<td>{_fmt(tr.speed * 60, '.1f')}</td>"
            f"<td>{_fmt(tr.interval[0] * 60, '.1f')}-{_fmt(tr.interval[1] * 60, '.1f')}"
            f"{note}</td><td>{_fmt(fr, '.2f')} ({_fmt(float(lo or 'nan'), '.2f')}-"
            f"{_fmt(float(hi or 'nan'), '.2f')})</td><td>{t.leg_length_m:.4f}</td>"
            f"<td>{html.escape(' '.join(f'{v * 60:g}' for v in tr.skipped)) or '–'}</td></tr>")
    return head + "".join(body) + "</tbody></table>"


def points_html(rows: Sequence[WalkRunRow]) -> str:
    """Every point: model, cost, speed, branch, cost and its grid error, step, first phase share,
    status; the cheapest at its speed in bold."""
    head = ("<table><thead><tr><th>model</th><th>cost</th><th>speed [m/min]</th>"
            "<th>Froude</th><th>branch</th><th>cost value</th><th>grid error</th>"
            "<th>step [m]</th><th>step time [s]</th><th>first phase share</th><th>status</th>"
            "</tr></thead><tbody>")
    body = []
    for r in sorted(rows, key=lambda r: (r.model, r.cost, r.speed_m_min, r.branch)):
        value = _fmt(r.cost_value, ".4g")
        body.append(
            f"<tr class='{'ok' if r.success else 'failed'}'><td>{html.escape(r.model)}</td>"
            f"<td>{html.escape(r.cost)}</td><td>{r.speed_m_min:g}</td>"
            f"<td>{_fmt(r.froude, '.2f')}</td><td>{html.escape(r.branch)}</td>"
            f"<td>{'<b>' + value + '</b>' if r.cheapest else value}</td>"
            f"<td>{_fmt(r.cost_error, '.2g')}</td><td>{_fmt(r.step_length, '.3f')}</td>"
            f"<td>{_fmt(r.step_time, '.3f')}</td><td>{_fmt(r.first_phase_share, '.2f')}</td>"
            f"<td>{html.escape(r.status)}</td></tr>")
    return head + "".join(body) + "</tbody></table>"


def write_walk_run_report(rows: Sequence[WalkRunRow], transitions: Sequence[TransitionRow],
                          out_dir: str | os.PathLike[str], *,
                          svg: bool = True) -> WalkRunReportInfo:
    """Write the walk-run study's figure and report (module docstring)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    findings = assess_walk_run(rows, transitions)
    paths, png = save_figure(walk_run_figure(rows, transitions), out, FIGURE_STEM, svg=svg)
    sections = ["<h2>Transitions</h2>" + transitions_html(transitions)
                + "<p>Crossing: where the cost curves of the cheapest walk and the run, "
                "linear between grid speeds, cross; grid error: the crossing with both costs "
                "moved by their grid error estimates (solver.accuracy.cost_error). Froude "
                "number v²/(g l), l the hip's height standing.</p>"]
    sections.append("<h2>Cost against speed</h2>"
                    f"<figure><img alt='{FIGURE_STEM}' src='{png_data_uri(png)}'><figcaption>"
                    "Each branch's optimum at each speed (error bars: grid error estimate), "
                    "the cheapest ringed, failed points as crosses at the bottom; the "
                    "transition (black, its grid-error interval grey, the bracket dotted) and "
                    "people's Froude number 0.5 (dashed).</figcaption></figure>")
    for key, items in findings.items():
        sections.append(f"<h2>Findings: {html.escape(key)}</h2>"
                        + findings_html(items, heading="claim",
                                        anchor_prefix=f"finding-{key.replace(' / ', '-')}-"))
    sections.append("<h2>Every point</h2>" + points_html(rows))
    intro = ("<p>At each speed the optimal walk, the walk without double support (where the "
             "model allows it) and the optimal run, step length free: which is cheapest, and "
             "where the cheapest changes from walking to running (docs/running.md).</p>")
    page = html_page("gaitopt walk-run study", intro, sections)
    path = out / "report.html"
    write_text_atomic(path, page)
    return WalkRunReportInfo(html=path, figures=tuple(paths), findings=findings)
