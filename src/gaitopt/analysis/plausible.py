"""Whether a solve's gait is plausible: ``gaitopt verify`` passes on it.

The check a solve hands to :func:`gaitopt.gait.api.solve_staged_run` (``plausible``) to judge
the optimum with the phase shares released (:mod:`gaitopt.gait.solve.share_release`): the
released optimum is kept only where every check of :func:`gaitopt.analysis.verify.verify_gait`
passes on it, the swing checks among them (``swing.reversals``: a flapping foot;
``swing.clearance``: a foot through the ground). It lives here, above the solve, because the
checks do.
"""

from __future__ import annotations

from gaitopt.analysis.verify import verify_gait
from gaitopt.gait.solve.record import MotionOutOfReachError, gait_from_run
from gaitopt.gait.solve.staged_run import StagedRun


def verified(run: StagedRun) -> str | None:
    """None when ``gaitopt verify`` passes on ``run``'s gait; else why not, one line (the
    failed checks with their values and limits, e.g. ``verify fails swing.reversals (6 > 3
    turns)``)."""
    try:
        gait = gait_from_run(run)
    except MotionOutOfReachError as exc:
        return f"its motion cannot be recorded ({exc})"
    report = verify_gait(gait)
    return None if report.passed else "verify fails " + report.failed_text()
