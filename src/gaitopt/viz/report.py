"""The report of a sweep: one self-contained HTML file plus every figure as PNG and SVG.

(One concept, kept whole at about 410 lines: one HTML page, its sections and tables; the
figures are drawn in :mod:`gaitopt.viz.sweep_figures`.)

``write_report(sweep_dir, out_dir)`` reads the sweep directory (``summary.csv`` and the gait
files it names, layout in :mod:`gaitopt.study.summary`) and writes to ``out_dir``:

* ``report.html``: headline table (the energy-optimal walk of each variant beside the
  paper's), Figs. 3-8, stick-figure strips, the solver statistics beside the paper's table,
  the findings, and the whole summary table; figures embedded as base64 PNG, no external
  resource or link;
* ``fig3_energy``, ``fig4_step_length``, ``fig5_hip_motion``, ``fig6_heights``,
  ``fig7_torques_no_impulse``, ``fig8_torques_impulse``, ``stick_<variant>`` as ``.png`` and
  ``.svg``.

Figs. 5-8 show, per the paper, each variant's energy-optimal walk and its solved walk nearest
50 m/min; a missing gait leaves its curve out and is listed under "problems".

Every figure's caption and the headline table state the sweep's grid (knots and control model)
and, when a check sweep on a finer grid exists (``<sweep>/check-grid``, written by ``gaitopt
study``; :mod:`gaitopt.study.grid_error`), the error estimate of what it shows: the largest
change of the cost (or step length) to the finer grid over the points shown, and for each
speed-free optimum how far its speed and step length move (step lengths in m and relative).
Points re-solved in refinement sweeps (``<sweep>/refine-grid``, ``refine-grid-2``, ...) are
shown with their values and gaits on their finest grid, and the captions say on which grids
and with which estimate (the change from the grid before).
"""

from __future__ import annotations

import html
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from gaitopt.fileio import write_text_atomic
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.study.findings import (
    FAST_SPEED_M_MIN,
    PAPER_OPTIMAL_SPEED_M_MIN,
    PAPER_OPTIMAL_STEP_LENGTH,
    Findings,
    assess_findings,
    findings_html,
    optimal_row,
    row_near_speed,
)
from gaitopt.study.grid_error import GridError, grid_error
from gaitopt.study.summary import (
    SUMMARY_COLUMNS,
    SUMMARY_FILE,
    VARIANTS,
    SummaryRow,
    read_summary,
    rows_of,
)
from gaitopt.viz.gait_figures import heights_figure, hip_motion_figure, torques_figure
from gaitopt.viz.stability_table import stability_table_html, start_stability_rows
from gaitopt.viz.stick import stick_strip_figure
from gaitopt.viz.style import VARIANT_LABELS, gait_style, png_data_uri, save_figure
from gaitopt.viz.sweep_comparison import (
    ComparedSweep,
    comparison_caption,
    comparison_figure,
    comparison_table_html,
    load_compared_sweep,
    sweep_label,
)
from gaitopt.viz.sweep_figures import energy_figure, step_length_figure

#: The paper's solver statistics (section 5.1): one sample solve, 8 + 5 knots.
PAPER_SOLVER_TABLE: dict[str, dict[str, Any]] = {
    "DIRCOL 1.2 / NPSOL": {"state_equations": 568635, "boundary_constraints": 43430,
                           "inequality_constraints": 249928, "run_time": "18 min",
                           "variables": 197, "equality_constraints": 131,
                           "inequality_constraints_nlp": 23},
    "DIRCOL 2.0 / SNOPT": {"state_equations": 230952, "boundary_constraints": 8497,
                           "inequality_constraints": 125099, "run_time": "12 min",
                           "variables": 197, "equality_constraints": 131,
                           "inequality_constraints_nlp": 23},
}
#: Evaluation kinds comparable with the paper's rows (keys of ``solver.evaluations``).
PAPER_EVALUATION_KINDS: dict[str, str] = {
    "state_equations": "function calls: state equations",
    "boundary_constraints": "function calls: implicit boundary constraints",
    "inequality_constraints": "function calls: nonlinear inequality constraints",
}


