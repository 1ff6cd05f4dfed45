"""A cost with kinks reached from the paper's optimum: the smoothing ladder of the staged solve.

A cost that declares itself not smooth (:data:`gaitopt.gait.formulations.cost.COST_TRAITS`:
the costs of transport, whose integrands take positive parts ``max(0, p_a)`` of actuator
powers ``p_a = u_a w_a``, smoothed in the NLP as ``pos(p) = (p + sqrt(p^2 + eps^2)) / 2`` with
``eps = cost_smoothing``, W) is not solved from the naive guess: the staged solve
(:func:`gaitopt.gait.solve.staged.solve_walking`) first solves the paper's smooth cost through
all its stages, then this module's *ladder*: the cost asked for on the target grid with
``eps`` from :data:`COST_SMOOTHING_START` (carried over to the model as a power) divided by
:data:`COST_SMOOTHING_STEP` per stage (:func:`smoothing_ladder`), each stage started from the
previous optimum, down to the requested ``eps``. So does a paper cost with a regularisation
(:func:`continues_from_paper`).

Why the ladder, and where it ends (docs/costs.md, docs/feet.md): from the naive guess IPOPT did
not converge on the costs of transport; from the paper's optimum a single jump to the
requested smoothing converged slowly or not at all. Each rung's kinks are ``1 / eps`` sharp
(``pos'' (0) = 1 / (2 eps)``): on the seven-link model at 80 m/min the rungs 1.6 W and 0.16 W
converged in 376 and 691 iterations, the requested 0.016 W did not within 1000, IPOPT's
objective settled to 4e-4 (relative) after about 170 iterations while the dual infeasibility
kept jumping between 1e-4 and 1e-1 (the Newton steps cross the kinks); IPOPT's adaptive
barrier, an initial barrier of 1e-4 and the quasi-Newton Hessian stalled the same way.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gaitopt.gait.formulations.cost import COST_TRAITS
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.options.model_scale import REFERENCE, ModelScale
from gaitopt.gait.solve.stages import PRIMAL_WARM_OPTIONS, sequence_kind
from gaitopt.ocp import Guess, Result

#: Smoothing (W) of the positive parts of the work costs in the first stage after the paper
#: cost's optimum, when the requested one is finer (the reference biped's; a model's is
#: carried over as a power, :meth:`~gaitopt.gait.options.model_scale.ModelScale.power`); each
#: further stage divides it by :data:`COST_SMOOTHING_STEP` until the requested one
#: (:func:`smoothing_ladder`).
COST_SMOOTHING_START = 1.0
COST_SMOOTHING_STEP = 10.0

#: One stage of the ladder: ``(name, options of its NLP, start, IPOPT options) -> Result``.
LadderStage = Callable[[str, GaitOptions, Guess | Result, dict[str, Any]], Result]


def continues_from_paper(options: GaitOptions) -> bool:
    """Whether a cold solve of ``options`` reaches its cost from the paper cost's optimum: a
    cost that is not smooth (:data:`~gaitopt.gait.formulations.cost.COST_TRAITS`), or any
    cost with a torque regularisation."""
    return not COST_TRAITS[options.cost].smooth or options.cost_regularization > 0.0


def smoothing_ladder(target: float, scale: ModelScale = REFERENCE) -> list[float]:
    """The smoothings (W) solved before ``target``: :data:`COST_SMOOTHING_START` (carried
    over to the model of ``scale`` as a power) divided by :data:`COST_SMOOTHING_STEP` while
    still coarser than ``target`` (``[1, 0.1]`` for 0.01 on the reference biped; ``[]`` when
    ``target`` is at least the start)."""
    out, eps = [], scale.power(COST_SMOOTHING_START)
    while eps > target * (1 + 1e-9):
        out.append(eps)
        eps /= COST_SMOOTHING_STEP
    return out


def climb_ladder(options: GaitOptions, start: Guess, scale: ModelScale,
                 stage: LadderStage) -> Result:
    """From the paper cost's optimum ``start`` (its values), the cost of ``options`` through
    :func:`smoothing_ladder` and then at its own ``cost_smoothing``; each stage of the ladder
    after the first starts from the previous one's optimum with its multipliers (the
    constraints are the same; only the kinks of the cost sharpen). Returns the last stage's
    result (the first failed one, if any fails)."""
    guess: Guess | Result = start
    solver_options: dict[str, Any] = dict(PRIMAL_WARM_OPTIONS)
    for eps in smoothing_ladder(options.cost_smoothing, scale):
        result = stage(f"{options.cost} cost, eps {eps:g} W",
                       options.replace(cost_smoothing=eps), guess, solver_options)
        if not result.success:
            return result
        guess, solver_options = result, {}
    return stage(f"{options.cost} cost", options, guess, solver_options)


#: The contact sequences (by kind, :func:`~gaitopt.gait.solve.stages.sequence_kind`) whose
#: check grid of a cost with kinks first holds the step length and speed
#: (:func:`check_holds_step`): where it was measured to be needed. The five-link walk's
#: check grids of the costs of transport converge in one stage (docs/costs.md).
CHECK_HELD_KINDS = frozenset({"heel-toe"})


def check_holds_step(options: GaitOptions, scale: ModelScale = REFERENCE) -> bool:
    """Whether the check grid of ``options`` is solved in two stages, both at the requested
    smoothing: the step length and speed held at the target grid's optimum, then free
    (:meth:`gaitopt.gait.solve.staged._Run.check`): a cost that is not smooth
    (:data:`~gaitopt.gait.formulations.cost.COST_TRAITS`) on a contact sequence of
    :data:`CHECK_HELD_KINDS` whose :func:`smoothing_ladder` has one rung at most (the
    seven-link's 0.16 W, the cost study's smoothing; a finer one climbs
    :func:`check_smoothings` instead, as before).

    Measured 2026-12-03 (docs/costs.md, "The accuracy pass"), the seven-link's cost study
    at 0.16 W, check grid 36 + 26 knots from the optimum on 24 + 16 mapped onto it with its
    multipliers, barrier 1e-6: held, then free, the work case converged in 102 + 24
    iterations near the optimum it came from (19.07 -> 18.37 m/min, cost -2.8 %), the
    metabolic 1.2 W/kg case in 300 + 13 (55.58 -> 55.37 m/min, -0.5 %). The smoothing ladder
    the check grid climbed before (1.6 W, then the requested smoothing, everything free)
    took 52 + 236 and 64 + 370 iterations, its 1.6 W stage moving the work optimum to
    33.6 m/min; the same ladder with the step held took 85 + 91 and 56 + 304, and its work
    case came back to another optimum (0.00154 against 0.00407 on 24 + 16, then 0.00278 and
    0.00338 on the finer grids): the estimate compared two optima, not two grids. At
    0.016 W with everything free from the start, IPOPT had left the optimum (the metabolic
    walk at 4.8 W/kg and 78 m/min: 600 iterations at the limit, cost 0.598 against 0.535)."""
    return (not COST_TRAITS[options.cost].smooth
            and sequence_kind(options) in CHECK_HELD_KINDS
            and len(smoothing_ladder(options.cost_smoothing, scale)) <= 1)


def check_smoothings(options: GaitOptions, scale: ModelScale = REFERENCE) -> list[float]:
    """The smoothings (W) the check grid solves before the requested one, everything free,
    each stage from the last with its multipliers: the :func:`smoothing_ladder` of a cost
    with kinks on a contact sequence of :data:`CHECK_HELD_KINDS` whose ladder has two rungs
    or more (the seven-link's 0.016 W, a solve below 36.5 m/min); else none (the held check
    of :func:`check_holds_step`, or one stage).

    Measured 2026-12-03 (docs/costs.md, "The accuracy pass"), the seven-link's metabolic
    walk at 4.8 W/kg and 78 m/min at 0.016 W, check grid 36 + 26 knots from the 24 + 16
    optimum: the ladder 1.6, 0.16, 0.016 W converged in 131 + 243 + 83 iterations; held at
    0.016 W directly it converged to the same optimum (0.5295) but in 2307, and held at
    0.16 W first (332) it had not converged at 0.016 W after more than 10 minutes."""
    if COST_TRAITS[options.cost].smooth or sequence_kind(options) not in CHECK_HELD_KINDS:
        return []
    ladder = smoothing_ladder(options.cost_smoothing, scale)
    return ladder if len(ladder) > 1 else []
