"""The summary ``gaitopt solve`` prints for a converged gait (a rich table), and its rows for
the accuracy estimates and the phase shares."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from rich.table import Table

from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.units import format_speed

if TYPE_CHECKING:
    from gaitopt.analysis.metrics import GaitMetrics


def summary_table(gait: Gait, sequence_used: ContactSequence | None) -> Table:
    """The table ``gaitopt solve`` prints for a converged gait: speed, step, shares, cost,
    peak torques against their bounds, contact forces, clearance, friction, NLP size and the
    accuracy estimates (:func:`accuracy_rows`)."""
    from gaitopt.analysis.metrics import gait_metrics

    metrics = gait_metrics(gait)
    p = gait.parameters
    table = Table(title="optimal gait", show_header=False)
    table.add_column("quantity")
    table.add_column("value")
    table.add_row("speed", format_speed(p["speed"]))
    table.add_row("step length", f"{p['step_length']:.4f} m")
    table.add_row("step time", f"{p['step_time']:.4f} s (single support "
                  f"{p['single_support_time']:.4f} s)")
    if sequence_used is not None and len(sequence_used.phases) > 1:
        table.add_row("phase fractions", phase_fractions_text(sequence_used, gait))
    table.add_row("liftoff impulse", f"{p['liftoff_impulse']:.4f} N s")
    if gait.options.get("cost", "paper") == "paper":
        table.add_row("cost (energy per metre)", f"{gait.cost_value:.6g} N^2 m s")
    else:
        table.add_row(f"cost ({gait.options['cost']} cost of transport)",
                      f"{gait.cost_value:.6g} (dimensionless)")
    for name, peak in metrics.peak_torques.items():
        bound = metrics.torque_bounds[name]
        table.add_row(f"peak torque {name}", f"{peak:8.2f} / {bound:g} N m "
                      f"({100 * peak / bound:5.1f} %)")
    table.add_row("smallest normal force", f"{metrics.min_normal_force:.3f} N")
    table.add_row("smallest normal impulse", f"{metrics.min_normal_impulse:.4f} N s")
    table.add_row("swing clearance", f"{metrics.swing_clearance * 1000:.1f} mm (lowest "
                  f"{metrics.swing_min_height * 1000:.2f} mm)")
    table.add_row("friction needed", friction_text(metrics, gait.options.get("friction")))
    s = gait.solver
    table.add_row("NLP size", f"{s['variables']} variables, {s['equality_constraints']} "
                  f"equality, {s['inequality_constraints']} inequality constraints")
    table.add_row("iterations (last stage)", str(s["iterations"]))
    paper = gait.options.get("cost", "paper") == "paper"
    for row in accuracy_rows(s["accuracy"], speed=gait.speed, step_length=gait.step_length,
                             unit=" N^2 m s" if paper else ""):
        table.add_row(*row)
    table.add_row("wall time", f"{s['wall_time_s']:.2f} s")
    return table


#: A friction ratio above this is shown by the forces behind it: no ground offers a
#: coefficient near it (rubber on concrete about 1), so the number itself says nothing more.
FRICTION_SHOWN = 5.0


def friction_text(metrics: GaitMetrics, friction: float | None) -> str:
    """The summary's friction row: the largest ``|tangential| / normal`` and where it is;
    above :data:`FRICTION_SHOWN` (a frictionless solve: a tip unloading while the ground still
    pushes it sideways) the forces there and how to bound them (``--friction``)."""
    unit = "N s" if metrics.friction_where.endswith(" impulse") else "N"
    at = f" at {metrics.friction_where}" if metrics.friction_where else ""
    if metrics.friction_required <= FRICTION_SHOWN:
        return f"{metrics.friction_required:.3f} (|tangential|/normal{at})"
    text = (f"{metrics.friction_required:.3g} (|tangential|/normal{at}: "
            f"{abs(metrics.friction_tangential):.3g} {unit} sideways against a normal "
            f"{metrics.friction_normal:.2g} {unit})")
    if friction is None:
        text += "; the ground has no friction limit here, --friction MU sets one"
    return text


def phase_fractions_text(sequence: ContactSequence, gait: Gait) -> str:
    """Each phase's solved share of the step time, ``(free)`` after those that were."""
    solved = (gait.contact_sequence or {}).get("phases", [])
    return ", ".join(f"{ph.name} {float(rec['fraction']):.4f}" + (" (free)" if ph.free else "")
                     for ph, rec in zip(sequence.phases, solved, strict=True))


