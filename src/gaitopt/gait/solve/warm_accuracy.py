"""What a warm start's gait file says about accuracy: the grid it was refined to, and its
estimate when the warm start finds the file's own optimum again.

A solve that refines itself (:mod:`gaitopt.gait.solve.refinement`: the knots left to the model,
``GaitOptions.accuracy`` set) needs an estimate of its grid error, which a check grid gives
(:mod:`gaitopt.gait.solve.accuracy`). Started from a gait file, two things are already known:

* **the grid** (:func:`refined_knots`): a file that refined itself to its target
  (``solver.accuracy.target`` set and ``within_target`` true) names the knots per phase that
  reached it; the warm start solves there first, not on the model's default grid, from which
  it would be refined back up to the same grid (the five-link walk at 60 m/min: 16 + 6, then
  24 + 8 and its check grid, 1.1 s against 0.3 s for 24 + 8 alone);
* **the estimate** (:func:`carried_estimate`): when the problem is the file's (the same
  model, the same options but the knots' form and the refinement's own settings, the same
  grid) and the warm start converged to the file's optimum (cost, step length and speed
  within :data:`SAME_OPTIMUM`, relative), the file's check grid has the same optimum too, so its
  estimate holds as it is and no check grid is solved again. The gait file says so
  (``solver.accuracy.estimate_from``: ``"warm start"``);
* **the check grid's point** (:func:`check_point`): a file keeps the NLP point and multipliers
  of its check grid's solution (``solver.warm_start_check``) beside its answer's
  (``solver.warm_start``). A warm start that must solve its check grid (at another speed, say)
  restarts it from that point, on the same check grid, as it restarts the answer's grid from
  the answer's: the check grid is still solved to IPOPT's tolerance, so the estimate is the
  warm start's own; only its start comes from the file. For that the warm start solves on the
  file's grid in the form the file stated it (:func:`refined_grid`: the ``knots`` option and
  phase shares, whose check grid is the file's), not on its per-phase counts, whose check
  grid can differ by a knot (the seven-link's 24 + 16 gives 24 + 18 + 16 + 16 knots and the
  check grid 36 + 26 + 24 + 24; 24 + 18 + 16 + 16 gives 36 + 27 + 24 + 24).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from gaitopt.gait.formulations.select import contact_sequence
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.contact_sequence import phase_knots
from gaitopt.gait.solve.staged_run import StagedRun
from gaitopt.ocp import WarmStart
from gaitopt.robot.model import RobotModel

#: Two converged solves of one NLP are the same optimum when their costs and parameters agree
#: within this (relative): IPOPT's tolerance (1e-7 on the scaled problem) leaves about 1e-9
#: between two solves from different starts; a different optimum differs by far more.
SAME_OPTIMUM = 1e-6
#: The keys of ``solver.accuracy`` that a carried estimate takes from the file.
ESTIMATE_KEYS = ("cost_error", "cost_error_method", "cost_error_factor", "check_knots",
                 "check_cost", "previous_knots", "previous_cost", "cost_error_relative",
                 "speed_change", "step_length_change", "speed_error", "step_length_error")
#: Options that change how a solve gets to its answer, not the problem (or, for the knots,
#: are compared as the grid solved instead).
NOT_THE_PROBLEM = frozenset({"knots", "phase_shares", "accuracy", "multistart",
                             "continuation", "max_iter"})


def refined_knots(gait: Gait, phases: tuple[str, ...]) -> dict[str, int] | None:
    """The knots per phase (by name) that ``gait`` refined itself to, if its file says it
    reached its accuracy target and its phases are ``phases`` (the names of the new problem's
    phases, in order); else None."""
    record = gait.solver.get("accuracy")
    if not isinstance(record, Mapping) or record.get("target") is None:
        return None
    knots = record.get("knots")
    if record.get("within_target") is not True or not isinstance(knots, Mapping):
        return None
    if tuple(knots) != phases:
        return None
    return {str(name): int(count) for name, count in knots.items()}


def refined_grid(gait: Gait, model: RobotModel, options: GaitOptions) -> GaitOptions | None:
    """``options`` on the grid ``gait`` refined itself to (:func:`refined_knots`, for the
    phases of ``model`` under ``options``): with the file's ``knots`` option and phase shares
    where they give the file's knots per phase (then the check grid is the file's too), else
    with the file's counts per phase; None where :func:`refined_knots` is None."""
    phases = tuple(ph.name for ph in contact_sequence(model, options).phases)
    knots = refined_knots(gait, phases)
    if knots is None:
        return None
    saved, shares = gait.options.get("knots") or (), gait.options.get("phase_shares")
    try:
        stated = options.replace(knots=tuple(int(k) for k in saved),
                                 phase_shares=None if shares is None else
                                 tuple(float(v) for v in shares))
        counts = phase_knots(contact_sequence(model, stated), stated.knots)
    except (GaitOptionsError, TypeError, ValueError):
        counts = ()
    if tuple(counts) == tuple(knots.values()):
        return stated
    return options.replace(knots=knots)


