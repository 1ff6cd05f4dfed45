"""``gaitopt report`` and ``gaitopt animate``: the figures, HTML report and findings of a
sweep, and an animation of a gait file. See docs/studies.md."""

from __future__ import annotations

import time
from pathlib import Path

import click
from rich.console import Console

from gaitopt.cli.base import UserError, cli, make_console
from gaitopt.gait.record.file import Gait, GaitFileError
from gaitopt.study.plan import SETTINGS_FILE
from gaitopt.study.summary import SUMMARY_FILE, SummaryError


def sweep_dirs(directory: Path) -> list[Path]:
    """The (sub-)sweeps of a sweep directory: itself, or its sub-folders with a summary."""
    if (directory / SUMMARY_FILE).exists():
        return [directory]
    subs = sorted(p.parent for p in directory.glob(f"*/{SUMMARY_FILE}"))
    if not subs:
        what = "no sweep" if not (directory / SETTINGS_FILE).exists() else "no finished point"
        raise UserError(f"{directory}: {what} here (no {SUMMARY_FILE}); run `gaitopt sweep -o "
                        f"{directory}` first")
    return subs


def write_reports(console: Console, directory: Path, out: Path,
                  compare: tuple[Path, ...] = (), workers: int | None = None) -> list[Path]:
    """Write the report of each (sub-)sweep, print where and the findings; ``compare``: other
    sweep folders drawn beside each (printed: their optima against people's walk);
    ``workers``: local processes of the stability analyses (None: the CPUs available; 0 or
    1: this process)."""
    from gaitopt.study.driver import default_workers
    from gaitopt.study.findings import findings_text
    from gaitopt.viz.report import write_report
    from gaitopt.viz.sweep_comparison import comparison_text

    for other in compare:
        if not (other / SUMMARY_FILE).exists():
            raise UserError(f"--compare {other}: no sweep here (no {SUMMARY_FILE})")
    pages = []
    for sweep in sweep_dirs(directory):
        target = out if sweep == directory else out / sweep.name
        try:
            info = write_report(sweep, target, compare=compare,
                                workers=default_workers() if workers is None else workers)
        except SummaryError as exc:
            raise UserError(str(exc)) from None
        if info.compared:
            console.print("\n".join(["compared:", *comparison_text(info.compared)]),
                          soft_wrap=True)
        console.print(f"report: {info.html} ({len(info.figures)} figure files beside it)",
                      soft_wrap=True)
        for problem in info.problems:
            console.print(f"  problem: {problem}", soft_wrap=True)
        console.print(findings_text(info.findings), soft_wrap=True)
        pages.append(info.html)
    return pages


@cli.command("report")
@click.argument("directory", type=click.Path(file_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder of the report (default: DIRECTORY/report).")
@click.option("--compare", "compare", multiple=True,
              type=click.Path(file_okay=False, path_type=Path),
              help="Another sweep folder to draw beside this one (energy and step length "
                   "against speed, optima, people's walk); for a cost study, another cost "
                   "study (its models beside this one's); repeatable.")
def report_command(directory: Path, output: Path | None, compare: tuple[Path, ...]) -> None:
    """Write the figures and the HTML report of a sweep (or of a cost study), and print the
    findings."""
    from gaitopt.study.cost_study import COST_STUDY_FILE

    if not directory.is_dir():
        raise UserError(f"{directory}: no such directory")
    if (directory / COST_STUDY_FILE).exists():
        write_cost_reports(make_console(), directory, output or directory / "report", compare)
        return
    write_reports(make_console(), directory, output or directory / "report", compare)


def write_cost_reports(console: Console, directory: Path, out: Path,
                       compare: tuple[Path, ...] = ()) -> Path:
    """Write a cost study's report from its ``costs.csv`` (and those of the cost studies in
    ``compare``, drawn beside it); print the answer and findings."""
    from gaitopt.study.cost_findings import cost_findings_text
    from gaitopt.study.cost_study import COST_STUDY_FILE
    from gaitopt.study.cost_table import CostStudyError
    from gaitopt.viz.cost_report import answer_text, write_cost_report

    for other in compare:
        if not (other / COST_STUDY_FILE).exists():
            raise UserError(f"--compare {other}: no cost study here (no {COST_STUDY_FILE}); "
                            "a cost study's report compares cost studies")
    try:
        info = write_cost_report(directory, out, compare=compare)
    except CostStudyError as exc:
        raise UserError(f"{exc}; rerun `gaitopt study --costs -o {directory}` to finish the "
                        "study") from None
    console.print(f"report: {info.html}", soft_wrap=True)
    console.print("\n".join(answer_text(info.rows)), soft_wrap=True)
    console.print(cost_findings_text(info.findings), soft_wrap=True)
    return info.html


def animate_file(console: Console, file: Path, output: Path, *, steps: int, fps: int) -> None:
    from gaitopt.viz.animation import animate_gait

    try:
        gait = Gait.load(file)
    except GaitFileError as exc:
        raise UserError(str(exc)) from None
    start = time.perf_counter()
    try:
        info = animate_gait(gait, output, steps=steps, fps=fps)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    console.print(f"animation: {info.path} ({info.frames} frames, {info.duration_s:.2f} s at "
                  f"{info.fps:g} fps, {steps} steps of {gait.speed * 60:.1f} m/min; written "
                  f"in {time.perf_counter() - start:.1f} s)", soft_wrap=True)


@cli.command("animate")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              default=Path("walk.gif"), show_default=True, help="A .gif or .mp4 file.")
@click.option("--steps", type=click.IntRange(min=1, max=100), default=4, show_default=True,
              help="Steps to show.")
@click.option("--fps", type=click.IntRange(min=1, max=120), default=30, show_default=True,
              help="Frames per second (the movie plays in real time).")
def animate_command(file: Path, output: Path, steps: int, fps: int) -> None:
    """Write an animation of a gait file: the stick figure walking, with contact forces."""
    animate_file(make_console(), file, output, steps=steps, fps=fps)


__all__ = ["animate_command", "animate_file", "report_command", "sweep_dirs", "write_reports"]
