"""Why a walking solve failed, in words and numbers, and what the user can change.

At the best point the failed solve found (the last stage's values), against the bounds the
user asked for (not a relaxed stage's):

* violated constraints: each path constraint of each phase by name (the worst value, its
  phase and time), the collocation defects (the equations of motion between knots), and the
  event and periodicity rows, with their sizes in the constraint's own units;
* binding bounds: actuator torques at their bounds (by actuator, how many knots), joints at
  their limits;
* binding bounds of the problem statement (with the solve's transcription): the stance
  leg's hip-to-tip distance ``r`` at its longest (the legs at full reach), the torso and
  the joint rates at their bounds;
* the most likely cause, named first: the torque bounds when they pin most knots of an
  actuator while constraints stay violated, else the family of the constraint with the
  largest violation (relative to its scale: the legs' reach, contact forces, the dynamics,
  ...), which is named with its size;
* advice that follows from them, the cause's first: looser torque bounds or a lower speed
  when torques saturate, a shorter step when the landing or the legs' reach fails, a finer
  grid or another start when the dynamics do not close, multistart.

Only the walking solve's own pieces are used: the (internal)
:class:`~gaitopt.gait.solve.staged_run.StagedRun`, its options and the cached transcription
of the grid the result lives on. Users read the diagnosis from the failed solve's
:class:`~gaitopt.gait.record.file.Gait` (:attr:`~gaitopt.gait.record.file.Gait.diagnosis`,
its :meth:`Diagnosis.text`, written by :func:`gaitopt.gait.solve.record.gait_from_run`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gaitopt.gait.formulations.select import stage_bounds
from gaitopt.gait.formulations.step_parameters import Relaxation
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve.staged import Grid, StagedRun, transcription_for
from gaitopt.ocp import Problem, Result, Transcription
from gaitopt.ocp.functions import broadcast_bound
from gaitopt.ocp.validate import as_bound
from gaitopt.robot.model import RobotModel

#: A constraint counts as violated above this share of its scale.
VIOLATION_SHARE = 1e-4
#: A variable counts as at its bound within this share of the bound's size.
BOUND_SHARE = 1e-4
#: The torque bounds are the likely cause when they pin at least this share of some
#: actuator's knots.
CAUSE_SHARE = 0.5


class SolveFailedError(RuntimeError):
    """A walking solve failed and left nothing to record; the message is its diagnosis."""


@dataclass(frozen=True)
class Finding:
    """One observation at the best point: ``kind`` (a key of :data:`ADVICE`, or ``other``),
    ``text``, and ``share``: a violation's size over its scale, or the share of a variable's
    knots at a bound (``binding``)."""

    kind: str
    text: str
    share: float
    binding: bool = False
    #: For a binding bound: the variable and how many knots, e.g. ``hip_1 at 13 of 13 knots``.
    subject: str = ""


@dataclass(frozen=True)
class Diagnosis:
    """What failed (``stage``, ``status``), the ``findings`` at the best point found, the
    most likely ``cause`` and the ``largest`` violation (texts, empty if none), the point's
    ``violation`` (largest constraint violation in the constraints' units) and ``advice``."""

    stage: str
    status: str
    findings: tuple[str, ...]
    advice: tuple[str, ...]
    cause: str = ""
    largest: str = ""
    violation: float = float("nan")
    where: str = ""

    def text(self) -> str:
        """The diagnosis as lines for a terminal."""
        at = f" at {self.where}" if self.where else ""
        lines = [f"the solve failed at stage '{self.stage}' ({self.status}){at}."]
        if self.cause:
            lines.append(f"Most likely cause: {self.cause}.")
        if self.largest:
            lines.append(f"Largest violation: {self.largest}.")
        if self.findings:
            lines.append("At the best point found:")
            lines += [f"  - {f}" for f in self.findings]
        if self.advice:
            lines.append("What you can change:")
            lines += [f"  - {a}" for a in self.advice]
        return "\n".join(lines)


def diagnose(run: StagedRun) -> Diagnosis:
    """Returns the :class:`Diagnosis` of a failed staged run (see the module docstring)."""
    options, model = run.options, run.model
    res, stage = best_failed_point(run)
    found: list[Finding] = []
    meshes = [np.asarray(m, dtype=float) for m in res.mesh]
    uniform = all(np.allclose(m, np.linspace(0.0, 1.0, m.size)) for m in meshes)
    grid: Grid = tuple(meshes)
    if uniform:  # the solve's own (cached) transcription
        grid = (meshes[0].size, meshes[1].size if len(meshes) > 1 else options.knots[1])
    try:
        tr = transcription_for(model, options, grid)
    except Exception:  # noqa: BLE001 - a diagnosis must never hide the failure itself
        tr = None
    matches = tr is not None and tr.layout.signature() == res.layout_signature
    if matches:
        assert tr is not None
        found += _path_findings(tr, res)
        found += _row_findings(tr, res, options)
    found += _binding_findings(model, res, tr.problem if matches and tr is not None else None)
    violated = [f for f in found if not f.binding]
    largest = max(violated, key=lambda f: f.share) if violated else None
    cause = _cause(found, largest)
    p = res.parameters
    where = ", ".join(part for part in (
        f"{p['speed'] * 60:.2f} m/min" if "speed" in p else "",
        f"step {p['step_length']:.3f} m" if "step_length" in p else "") if part)
    kinds = [cause[0]] if cause else []
    kinds += [f.kind for f in found  # bounds that bind at an optimum too advise nothing
              if (not f.binding or f.kind == "torque") and f.kind in ADVICE
              and f.kind not in kinds]
    return Diagnosis(stage=stage, status=res.status, findings=tuple(f.text for f in found),
                     advice=tuple(_advice(kinds, options)), cause=cause[1] if cause else "",
                     largest=largest.text if largest is not None else "",
                     violation=res.constraint_violation, where=where)


def _cause(found: list[Finding], largest: Finding | None) -> tuple[str, str] | None:
    """The kind and words of the most likely cause: the torque bounds when they pin at least
    :data:`CAUSE_SHARE` of some actuator's knots (saturated torques with constraints still
    violated), else the family of the largest violation. (Other bounds that bind, such as
    the stance leg at full reach, are listed but are no cause by themselves: the optimal
    walk has them too.)"""
    torques = [f for f in found if f.binding and f.kind == "torque" and f.share >= CAUSE_SHARE]
    if torques:
        return "torque", f"{CAUSES['torque']}: {', '.join(f.subject for f in torques)}"
    if largest is None:
        return None
    words = CAUSES.get(largest.kind, "a constraint that no point found could meet")
    if largest.kind == "reach":
        reach = [f.subject for f in found if f.binding and f.kind == "reach"]
        if reach:
            words += f" (the stance leg's hip-to-tip distance {reach[0]})"
    return largest.kind, words


def best_failed_point(run: StagedRun) -> tuple[Result, str]:
    """Returns the failed stage's result closest to what was asked: among the stages solved
    at the requested speed (all, if the speed is free) the one with the smallest constraint
    violation, and its name; the run's final result if no stage result is kept."""
    target = run.options.speed
    pairs = [(r, name) for name, r in run.stage_results
             if not r.success and np.all(np.isfinite(r.w))
             and (target is None or abs(r.parameters.get("speed", target) - target) < 1e-9)]
    if not pairs:
        failed = run.failed_stage
        return run.result, failed.name if failed is not None else "solve"
    return min(pairs, key=lambda pair: pair[0].constraint_violation)


def _path_findings(tr: Transcription, res: Result) -> list[Finding]:
    out = []
    for spec, traj in zip(tr.problem.phases, res.phases, strict=True):
        for pc in spec.path_constraints:
            values = np.asarray(traj.path.get(pc.name, np.zeros((0, 0))), dtype=np.float64)
            if values.size == 0:
                continue
            r = values.shape[1]
            lo = broadcast_bound(pc.lower, r, pc.name, -np.inf)
            hi = broadcast_bound(pc.upper, r, pc.name, np.inf)
            scale = broadcast_bound(pc.scale, r, pc.name, 1.0) if pc.scale is not None else \
                np.maximum(np.where(np.isfinite(lo), np.abs(lo), 0.0),
                           np.where(np.isfinite(hi), np.abs(hi), 0.0)) + 1.0
            excess = np.maximum(lo - values, values - hi)
            share = excess / scale
            if not np.any(share > VIOLATION_SHARE):
                continue
            k, j = np.unravel_index(int(np.argmax(share)), share.shape)
            out.append(Finding(_kind(pc.name),
                               f"{spec.name}: '{pc.name}' violated by {excess[k, j]:.3g} at "
                               f"t = {traj.t[k]:.3f} s (knot {k})", float(share[k, j])))
    return out


def _row_findings(tr: Transcription, res: Result, options: GaitOptions) -> list[Finding]:
    bounds = stage_bounds(tr, Relaxation(), options)
    g = np.asarray(tr.nlp.evaluate(res.w)[0], dtype=np.float64).ravel()
    out = []
    for blk in tr.nlp.constraints.blocks:
        if blk.kind == "path":
            continue
        rows = np.arange(blk.rows.start, blk.rows.stop)
        excess = np.maximum(bounds.lbg[rows] - g[rows], g[rows] - bounds.ubg[rows])
        scale = tr.nlp.d_g[rows]
        share = np.where(np.isfinite(excess), excess, 0.0) / scale
        if rows.size == 0 or not np.any(share > VIOLATION_SHARE):
            continue
        i = int(np.argmax(share))
        what = (f"{blk.phase}: the equations of motion between knots (collocation defects)"
                if blk.kind == "defects" else f"'{blk.name}'")
        out.append(Finding("dynamics" if blk.kind == "defects" else _kind(blk.name),
                           f"{what} violated by {float(excess[i]):.3g}", float(share[i])))
    return out


def _binding_findings(model: RobotModel, res: Result, problem: Problem | None) -> list[Finding]:
    """Torques at their bounds, joints at their limits and (with the ``problem``) every other
    state bound of the statement that binds, counted over all knots; ``share`` is the share
    of the variable's knots at the bound."""
    torques = {a.name: a.limits for a in model.actuators}
    joints = {j.name: j.limits for j in model.joints}
    counts: dict[tuple[str, str], list[Any]] = {}
    for traj in res.phases:
        stated = {} if problem is None else {
            n: as_bound(b, n) for ph in problem.phases if ph.name == traj.name
            for n, b in ph.state_bounds.items()}
        columns = [("torque", name, traj.u[:, j], torques[name])
                   for j, name in enumerate(traj.controls) if name in torques]
        for j, name in enumerate(traj.states):
            if name in joints:
                columns.append(("joint", name, traj.x[:, j], joints[name]))
            elif name in stated:
                columns.append((_state_kind(name), name, traj.x[:, j], stated[name]))
        for kind, name, values, (lo, hi) in columns:
            size = max(abs(v) for v in (lo, hi, 1.0) if np.isfinite(v))
            at = (values <= lo + BOUND_SHARE * size) | (values >= hi - BOUND_SHARE * size)
            c = counts.setdefault((kind, name), [0, 0, (lo, hi)])
            c[0] += int(np.count_nonzero(at))
            c[1] += values.shape[0]
    out = []
    for (kind, name), (n_at, n_all, (lo, hi)) in counts.items():
        if n_at == 0:
            continue
        knots = f"at {n_at} of {n_all} knots"
        if kind == "reach":
            text = (f"the stance leg's hip-to-tip distance {name} at its bound ({lo:.3g}, "
                    f"{hi:.3g} m; the longest is the legs' reach with the least knee bend)")
        elif kind in ("torque", "joint"):
            what = "at its bound" if kind == "torque" else "at its limit"
            unit = "N m" if kind == "torque" else "rad"
            text = f"{kind} {name} {what} ({lo:g}, {hi:g} {unit})"
        else:
            unit = "rad/s" if name.endswith("_rate") else "rad"
            text = f"state {name} at its bound ({lo:g}, {hi:g} {unit})"
        out.append(Finding(kind, f"{text} {knots}", n_at / n_all, binding=True,
                           subject=f"{name} at the bound {knots}"))
    return out


def _state_kind(name: str) -> str:
    """The family of a bounded state of the reduced statement (``r``: the legs' reach)."""
    return "reach" if name == "r" else "other"


def _kind(name: str) -> str:
    """The family of a constraint from its name."""
    text = name.lower()
    for key, words in (("periodic", ("periodic", "event map")),
                       ("force", ("contact force",)), ("impulse", ("impulse",)),
                       ("reach", ("reach", "lands at", "touchdown", "held points")),
                       ("clearance", ("clearance", "above the ground")),
                       ("friction", ("friction",)), ("periodic", ("heel strike", "liftoff")),
                       ("joint", ("limit",))):
        if any(w in text for w in words):
            return key
    return "other"


ADVICE = {
    "torque": "the torques saturate: looser torque bounds (actuators[].limits in a model "
              "file: gaitopt model export MODEL -o my.yaml) or a lower speed",
    "reach": "the legs cannot reach where the step asks: a shorter step (--step-length) or "
             "leave it free; a lower speed",
    "force": "the ground would have to pull on a held point: a lower speed or a shorter "
             "step; ankle torques help keep the stance foot loaded",
    "impulse": "an impact or liftoff would need the ground to pull: try --paper-impulse-maps "
               "to see whether that is the only obstacle, or another speed or step",
    "clearance": "a swinging point would go below the ground: a smaller --clearance, a "
                 "shorter step, or a finer grid",
    "friction": "the friction cone binds: a larger --friction or none",
    "joint": "joints reach their limits: wider joint limits in the model file",
    "dynamics": "the equations of motion do not close: a finer grid (--knots), "
                "--multistart, or a warm start from a nearby gait (--warm-start)",
    "periodic": "the step does not close into a periodic gait: --multistart or a warm start "
                "from a nearby gait",
}


#: The most likely causes in words, by kind.
CAUSES = {
    "torque": "the torque bounds",
    "reach": "the legs' reach (the step asks for more than the legs can reach)",
    "joint": "the joint limits",
    "force": "the contact forces (the ground would have to pull)",
    "impulse": "the contact impulses (the ground would have to pull at an event)",
    "clearance": "the swing clearance",
    "friction": "the friction cone",
    "dynamics": "the equations of motion (no motion on this grid meets them)",
    "periodic": "closing the step into a periodic gait",
}


def _advice(kinds: list[str], options: GaitOptions) -> list[str]:
    # One line per kind of constraint, in the order of the findings (a kind found in two
    # phases gives its advice once).
    out = list(dict.fromkeys(ADVICE[k] for k in kinds if k in ADVICE))
    if not options.multistart:
        out.append("--multistart tries every naive start and the continuation in speed")
    return out
