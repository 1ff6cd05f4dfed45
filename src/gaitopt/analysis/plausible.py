"""Whether a solve's gait is plausible: ``gaitopt verify`` passes on it.

The check a solve hands to :func:`gaitopt.gait.api.solve_staged_run` (``plausible``) to judge
the optimum with the phase shares released (:mod:`gaitopt.gait.solve.share_release`): the
released optimum is kept only where every check of :func:`gaitopt.analysis.verify.verify_gait`
passes on it, the swing checks among them (``swing.reversals``: a flapping foot;
``swing.clearance``: a foot through the ground). It lives here, above the solve, because the
checks do.
"""

from __future__ import annotations

from typing import Any

from gaitopt.analysis.verify import VerifyReport, verify_gait
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run
from gaitopt.gait.solve.staged_run import StagedRun


def verified(run: StagedRun) -> str | None:
    """None when ``gaitopt verify`` passes on ``run``'s gait; else why not, one line (the
    failed checks with their values and limits, e.g. ``verify fails swing.reversals (6 > 3
    turns)``)."""
    return Verifier()(run)


class Verifier:
    """:func:`verified` that keeps each report, so that a gait is verified once: ``gaitopt
    solve`` passes it as the solve's ``plausible`` and asks it for the report of the gait it
    writes (:meth:`report`), which is the released gait it judged when the release was kept
    (a verify of the seven-link walk takes 1-2 s). A gait is the one judged when everything
    ``verify`` reads is equal: the file's content but its time of writing and the solver's
    record other than ``solver.accuracy``."""

    def __init__(self) -> None:
        self._reports: list[tuple[dict[str, Any], VerifyReport]] = []

    def __call__(self, run: StagedRun) -> str | None:
        """None when ``gaitopt verify`` passes on ``run``'s gait; else why not (as
        :func:`verified`)."""
        try:
            gait = gait_from_run(run)
        except MotionOutOfReachError as exc:
            return f"its motion cannot be recorded ({exc})"
        report = self.report(gait)
        return None if report.passed else "verify fails " + report.failed_text()

    def report(self, gait: Gait) -> VerifyReport:
        """``verify_gait(gait)``, or the report of an equal gait verified before."""
        key = _verified_content(gait)
        for seen, report in self._reports:
            if seen == key:
                return report
        report = verify_gait(gait)
        self._reports.append((key, report))
        return report


def _verified_content(gait: Gait) -> dict[str, Any]:
    """What :func:`~gaitopt.analysis.verify.verify_gait` reads of ``gait``, as plain data."""
    data = gait.to_dict()
    data.pop("created")
    data["solver"] = data["solver"].get("accuracy")
    return data
