"""The report's stability table: the Floquet multipliers of each variant's optimal gait.

For every gait it shows (:func:`gaitopt.analysis.stability.gait_stability`, docs/stability.md)

* **open loop, about the gait**: the return map linearized about the gait's own knots
  (``about="gait"``): the stability of the orbit the optimizer found under its own torques;
* **with PD tracking** of gains :data:`REPORT_PD` (N m/rad, N m s/rad) added to the replayed
  torques: the simulated step at the gait's start state, whose residual ``max |P(y) - y|``
  says how close the simulated orbit is to the gait's.

Each cell gives the spectral radius (the largest multiplier's modulus) and the verdict
(stable below 1 - 1e-3, unstable above 1 + 1e-3); a gait whose step cannot be analysed (a
contact sequence the return map does not handle, a replay that never lands) shows why. The
finite-difference check of the monodromy is left to ``gaitopt stability`` (it doubles the
time).

The report runs the analyses in local processes (:func:`start_stability_rows`) while it draws
its figures: a PD-tracked analysis of the seven-link walk takes 4-5 s, an open-loop one about
1 s (10-19 s and 2-4 s before 2026-12-04, when the return map's calls went through CasADi's
DM conversions; docs/stability.md, "Speed").
"""

from __future__ import annotations

import html
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from gaitopt.analysis.stability import StabilityError, StabilityReport, gait_stability
from gaitopt.gait.record.file import Gait

#: PD gains (kp N m/rad, kd N m s/rad) of the report's tracked column.
REPORT_PD: tuple[float, float] = (300.0, 30.0)


@dataclass(frozen=True)
class StabilityCell:
    """One analysis: its report, or the reason there is none."""

    report: StabilityReport | None
    error: str = ""

    def text(self) -> str:
        if self.report is None:
            return f"not analysed: {self.error}"
        r = self.report
        return f"{r.spectral_radius:.3g} ({r.verdict}; residual {r.residual:.2g})"


@dataclass(frozen=True)
class StabilityRow:
    """The open-loop and PD-tracked analyses of one labelled gait."""

    label: str
    open_loop: StabilityCell
    tracked: StabilityCell


def _cell(gait: Gait, pd: tuple[float, float] | None) -> StabilityCell:
    """Open loop about the gait's knots (``pd`` None), or PD-tracked from its start."""
    try:
        report = (gait_stability(gait, about="gait", check=False) if pd is None
                  else gait_stability(gait, pd=pd, check=False))
        return StabilityCell(report)
    except StabilityError as exc:
        return StabilityCell(None, str(exc))


def stability_rows(gaits: Sequence[tuple[str, Gait]],
                   pd: tuple[float, float] = REPORT_PD) -> list[StabilityRow]:
    """The two analyses of each ``(label, gait)``."""
    return [StabilityRow(label, _cell(gait, None), _cell(gait, pd)) for label, gait in gaits]


def _file_cell(path: Path, pd: tuple[float, float] | None) -> StabilityCell:
    """:func:`_cell` of the gait file at ``path`` (a worker's job: a Gait does not pickle)."""
    return _cell(Gait.load(path), pd)


def start_stability_rows(optima: Sequence[tuple[str, Gait, Path]],
                         pd: tuple[float, float] = REPORT_PD, *,
                         workers: int = 1) -> Callable[[], list[StabilityRow]]:
    """Start the two analyses of each ``(label, gait, its file)`` and return the function
    that waits for them and gives the rows (as :func:`stability_rows`). With ``workers`` > 1
    they run at once in that many local processes, each loading the file (at most one per
    analysis; the PD-tracked ones first, the slower on a model with feet), so the caller can
    go on meanwhile; else on the gaits in this process when the function is called."""
    if workers <= 1 or not optima:
        return lambda: stability_rows([(label, gait) for label, gait, _ in optima], pd)
    from gaitopt.study.executors import end_with_driver, mp_context, stop_workers

    pool = ProcessPoolExecutor(max_workers=min(workers, 2 * len(optima)),
                               mp_context=mp_context(), initializer=end_with_driver,
                               initargs=(os.getpid(),))
    tracked = [pool.submit(_file_cell, path, pd) for _, _, path in optima]
    about: list[Future[StabilityCell]] = [pool.submit(_file_cell, path, None)
                                          for _, _, path in optima]

    def rows() -> list[StabilityRow]:
        try:
            return [StabilityRow(label, a.result(), t.result())
                    for (label, _, _), a, t in zip(optima, about, tracked, strict=True)]
        except KeyboardInterrupt:  # Ctrl-C or SIGTERM: end the analyses, do not wait for them
            stop_workers(pool)
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)

    return rows


def stability_table_html(rows: Sequence[StabilityRow],
                         pd: tuple[float, float] = REPORT_PD) -> str:
    """The rows as an HTML table with a sentence on what the columns mean."""
    lines = ["<p>Floquet multipliers of the step-to-step return map (docs/stability.md): "
             "spectral radius, verdict and the residual max |P(y) - y| at the analysed state. "
             "Open loop: linearized about the gait's own knots. Tracked: the gait's torques "
             f"plus joint-space PD tracking (kp {pd[0]:g} N m/rad, kd {pd[1]:g} N m s/rad), "
             "the simulated step from the gait's start. Above 1 a disturbance grows from step "
             "to step.</p>",
             "<table><tr><th>gait</th><th>open loop, about the gait</th>"
             f"<th>PD {pd[0]:g}, {pd[1]:g}</th></tr>"]
    for r in rows:
        lines.append(f"<tr><td>{html.escape(r.label)}</td>"
                     f"<td>{html.escape(r.open_loop.text())}</td>"
                     f"<td>{html.escape(r.tracked.text())}</td></tr>")
    return "\n".join(lines) + "</table>"


__all__ = ["REPORT_PD", "StabilityCell", "StabilityRow", "stability_rows",
           "stability_table_html", "start_stability_rows"]
