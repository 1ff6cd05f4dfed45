"""Why a walking solve failed, in words and numbers, and what the user can change.

At the best point the failed solve found (the last stage's values), against the bounds the
user asked for (not a relaxed stage's):

* violated constraints: each path constraint of each phase by name (the worst value, its
  phase and time), the collocation defects (the equations of motion between knots), and the
  event and periodicity rows, with their sizes in the constraint's own units;
* binding bounds: actuator torques at their bounds (by actuator, how many knots), joints at
  their limits;
* advice that follows from them: looser torque bounds or a lower speed when torques
  saturate, a shorter step when the landing or the legs' reach fails, a finer grid or
  another start when the dynamics do not close, multistart.

Only the walking solve's public pieces are used: the :class:`WalkingSolution`, its options
and the cached transcription of the grid the result lives on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gaitopt.gait.formulation import stage_bounds
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.problem import Relaxation
from gaitopt.gait.solve import Grid, WalkingSolution, transcription_for
from gaitopt.ocp import Result, Transcription
from gaitopt.ocp.functions import broadcast_bound
from gaitopt.robot.model import RobotModel

#: A constraint counts as violated above this share of its scale.
VIOLATION_SHARE = 1e-4
#: A variable counts as at its bound within this share of the bound's size.
BOUND_SHARE = 1e-4


class SolveFailedError(RuntimeError):
    """A walking solve failed and left nothing to record; the message is its diagnosis."""


@dataclass(frozen=True)
class Diagnosis:
    """What failed (``stage``, ``status``), the ``findings`` at the best point found, and
    ``advice`` (lines of text)."""

    stage: str
    status: str
    findings: tuple[str, ...]
    advice: tuple[str, ...]

    def text(self) -> str:
        """The diagnosis as lines for a terminal."""
        lines = [f"the solve failed at stage '{self.stage}' ({self.status})."]
        if self.findings:
            lines.append("At the best point found:")
            lines += [f"  - {f}" for f in self.findings]
        if self.advice:
            lines.append("What you can change:")
            lines += [f"  - {a}" for a in self.advice]
        return "\n".join(lines)


def diagnose(solution: WalkingSolution) -> Diagnosis:
    """The :class:`Diagnosis` of a failed walking solve (see the module docstring)."""
    options, model = solution.options, solution.model
    res, stage = best_failed_point(solution)
    findings: list[str] = []
    hints: set[str] = set()
    meshes = [np.asarray(m, dtype=float) for m in res.mesh]
    uniform = all(np.allclose(m, np.linspace(0.0, 1.0, m.size)) for m in meshes)
    grid: Grid = tuple(meshes)
    if uniform:  # the solve's own (cached) transcription
        grid = (meshes[0].size, meshes[1].size if len(meshes) > 1 else options.knots[1])
    try:
        tr = transcription_for(model, options, grid)
    except Exception:  # noqa: BLE001 - a diagnosis must never hide the failure itself
        tr = None
    if tr is not None and tr.layout.signature() == res.layout_signature:
        findings += _path_findings(tr, res, hints)
        findings += _row_findings(tr, res, options, hints)
    findings += _binding_findings(model, res, hints)
    return Diagnosis(stage=stage, status=res.status, findings=tuple(findings),
                     advice=tuple(_advice(hints, options)))


def best_failed_point(solution: WalkingSolution) -> tuple[Result, str]:
    """The failed stage's result closest to what was asked: among the stages solved at the
    requested speed (all, if the speed is free) the one with the smallest constraint
    violation, and its name; the solution's final result if no stage result is kept."""
    target = solution.options.speed
    pairs = [(r, name) for name, r in solution.stage_results
             if not r.success and np.all(np.isfinite(r.w))
             and (target is None or abs(r.parameters.get("speed", target) - target) < 1e-9)]
    if not pairs:
        failed = solution.failed_stage
        return solution.result, failed.name if failed is not None else "solve"
    return min(pairs, key=lambda pair: pair[0].constraint_violation)


def _path_findings(tr: Transcription, res: Result, hints: set[str]) -> list[str]:
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
            out.append(f"{spec.name}: '{pc.name}' violated by {excess[k, j]:.3g} at "
                       f"t = {traj.t[k]:.3f} s (knot {k})")
            hints.add(_kind(pc.name))
    return out


def _row_findings(tr: Transcription, res: Result, options: GaitOptions,
                  hints: set[str]) -> list[str]:
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
        worst = float(excess[int(np.argmax(share))])
        what = (f"{blk.phase}: the equations of motion between knots (collocation defects)"
                if blk.kind == "defects" else f"'{blk.name}'")
        out.append(f"{what} violated by {worst:.3g}")
        hints.add("dynamics" if blk.kind == "defects" else _kind(blk.name))
    return out


def _binding_findings(model: RobotModel, res: Result, hints: set[str]) -> list[str]:
    """Torques at their bounds and joints at their limits, counted over all knots."""
    torque = {a.name: a.limits for a in model.actuators}
    joints = {j.name: j.limits for j in model.joints}
    counts: dict[tuple[str, str], list[int]] = {}
    for traj in res.phases:
        for kind, names, values, limits in (("torque", traj.controls, traj.u, torque),
                                            ("joint", traj.states, traj.x, joints)):
            for j, name in enumerate(names):
                if name not in limits:
                    continue
                lo, hi = limits[name]
                tol = BOUND_SHARE * max(abs(lo), abs(hi), 1.0)
                at = (values[:, j] <= lo + tol) | (values[:, j] >= hi - tol)
                c = counts.setdefault((kind, name), [0, 0])
                c[0] += int(np.count_nonzero(at))
                c[1] += values.shape[0]
    out = []
    for (kind, name), (n_at, n_all) in counts.items():
        if n_at == 0:
            continue
        lo, hi = (torque if kind == "torque" else joints)[name]
        unit = "N m" if kind == "torque" else "rad"
        what = "at its bound" if kind == "torque" else "at its limit"
        out.append(f"{kind} {name} {what} ({lo:g}, {hi:g} {unit}) at {n_at} of {n_all} knots")
        hints.add(kind)
    return out


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
    "torque": "the torques saturate: looser torque bounds (actuators[].limits in the model "
              "file) or a lower speed",
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


def _advice(hints: set[str], options: GaitOptions) -> list[str]:
    out = [ADVICE[h] for h in ("torque", "reach", "force", "impulse", "clearance",
                               "friction", "joint", "dynamics", "periodic") if h in hints]
    if not options.multistart:
        out.append("--multistart tries every naive start and the continuation in speed")
    return out