def stored_point(data: Any) -> WarmStart | None:
    """A :class:`~gaitopt.ocp.WarmStart` from its record in a gait file (``solver.warm_start``
    or ``solver.warm_start_check``: ``w``, ``lam_x``, ``lam_g``, ``layout``, ``method``), or
    None (none kept, or unreadable)."""
    if not isinstance(data, Mapping):
        return None
    try:
        return WarmStart(w=np.asarray(data["w"], dtype=float),
                         lam_x=np.asarray(data["lam_x"], dtype=float),
                         lam_g=np.asarray(data["lam_g"], dtype=float),
                         layout=str(data["layout"]), method=str(data["method"]))
    except (KeyError, TypeError, ValueError):
        return None


def check_point(gait: Gait | None) -> WarmStart | None:
    """The NLP point and multipliers of the file's check grid (``solver.warm_start_check``,
    written with a converged check grid), or None. It fits only the transcription of that
    check grid (:meth:`gaitopt.ocp.WarmStart.fits`), which the solve checks before using it."""
    return None if gait is None else stored_point(gait.solver.get("warm_start_check"))


def _same(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=SAME_OPTIMUM)


def carried_estimate(gait: Gait, run: StagedRun, record: Mapping[str, Any]
                     ) -> dict[str, Any] | None:
    """The file's estimate (:data:`ESTIMATE_KEYS` of ``gait.solver["accuracy"]``, with
    ``estimate_from: "warm start"``) for ``run``, a converged warm start whose own accuracy
    ``record`` (:func:`~gaitopt.gait.solve.accuracy.accuracy_record`) has no estimate, when
    ``run`` solved the file's problem on the file's grid to the file's optimum (module
    docstring); else None."""
    old = gait.solver.get("accuracy")
    if (not run.success or record.get("cost_error") is not None
            or not isinstance(old, Mapping) or old.get("cost_error") is None):
        return None
    if dict(old.get("knots") or {}) != dict(record.get("knots") or {}):
        return None
    if (_plain(dict(gait.model_data)) != _plain(run.model.to_dict())
            or not same_problem(gait.options, run.options)):
        return None
    if not _same(run.result.objective, gait.cost_value):
        return None
    saved, new = gait.parameters, run.result.parameters
    if not all(_same(float(new[k]), float(saved[k])) for k in ("step_length", "speed")
               if k in new and k in saved):
        return None
    return {**{k: old.get(k) for k in ESTIMATE_KEYS}, "estimate_from": "warm start"}


def same_problem(saved: Mapping[str, Any], options: GaitOptions,
                 but: frozenset[str] = frozenset()) -> bool:
    """Whether a gait file's ``options`` state the problem of ``options``: equal but for
    :data:`NOT_THE_PROBLEM` and the options named in ``but`` (e.g. ``{"speed"}``: the same
    problem at another speed)."""
    new = options.to_dict()
    keys = (set(saved) | set(new)) - NOT_THE_PROBLEM - but
    return all(_plain(saved.get(k)) == _plain(new.get(k)) for k in keys)


def _plain(value: Any) -> Any:
    """Lists and tuples alike (a file's lists against the options' tuples), in mappings too."""
    if isinstance(value, list | tuple):
        return tuple(_plain(v) for v in value)
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    return value