@dataclass(frozen=True)
class ReportInfo:
    """What :func:`write_report` wrote: the HTML file, the figure files, any problems, the
    findings and the sweeps compared (this one first; empty without ``compare``)."""

    html: Path
    figures: tuple[Path, ...]
    problems: tuple[str, ...]
    findings: Findings
    compared: tuple[ComparedSweep, ...] = ()


@dataclass(frozen=True)
class _Selected:
    label: str
    gait: Gait
    style: dict[str, Any]


def write_report(sweep_dir: str | os.PathLike[str], out_dir: str | os.PathLike[str], *,
                 svg: bool = True,
                 check_dir: str | os.PathLike[str] | None = None,
                 compare: Sequence[str | os.PathLike[str]] = (),
                 stability: bool = True, workers: int = 1) -> ReportInfo:
    """Write the report of the sweep in ``sweep_dir`` to ``out_dir`` (see module docstring);
    ``svg=False`` skips the SVG copies of the figures; ``check_dir`` is the check sweep on a
    finer grid (default ``<sweep_dir>/check-grid`` when it exists); ``compare``: other sweep
    folders drawn beside this one (:mod:`gaitopt.viz.sweep_comparison`, figure
    ``compare_sweeps``); ``stability``: the Floquet multipliers of each variant's optimal gait
    (:mod:`gaitopt.viz.stability_table`; a few seconds per gait), run in ``workers`` local
    processes while the figures are drawn when ``workers`` > 1.

    Raises :class:`gaitopt.study.summary.SummaryError` if ``summary.csv`` is missing or
    invalid; unreadable gait files are reported in the HTML, not raised.
    """
    sweep, out = Path(sweep_dir), Path(out_dir)
    rows = read_summary(sweep / SUMMARY_FILE)
    out.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    cache: dict[str, Gait | None] = {}

    def load(row: SummaryRow | None) -> Gait | None:
        if row is None or not row.file:
            return None
        if row.file not in cache:
            try:
                cache[row.file] = Gait.load(sweep / row.file)
            except GaitFileError as exc:
                problems.append(str(exc))
                cache[row.file] = None
        return cache[row.file]

    errors = grid_error(sweep, rows, check_dir)
    if errors is not None:  # refined points show their refined values
        rows = errors.reported(rows)
    optimal = {v: optimal_row(rows, v) for v in VARIANTS}
    fast = {v: row_near_speed(rows, v, FAST_SPEED_M_MIN) for v in VARIANTS}
    for v in VARIANTS:
        load(optimal[v])
        load(fast[v])
    gaits = {f: g for f, g in cache.items() if g is not None}
    findings = assess_findings(rows, gaits)
    stability_rows = start_stability_rows(
        [(f"{v}, {row.speed_m_min:.1f} m/min", gait, sweep / row.file) for v in VARIANTS
         if (row := optimal[v]) is not None and (gait := load(row)) is not None]
        if stability else [], workers=workers)

    def grid_note(shown: Sequence[SummaryRow | None] | None = None, what: str = "cost") -> str:
        """The grid and error-estimate sentence of a figure showing ``shown`` (all rows)."""
        if errors is None:
            return ""
        return " " + errors.statement(None if shown is None else errors.of(shown), what=what)

    sections: list[str] = []
    figures: list[Path] = []

    def add(fig: Figure | None, stem: str, caption: str) -> None:
        if fig is None:
            sections.append(f"<p class='missing'>{html.escape(caption)}: no gait to show.</p>")
            return
        paths, data = save_figure(fig, out, stem, svg=svg)
        figures.extend(paths)
        sections.append(f"<figure><img alt='{html.escape(stem)}' src='{png_data_uri(data)}'>"
                        f"<figcaption>{html.escape(caption)}</figcaption></figure>")

    sections.append("<h2>Energy-optimal walk of each variant</h2>"
                    + _headline(rows, optimal, errors))
    sections.append("<h2>Energy and step length against speed</h2>")
    add(energy_figure(rows), "fig3_energy", "Fig. 3: cost (energy per metre) against speed, "
        "four variants; the human curve on the right axis for comparing shapes." + grid_note())
    add(step_length_figure(rows), "fig4_step_length", "Fig. 4: optimal step length against "
        "speed." + grid_note(what="step length"))

    compared: list[ComparedSweep] = []
    if compare:
        compared = [ComparedSweep(sweep_label(sweep), tuple(rows), sweep)]
        compared += [load_compared_sweep(d) for d in compare]
        sections.append("<h2>Compared with other sweeps</h2>"
                        + comparison_table_html(compared))
        add(comparison_figure(compared), "compare_sweeps", comparison_caption(compared))

    shown: dict[tuple[str, str], list[SummaryRow]] = {}

    def pick(variants: tuple[str, str]) -> list[_Selected]:
        """Optimal walks with/without ankles, then near 50 m/min (paper's line styles)."""
        chosen = []
        order = [(variants[0], optimal, 0), (variants[1], optimal, 1),
                 (variants[0], fast, 2), (variants[1], fast, 3)]
        for variant, table, k in order:
            row = table[variant]
            gait = load(row)
            if row is not None and gait is not None:
                kind = "optimal" if table is optimal else "fixed speed"
                chosen.append(_Selected(f"{variant}, {row.speed_m_min:.1f} m/min ({kind})",
                                        gait, gait_style(k)))
                shown.setdefault(variants, []).append(row)
        return chosen

    def curves(selected: Sequence[_Selected]
               ) -> tuple[list[tuple[str, Gait]], list[dict[str, Any]]]:
        return [(s.label, s.gait) for s in selected], [s.style for s in selected]

    with_impulse = pick(("ankle+impulse", "impulse"))
    without_impulse = pick(("ankle", "plain"))
    sections.append("<h2>Trajectories with the liftoff impulse</h2>")
    c, st = curves(with_impulse)
    add(hip_motion_figure(c, styles=st) if c else None, "fig5_hip_motion",
        "Fig. 5: hip horizontal position and velocity over a double step, liftoff impulse on; "
        "optimal speed with/without ankle torques (solid/dashed), near 50 m/min (dash-dot/"
        "dotted). Grey lines: heel strike, next liftoff, next heel strike."
        + grid_note(shown.get(("ankle+impulse", "impulse"), [])))
    add(heights_figure(c, styles=st) if c else None, "fig6_heights",
        "Fig. 6: hip and knee heights over a double step (same gaits as Fig. 5)."
        + grid_note(shown.get(("ankle+impulse", "impulse"), [])))
    sections.append("<h2>Torques</h2>")
    c7, st7 = curves(without_impulse)
    add(torques_figure(c7, styles=st7, title="Fig. 7  torques without liftoff impulse")
        if c7 else None, "fig7_torques_no_impulse",
        "Fig. 7: torques without the liftoff impulse, with their bounds (dashed)."
        + grid_note(shown.get(("ankle", "plain"), [])))
    add(torques_figure(c, styles=st, title="Fig. 8  torques with liftoff impulse")
        if c else None, "fig8_torques_impulse",
        "Fig. 8: torques with the liftoff impulse, with their bounds (dashed)."
        + grid_note(shown.get(("ankle+impulse", "impulse"), [])))
    sections.append("<h2>Stick figures of the optimal step</h2>")
    for v in VARIANTS:
        gait = load(optimal[v])
        add(stick_strip_figure(gait, title=f"{VARIANT_LABELS[v]}: optimal step at "
                               f"{gait.speed * 60:.1f} m/min") if gait else None,
            f"stick_{v.replace('+', '-')}", f"One step of the optimal walk, {v}."
            + grid_note([optimal[v]]))
    if stability:
        sections.append("<h2>Orbital stability of the optimal gaits</h2>"
                        + stability_table_html(stability_rows()))
    sections.append("<h2>Solver statistics</h2>" + _solver_table(rows, optimal, load))
    sections.append("<h2>Findings of the paper, checked</h2>" + findings_html(findings))
    sections.append("<h2>All sweep points</h2>" + _summary_table(rows))
    if problems:
        sections.append("<h2>Problems</h2><ul>" + "".join(
            f"<li>{html.escape(p)}</li>" for p in problems) + "</ul>")
    page = _page(f"gaitopt report: {sweep.name or sweep.resolve().name}", sections, rows)
    path = out / "report.html"
    write_text_atomic(path, page)
    return ReportInfo(html=path, figures=tuple(figures), problems=tuple(problems),
                      findings=findings, compared=tuple(compared))


