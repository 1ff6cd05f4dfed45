"""Checking a saved gait independently of the solver: every field a user reads.

``verify_gait`` trusts nothing but the file and the model in it, and reads only the
full-coordinate fields (``q, qd, qdd, u, contact_forces``, each phase's ``contacts``, the
events, the samples, the parameters): it works the same whichever formulation computed the
gait (reduced coordinates or full coordinates). It uses the full-coordinate dynamics of
:mod:`gaitopt.dynamics` (RNEA, contact kinematics, the Contact and Collision Algorithms, the
liftoff impulse) and SciPy's adaptive Runge-Kutta integrator, never the solver's equations.

The checks (stable ids, see :data:`CHECKS` and ``docs/outputs.md``, section "Verify"):

* at every knot (:mod:`.checks.knots`): the equations of motion with the phase's contacts
  held, the held tips' positions, velocities and accelerations, normal forces >= 0, the phase
  states ``x, xdot`` against ``q, qd, qdd``, the parameters against the phases and events;
* re-integration per interval against the grid's own error estimate (:mod:`.checks.integration`);
* the events (:mod:`.checks.events`): continuity, the impact and liftoff maps and impulses,
  periodicity with the legs relabelled;
* the dense samples (:mod:`.checks.samples`): on the phases' interpolants, points at the
  kinematics, normal forces between knots, torque bounds, joint limits, swing clearance;
* the solve's own grid-error estimates within the accuracy it was asked to reach
  (``accuracy.estimate``; :mod:`gaitopt.gait.solve.refinement`);
* the cost recomputed from the file (:func:`gaitopt.gait.formulations.cost.recompute_cost`): for the
  paper's cost the exact integral of the squared piecewise-linear controls plus the impulse
  squared, over the step length; the costs of transport by the transcription's quadrature,
  with the liftoff impulse's work at the event the file's contact sequence marks impulsive
  (:func:`gaitopt.gait.formulations.cost.impulse_events`: ``toe_off`` in a heel-toe walk).

What the transcription imposes exactly (knots, events, periodicity, cost) is checked to about
1e-6 (relative where it says so); what it cannot impose between knots against the accuracy of
the grid. ``tolerance_scale`` multiplies every limit.
"""

from __future__ import annotations

import numpy as np

from gaitopt.analysis.checks.check import CHECKS, LIMITS, Check, CheckSpec
from gaitopt.analysis.checks.events import event_checks
from gaitopt.analysis.checks.integration import integration_checks
from gaitopt.analysis.checks.knots import UnknownStatesError, knot_checks
from gaitopt.analysis.checks.samples import sample_checks
from gaitopt.analysis.checks.swing import swing_checks
from gaitopt.gait.formulations.cost import recompute_cost
from gaitopt.gait.record.file import Gait
from gaitopt.gait.solve.refinement import worst_estimate

__all__ = ["CHECKS", "LIMITS", "Check", "CheckSpec", "UnknownStatesError", "VerifyReport",
           "verify_gait"]


class VerifyReport:
    """The outcome of :func:`verify_gait`: the checks in report order."""

    def __init__(self, checks: tuple[Check, ...]) -> None:
        self.checks = checks

    def __repr__(self) -> str:
        failed = self.failed_ids
        return (f"VerifyReport({len(self.checks)} checks, "
                + ("passed)" if not failed else f"failed: {', '.join(failed)})"))

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    @property
    def failed_ids(self) -> tuple[str, ...]:
        """Ids of the checks that failed, in report order."""
        return tuple(c.id for c in self.checks if not c.passed)

    def check(self, key: str) -> Check:
        """A check by its id (or, for people, its prose name)."""
        for c in self.checks:
            if key in (c.id, c.name):
                return c
        raise KeyError(f"no check {key!r} in this report (ids: {', '.join(CHECKS)})")

    def to_dict(self) -> dict[str, object]:
        """Plain JSON data: ``passed`` and the list of ``checks`` (:meth:`Check.to_dict`)."""
        return {"passed": self.passed, "checks": [c.to_dict() for c in self.checks]}

    def failed_text(self) -> str:
        """The failed checks in one line, each with its value, limit and unit (e.g.
        ``swing.reversals (6 > 3 turns), integration.interval (0.031 > 0.01)``); empty when
        every check passed."""
        return ", ".join(f"{c.id} ({c.value:.3g} > {c.limit:.3g} {c.unit})".replace(" )", ")")
                         for c in self.checks if not c.passed)

    def record(self) -> dict[str, object]:
        """What a solve keeps of this report in its gait file (``solver.verify``,
        docs/outputs.md): ``passed``, the number of ``checks`` and the ``failed`` ones
        (:meth:`Check.to_dict`)."""
        return {"passed": self.passed, "checks": len(self.checks),
                "failed": [c.to_dict() for c in self.checks if not c.passed]}


def verify_gait(gait: Gait, *, tolerance_scale: float = 1.0) -> VerifyReport:
    """Run every check on ``gait`` (see the module docstring).

    Raises:
        ValueError: ``tolerance_scale`` is not a finite number > 0.
        UnknownStatesError: a phase's ``state_names`` belong to no known formulation.
    """
    if not (isinstance(tolerance_scale, int | float) and np.isfinite(tolerance_scale)
            and tolerance_scale > 0):
        raise ValueError(f"tolerance_scale: expected a finite number > 0, got "
                         f"{tolerance_scale!r}")
    lim = {k: v * tolerance_scale for k, v in LIMITS.items()}
    checks = [*knot_checks(gait, lim), *integration_checks(gait, lim), *event_checks(gait, lim),
              *sample_checks(gait, lim), *swing_checks(gait, lim), _cost_check(gait, lim),
              _accuracy_check(gait, lim)]
    order = list(CHECKS)
    return VerifyReport(tuple(sorted(checks, key=lambda c: order.index(c.id))))


def _cost_check(gait: Gait, lim: dict[str, float]) -> Check:
    cost = recompute_cost(gait)
    saved = gait.cost_value
    rel = abs(cost - saved) / max(abs(saved), 1e-12)
    # The trapezoidal transcription integrates u'u by the trapezoidal rule, not exactly.
    trapezoidal = gait.options.get("transcription", "hermite-simpson") == "trapezoidal"
    limit = 5e-2 if trapezoidal else lim["cost.recomputed"]
    return Check("cost.recomputed", rel, limit)


def _accuracy_check(gait: Gait, lim: dict[str, float]) -> Check:
    """``accuracy.estimate``: the largest relative grid-error estimate the solve recorded
    (:func:`gaitopt.gait.solve.refinement.worst_estimate`) against the accuracy it was asked to
    reach (``solver.accuracy.target``, scaled like every limit). A gait solved on a grid the
    caller chose has no target: the estimate is reported and the check passes."""

    record = gait.solver.get("accuracy") or {}
    target = record.get("target")
    worst, name = worst_estimate(record, gait.parameters)
    if target is None:
        value = worst if np.isfinite(worst) else 0.0
        return Check("accuracy.estimate", value, np.inf,
                     f"{name}; no accuracy target (a grid the caller chose): reported only")
    scale = lim["accuracy.estimate"] / LIMITS["accuracy.estimate"]
    return Check("accuracy.estimate", worst, float(target) * scale, name)