def accuracy_rows(accuracy: Mapping[str, Any], *, speed: float | None = None,
                  step_length: float | None = None,
                  unit: str = " N^2 m s") -> list[tuple[str, str]]:
    """Summary rows of a gait file's ``solver.accuracy``: the collocation error per phase,
    the cost's discretization error estimate and how far speed and step length moved (with
    their estimates relative to the gait's ``speed`` and ``step_length`` when given);
    ``unit``: the cost's, after the error (the paper's; empty for a cost of transport)."""
    from gaitopt.gait.solve.refinement import diverging_text

    errors = ", ".join(f"{name} {'n/a' if e is None else f'{e:.1e}'} "
                       f"({accuracy['knots'][name]} knots)"
                       for name, e in accuracy["collocation_error"].items())
    tol = accuracy["mesh_tol"]
    if tol is not None:
        errors += f"; mesh_tol {tol:g} {'met' if accuracy['mesh_converged'] else 'NOT met'}"
    rows = [("collocation error (largest per interval)", errors)]
    if accuracy["cost_error"] is None:
        rows.append(("cost error estimate", "n/a (one grid; solve with --mesh-tol)"))
        return rows + smoothing_rows(accuracy)
    check = accuracy.get("check_knots")
    grid = "+".join(str(k) for k in (check or accuracy["previous_knots"]).values())
    factor = accuracy.get("cost_error_factor") or 1.0
    rel = accuracy.get("cost_error_relative")
    if check is not None:
        how = f"{factor:g} x the change to {grid} knots, J {accuracy['check_cost']:.6g}"
        moved = f"change to {grid} knots"
    else:
        how = f"change from {grid} knots, J {accuracy['previous_cost']:.6g}"
        moved = f"change from {grid} knots"
    target = accuracy.get("target") or 0.01
    share = "" if rel is None else (
        f" = {100 * rel:.2f} % of J: " + (
            f"within {100 * target:g} %" if rel <= target else
            f"above {100 * target:g} % (a finer --knots or --mesh-tol 1e-4)"))
    rows.append(("cost error estimate", f"{accuracy['cost_error']:+.4g}{unit}{share} ({how})"))
    if accuracy.get("target") is not None:
        worst, name = accuracy.get("worst_estimate"), accuracy.get("worst_estimate_of", "cost")
        shown = "none" if worst is None else f"{100 * worst:.2g} %"
        verdict = ("converged" if accuracy.get("within_target") else
                   f"NOT CONVERGED to {100 * target:g} %")
        rows.append(("accuracy", f"{verdict}: largest estimate {shown} ({name}); "
                     f"{accuracy.get('refinements', 0)} refinement(s) of the grid"
                     f"{diverging_text(accuracy)}"))
    dv, dl = accuracy.get("speed_change"), accuracy.get("step_length_change")
    if dv is not None and dl is not None and (dv != 0.0 or dl != 0.0):
        text = f"speed {60 * dv:+.3f} m/min, step length {dl:+.4f} m"
        ev, el = accuracy.get("speed_error"), accuracy.get("step_length_error")
        if check is not None and ev is not None and el is not None:
            text += (f"; estimate {factor:g} x: speed {60 * ev:.3f} m/min{_share(ev, speed)}, "
                     f"step length {el:.4f} m{_share(el, step_length)}")
        rows.append((moved, text))
    return rows + smoothing_rows(accuracy)


def smoothing_rows(accuracy: Mapping[str, Any]) -> list[tuple[str, str]]:
    """The summary row of ``solver.accuracy.smoothing`` (a cost of transport's smoothing
    share, :func:`gaitopt.gait.formulations.cost.smoothing_record`); none without it."""
    smoothing = accuracy.get("smoothing")
    if not isinstance(smoothing, Mapping):
        return []
    share, target = smoothing["share"], accuracy.get("target") or 0.01
    text = (f"{100 * share:.2g} % of J at eps {smoothing['cost_smoothing']:g} W (the motion's "
            f"cost unsmoothed: {smoothing['unsmoothed_cost']:.6g})")
    if share > target:
        text += (f"; above {100 * target:g} %: the smoothing, not only the motion, sets this "
                 "optimum (docs/costs.md)")
    return [("cost smoothing", text)]


def _share(error: float, value: float | None) -> str:
    """`` (0.55 %)``: ``error`` relative to ``value`` (nothing without a value)."""
    return "" if not value else f" ({100 * error / abs(value):.2f} %)"