def write_gait_figures(curves: Sequence[tuple[str, Gait]], out_dir: str | os.PathLike[str],
                       *, svg: bool = True) -> list[Path]:
    """Figures of a few gaits, overlaid: ``hip_motion``, ``heights``, ``torques`` and one
    ``stick_<k>`` strip per gait (k = 1, 2, ...), as PNG (and SVG) in ``out_dir``.

    ``curves`` pairs a legend label with each gait, e.g. ``[(path.name, Gait.load(path))]``.
    """
    if not curves:
        raise ValueError("write_gait_figures: no gaits given")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    figures = [(hip_motion_figure(curves), "hip_motion"), (heights_figure(curves), "heights"),
               (torques_figure(curves), "torques")]
    figures += [(stick_strip_figure(g, title=label), f"stick_{k}")
                for k, (label, g) in enumerate(curves, start=1)]
    for fig, stem in figures:
        paths += save_figure(fig, out, stem, svg=svg)[0]
    return paths


def _fmt(x: float, spec: str) -> str:
    return "–" if not math.isfinite(x) else format(x, spec)


def _headline(rows: Sequence[SummaryRow], optimal: Mapping[str, SummaryRow | None],
              errors: GridError | None = None) -> str:
    head = ("<table><thead><tr><th>variant</th><th>speed [m/min]</th><th>speed [m/s]</th>"
            "<th>step length [m]</th><th>step time [s]</th><th>cost</th><th>from</th>"
            "<th>solved</th><th>error estimate</th></tr></thead><tbody>")
    body = []
    for v in VARIANTS:
        r = optimal[v]
        total = len(rows_of(rows, v, success=None))
        solved = len(rows_of(rows, v))
        if r is None:
            body.append(f"<tr><td>{v}</td><td colspan=6>no successful solve</td>"
                        f"<td>{solved}/{total}</td><td>–</td></tr>")
            continue
        source = "speed-free solve" if r.speed_mode == "free" else "grid minimum"
        body.append(f"<tr><td>{v}</td><td>{_fmt(r.speed_m_min, '.1f')}</td>"
                    f"<td>{_fmt(r.speed_m_s, '.3f')}</td><td>{_fmt(r.step_length, '.3f')}</td>"
                    f"<td>{_fmt(r.step_time, '.3f')}</td><td>{_fmt(r.cost, '.4g')}</td>"
                    f"<td>{source}</td><td>{solved}/{total}</td>"
                    f"<td>{html.escape(_optimum_error(errors, r))}</td></tr>")
    body.append(f"<tr class='paper'><td>paper (all variants)</td><td>≈ "
                f"{PAPER_OPTIMAL_SPEED_M_MIN:g}</td><td>≈ {PAPER_OPTIMAL_SPEED_M_MIN / 60:.2f}"
                f"</td><td>≈ {PAPER_OPTIMAL_STEP_LENGTH:g}</td><td>–</td><td>–</td>"
                "<td>Figs. 3, 4</td><td>–</td><td>–</td></tr>")
    grid = "" if errors is None else f"<p>{html.escape(errors.statement())}</p>"
    return head + "".join(body) + "</tbody></table>" + grid


def _optimum_error(errors: GridError | None, row: SummaryRow) -> str:
    """How far an optimum moves to the check grid: cost (%), speed (m/min), step (m)."""
    if errors is None or errors.check_knots is None:
        return "–"
    found = errors.of([row])
    if not found:
        return "not checked"
    p = found[0]
    grid = f"to {errors.check_knots[0]}+{errors.check_knots[1]}"
    if p.refined and p.grid is not None and p.check_grid is not None:
        grid = (f"solved on {p.grid[0]}+{p.grid[1]}, change from "
                f"{p.check_grid[0]}+{p.check_grid[1]}")
    moved = "" if row.speed_mode == "fixed" else f"speed {p.speed_m_min:+.2f} m/min, "
    estimate = "" if row.speed_mode == "fixed" else f"speed {p.speed_error:.2f} m/min, "
    return (f"{grid} knots: cost {100 * p.cost:.2f} %, {moved}step {p.step_length:+.4f} m; "
            f"error estimate ({p.factor:g} x): cost {100 * p.cost_error:.2f} %, {estimate}"
            f"step {p.step_error:.4f} m ({100 * p.step_relative:.2f} %)")


def _solver_table(rows: Sequence[SummaryRow], optimal: Mapping[str, SummaryRow | None],
                  load: Any) -> str:
    columns: list[tuple[str, dict[str, Any]]] = list(PAPER_SOLVER_TABLE.items())
    extra: list[str] = []
    for v in VARIANTS:
        gait = load(optimal[v])
        if gait is None:
            continue
        s = gait.solver
        col = {"variables": s["variables"], "equality_constraints": s["equality_constraints"],
               "inequality_constraints_nlp": s["inequality_constraints"],
               "run_time": f"{s['wall_time_s']:.3g} s", "iterations": s["iterations"],
               **s["evaluations"]}
        extra += [k for k in s["evaluations"] if k not in PAPER_EVALUATION_KINDS
                  and k not in extra]
        knots = "+".join(str(p.t.size) for p in gait.phases)
        columns.append((f"ours: {v} optimum ({knots} knots)", col))
    labels = {"variables": "NLP variables", "equality_constraints": "equality constraints",
              "inequality_constraints_nlp": "inequality constraints",
              **PAPER_EVALUATION_KINDS,
              **{k: f"function calls: {k}" for k in extra},
              "iterations": "iterations", "run_time": "run time"}
    out = ["<table><thead><tr><th></th>" + "".join(f"<th>{html.escape(n)}</th>"
                                                   for n, _ in columns) + "</tr></thead><tbody>"]
    for key, label in labels.items():
        cells = "".join(f"<td>{html.escape(_cell(col.get(key)))}</td>" for _, col in columns)
        out.append(f"<tr><td>{html.escape(label)}</td>{cells}</tr>")
    out.append("</tbody></table>")
    solved = [r for r in rows if r.success and math.isfinite(r.wall_time_s)]
    total = sum(r.wall_time_s for r in rows if math.isfinite(r.wall_time_s))
    out.append(f"<p>Whole sweep: {len(rows)} points, {len(solved)} solved, total solver wall "
               f"time {total:.1f} s. The paper's runs: Sparc Ultra 2, 166 MHz, 8+5 knots.</p>")
    return "".join(out)


def _cell(value: Any) -> str:
    if value is None:
        return "–"
    if isinstance(value, int):
        return f"{value:,}"
    return str(value)


def _summary_table(rows: Sequence[SummaryRow]) -> str:
    head = "".join(f"<th>{c}</th>" for c in SUMMARY_COLUMNS)
    body = []
    for r in rows:
        cells = "".join(f"<td>{html.escape(v)}</td>" for v in r.as_csv_dict().values())
        body.append(f"<tr class='{'ok' if r.success else 'failed'}'>{cells}</tr>")
    return (f"<details><summary>{len(rows)} rows of summary.csv</summary><table class='small'>"
            f"<thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table></details>")


_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Helvetica,Arial,sans-serif;max-width:1100px;
margin:2em auto;padding:0 1em;color:#1b1b1b;line-height:1.45}
h1{font-size:1.6em}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:0.8em 0;font-size:0.9em}
th,td{border:1px solid #ccc;padding:0.3em 0.6em;text-align:left;vertical-align:top}
th{background:#f3f3f3}tr.paper td{background:#fff8e1}tr.failed td{color:#b3261e}
table.small{font-size:0.75em}figure{margin:1.2em 0}img{max-width:100%;height:auto}
figcaption{font-size:0.9em;color:#444}.missing{color:#b3261e}
"""


def _page(title: str, sections: Sequence[str], rows: Sequence[SummaryRow]) -> str:
    n_ok = sum(r.success for r in rows)
    intro = (f"<p>{len(rows)} sweep points, {n_ok} solved. Cost: (∫uᵀu dt + P²) / step length "
             "(paper eqs. 4-5). Speeds in m/min as in the paper (1 m/s = 60 m/min).</p>")
    return ("<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
            f"<h1>{html.escape(title)}</h1>{intro}" + "\n".join(sections) + "</body></html>\n")


def html_page(title: str, intro_html: str, sections: Sequence[str]) -> str:
    """A self-contained HTML page in the report's style: the title, an introduction (HTML)
    and the sections (HTML), no external resource."""
    return ("<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
            f"<h1>{html.escape(title)}</h1>{intro_html}" + "\n".join(sections)
            + "</body></html>\n")
