"""Defaults that follow the model: the gait its feet allow, the speed, the bounds, the grid.

:class:`~gaitopt.gait.options.gait_options.GaitOptions` marks the defaults that depend on the model
(:func:`~gaitopt.gait.options.gait_options.from_model`); :func:`options_for_model` replaces each one
still marked with the model's value, so ``GaitOptions()`` means the same problem from Python as
``gaitopt solve --model M`` with no option:

* ``gait``: what the model's contact points allow (:func:`default_gait`): one point per leg
  walks (the paper's walk), two per leg (a heel and a toe on each foot) walk heel to toe. A
  gait the model cannot do is refused in one line that names the one it can
  (:func:`gait_problem`).
* ``formulation``: the paper's reduced coordinates for the walk of a five-link-shaped biped,
  else full coordinates (:func:`gaitopt.gait.formulations.select.default_formulation`).
* ``knots``: 16 + 6 for two phases, :data:`MULTI_PHASE_KNOTS` for more (the heel-toe walk
  passes ``verify`` from 24 + 16 on; docs/feet.md).
* ``speed``: :data:`DEFAULT_SPEEDS` of the gait at equal Froude number (:func:`default_speed`).
* ``cost_smoothing``: the reference biped's 0.01 W carried over as a power, times the power of
  ten nearest to the speed's ratio to 12 m/min at equal Froude number (:func:`cost_smoothing_for`).
* ``speed_bounds``, ``step_length_bounds``, ``rate_bound``, ``max_impulse``: the reference
  biped's values carried over by
  :class:`~gaitopt.gait.options.model_scale.ModelScale` (speeds by ``sqrt(g l)``, lengths by ``l``,
  rates by ``sqrt(g / l)``, impulses by ``m sqrt(g l)``, powers by ``m g sqrt(g l)``).
* a run's stance share, free within :data:`RUN_STANCE_BOUNDS`, its step length bounds,
  :data:`RUN_STEP_LENGTH_BOUNDS`, and on point feet its swing clearance
  :data:`RUN_SWING_CLEARANCE` (docs/running.md); every other gait's fraction 0.85 and no
  clearance (``y >= 0``).

For the five-link biped every resolved value equals the marked one exactly.
"""

from __future__ import annotations

import math
from typing import Any

from gaitopt.gait.formulations.select import default_formulation
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, follows_model
from gaitopt.gait.options.model_scale import ModelScale, model_scale
from gaitopt.gait.sequence.builtin import legs_contacts
from gaitopt.gait.sequence.contact_sequence import ContactSequenceError, sequence_from_dict
from gaitopt.robot.model import RobotModel

#: Knots per phase of a step with more than two phases (the first phase, every later one):
#: the heel-toe walk of ``seven-link`` fails ``verify`` on 16 + 6 and 16 + 10 knots and
#: passes on 24 + 16 (docs/feet.md, "Grid"). Two-phase steps keep the options' 16 + 6.
MULTI_PHASE_KNOTS = (24, 16)

#: The default speed of each gait on the reference biped (legs of 1 m, g = 9.81 m/s^2), in
#: m/s; a model walks at the speed of equal Froude number ``v^2 / (g l)``, i.e. the
#: dimensionless speed ``v / sqrt(g l)``: the walk 0.2 m/s (12 m/min, the paper's optimum
#: of the five-link biped; 0.0639), the heel-toe walk 1.25 m/s (0.399: 72.2 m/min for
#: ``seven-link``, next to its speed-free optimum 73.5-74.8 m/min, where the error estimate
#: of the default grid is 0.00-0.03 %; at 12 and 30 m/min it is 34 % and 18 %,
#: docs/walking.md "Defaults that follow the model"), the run the walk's.
DEFAULT_SPEEDS: dict[str, float] = {"walk": 0.2, "run": 0.2, "heel-toe": 1.25}

#: A run's stance share (``single_support_fraction``: the stance phase's share of the step
#: time) is free by default within these bounds (``single_support_fraction_bounds``), unless
#: the caller gives the fraction, its bounds, ``free_phase_fractions`` or a stride: people's
#: duty factor of 0.25-0.45 (stance per stride) is a stance share of 0.5-0.9 of a step, and
#: the bounds leave the optimum room on both sides (docs/running.md).
RUN_STANCE_BOUNDS = (0.2, 0.95)
#: The first guess of a run's free stance share is ``clip(a - b Fr, lo, hi)`` with
#: ``(a, b, lo, hi)`` these numbers and ``Fr = v^2 / (g l)`` the Froude number of the speed
#: (:func:`run_stance_guess`): the coarse stages hold the share at its guess until the
#: fractions are released, and from a guess far from the optimum they fail first (the
#: five-link run at 120 m/min fails from 0.7 and converges from 0.83 or 0.9). The optima
#: measured in docs/running.md: 0.95 (the bound) at Fr 0.1-0.25, 0.73 at 0.69, 0.48 at 1.76.
RUN_STANCE_GUESS = (0.95, 0.3, 0.4, 0.9)
#: A run's step length bounds on the reference biped (legs of 1 m; times ``l / 1 m``): a
#: flight carries the step beyond the legs' reach (people take 1.2-1.6 m steps at 240 m/min
#: on 0.9 m legs), where the walk's 0.8 m would cap it.
RUN_STEP_LENGTH_BOUNDS = (0.02, 3.0)
#: A run's swing clearance on the reference biped (m on legs of 1 m; times ``l / 1 m``): where
#: the caller gives none, the swing foot stays above ``c (4 s (1 - s))^2`` over the stance
#: (``s`` its normalised time; ``GaitOptions.swing_clearance``, quartic profile; a given 0
#: keeps the paper's ``y >= 0``). With only
#: ``y >= 0`` the five-link run's swing foot grazed the ground at the other leg's mid-stance
#: (0 mm at 90 and 120 m/min) and its knee flexed twice in one swing (4 and 6 turns, failing
#: ``swing.reversals``); with 0.1 m it flexes once (2 turns) for +2.4 % and +0.1 % of the
#: cost (docs/running.md, "The swing of a run"). Only on point feet (one contact point per
#: leg): the seven-link run on its toes passes ``verify`` without it at 60-240 m/min, and with
#: it costs 3-16 % more and, with its step fixed at 1.0 m at 150 m/min, holds the swing foot on
#: its plantarflexion limit (4 turns, failing ``swing.reversals``).
RUN_SWING_CLEARANCE = 0.1


def _describe(model: RobotModel) -> str:
    counts = [len(g) for g in legs_contacts(model)]
    if len(counts) == 2 and counts == [1, 1]:
        return f"model {model.name!r} has one contact point on each leg"
    if len(counts) == 2 and counts == [2, 2]:
        return f"model {model.name!r} has a heel and a toe on each foot"
    return (f"model {model.name!r} has {len(counts)} leg(s) with "
            f"{'+'.join(map(str, counts)) or 'no'} contact point(s)")


def default_gait(model: RobotModel) -> str:
    """The built-in gait the model's contact points allow: ``"walk"`` with one point on each
    of two legs, ``"heel-toe"`` with two (heel and toe).

    Raises:
        GaitOptionsError: another count (no built-in gait fits: a contact sequence must be
            given).
    """
    counts = [len(g) for g in legs_contacts(model)]
    if counts == [1, 1]:
        return "walk"
    if counts == [2, 2]:
        return "heel-toe"
    raise GaitOptionsError(f"{_describe(model)}: no built-in gait fits (walk: one contact "
                           "point per leg, heel-toe: two): give a contact sequence "
                           "(--contact-sequence)")


def gait_problem(model: RobotModel, gait: str) -> str | None:
    """Why ``model`` cannot do the built-in ``gait`` (one line naming the gait it can), or
    None if it can (the walk needs one point per leg, the heel-toe walk two, the run either:
    on feet it runs on the toes) or
    if no built-in gait fits (the gait's own checks then name what the model lacks)."""
    try:
        allowed = default_gait(model)
    except GaitOptionsError:
        return None
    if gait in (allowed, "run"):
        return None  # a run stands on one point per leg, or on the toes of feet
    also = " or 'run'"
    return (f"sequence.gait = {gait!r}: {_describe(model)}: use gait {allowed!r}{also} "
            f"(--gait {allowed}, the default)")


def default_speed(model: RobotModel, gait: str) -> float:
    """The default speed (m/s) of ``gait`` on ``model``: :data:`DEFAULT_SPEEDS` at equal
    Froude number, ``v = v_ref sqrt(g l / (g_ref l_ref))`` (0.2 m/s exactly for the
    five-link walk)."""
    return model_scale(model).speed(DEFAULT_SPEEDS.get(gait, DEFAULT_SPEEDS["walk"]))


def _phase_count(options: GaitOptions, gait: str) -> int:
    if options.contact_sequence is not None:
        try:
            return len(sequence_from_dict(options.contact_sequence).phases)
        except ContactSequenceError as exc:
            raise GaitOptionsError(str(exc)) from None
    return 4 if gait == "heel-toe" else 2


def run_stance_guess(model: RobotModel, speed: float) -> float:
    """The first guess of a run's stance share at ``speed`` (m/s) on ``model``
    (:data:`RUN_STANCE_GUESS`: 0.9 at a walk's Froude numbers, 0.74 at 150 m/min and 0.42
    at 240 m/min on 0.93 m legs)."""
    a, b, lo, hi = RUN_STANCE_GUESS
    scale = model_scale(model)
    froude = speed * speed / (scale.gravity * scale.leg_length)
    return min(max(a - b * froude, lo), hi)


def _stance_share(options: GaitOptions, guess: float | None) -> dict[str, Any]:
    """The fraction left to the model: a run's (``guess`` given) free within
    :data:`RUN_STANCE_BOUNDS` from ``guess`` (moved into bounds the caller gave; fixed at it
    with ``free_phase_fractions`` or a stride, which free it their own way or not at all),
    any other gait's 0.85."""
    o = options
    if guess is None:
        return {"single_support_fraction": float(o.single_support_fraction)}
    if o.single_support_fraction_bounds is not None:
        lo, hi = o.single_support_fraction_bounds
        return {"single_support_fraction": min(max(guess, lo), hi)}
    if o.free_phase_fractions or o.stride:
        return {"single_support_fraction": guess}
    return {"single_support_fraction": guess,
            "single_support_fraction_bounds": RUN_STANCE_BOUNDS}


def options_for_model(model: RobotModel, options: GaitOptions) -> GaitOptions:
    """``options`` with every default that follows the model (module docstring) replaced by
    the model's value; the values the caller gave stay.

    Raises:
        GaitOptionsError: a given built-in gait the model cannot do (:func:`gait_problem`).
            (When no built-in gait fits and none was given, the gait is the walk, and the
            walk's own checks name what the model lacks.)
    """

    o, changes = options, dict[str, Any]()
    custom = o.contact_sequence is not None
    gait = str(o.gait)
    if custom:
        if follows_model(o.gait):
            changes["gait"] = gait
    elif follows_model(o.gait):
        try:
            gait = changes["gait"] = default_gait(model)
        except GaitOptionsError:
            # No built-in gait fits (not two legs with one or two points each): the walk, whose
            # own checks say what the model lacks (two contact points, one per leg).
            gait = changes["gait"] = "walk"
    elif (why := gait_problem(model, gait)) is not None:
        raise GaitOptionsError(why)
    if follows_model(o.formulation):
        changes["formulation"] = default_formulation(model, gait, custom, bool(o.stride))
    if follows_model(o.discretisation.knots):
        changes["knots"] = (MULTI_PHASE_KNOTS if _phase_count(o, gait) > 2
                            else tuple(int(k) for k in o.knots))
    scale = model_scale(model)
    if follows_model(o.speed):
        speed_gait = gait
        if custom:
            try:
                speed_gait = default_gait(model)
            except GaitOptionsError:
                speed_gait = "walk"
        changes["speed"] = default_speed(model, speed_gait)
    if follows_model(o.speed_bounds):
        changes["speed_bounds"] = tuple(scale.speed(v) for v in o.speed_bounds)
    if follows_model(o.step_length_bounds):
        bounds = RUN_STEP_LENGTH_BOUNDS if gait == "run" and not custom else o.step_length_bounds
        changes["step_length_bounds"] = tuple(scale.length(v) for v in bounds)
    if follows_model(o.single_support_fraction):
        speed = changes.get("speed", o.speed)
        if speed is None:  # a free speed starts from the run's default, within its bounds
            lo, hi = changes.get("speed_bounds", o.speed_bounds)
            speed = min(max(default_speed(model, "run"), lo), hi)
        guess = run_stance_guess(model, speed) if gait == "run" and not custom else None
        changes |= _stance_share(o, guess)
    if (gait == "run" and not custom and o.swing_clearance is None
            and all(len(leg) == 1 for leg in legs_contacts(model))):
        changes["swing_clearance"] = scale.length(RUN_SWING_CLEARANCE)
    if follows_model(o.rate_bound):
        changes["rate_bound"] = scale.rate(o.rate_bound)
    if follows_model(o.max_impulse):
        changes["max_impulse"] = scale.impulse(o.max_impulse)
    if follows_model(o.cost_smoothing):
        speed = changes.get("speed", o.speed)
        if speed is None:  # a free speed: the one its solve starts from, the gait's default
            speed = default_speed(model, str(changes.get("gait", gait)))
        changes["cost_smoothing"] = cost_smoothing_for(scale, o.cost_smoothing, speed)
    return o.replace(**changes)


#: The speed (m/s) of the reference biped at which its ``cost_smoothing`` (0.01 W) applies:
#: the paper's optimal 12 m/min, where the five-link costs of transport were measured.
SMOOTHING_SPEED = 0.2


def cost_smoothing_for(scale: ModelScale, reference: float, speed: float) -> float:
    """The smoothing ``eps`` (W) of the costs of transport's positive parts for a model of
    ``scale`` walking at ``speed`` (m/s), from the reference biped's ``reference`` (W) at
    :data:`SMOOTHING_SPEED`: carried over as a power, then times the power of ten nearest to
    the speed's ratio to the reference speed at equal Froude number, never below 1:
    ``eps = power(reference) 10^k``, ``k = round(log10(max(1, v / speed(SMOOTHING_SPEED))))``.

    Why it grows with the speed: the costs of transport divide the work by ``W L``, so their
    integrand is the actuator power over ``W v`` (``W`` the weight); an ``eps`` that follows
    ``W v`` smooths the same share of that dimensionless integrand at every speed. A fixed
    ``eps`` sharpens the kinks against the powers as the speed grows: on the seven-link
    model at 80 m/min IPOPT did not converge with 0.016 W within 1000 iterations, and did
    with 0.16 W (docs/feet.md, "Costs of transport at people's speed"). Why powers of
    ten: ``eps`` shapes the NLP, so every value is another NLP to build; these are the
    rungs of the smoothing ladder (:mod:`gaitopt.gait.solve.cost_continuation`), which a
    solve builds anyway, and a sweep over speeds needs one or two of them. Below the
    reference speed it stays at the reference value, where the five-link studies were
    measured: 0.01 W exactly on the five-link biped up to 37.9 m/min (ratio sqrt(10))."""
    ratio = max(1.0, speed / scale.speed(SMOOTHING_SPEED))
    return scale.power(reference) * 10.0 ** round(math.log10(ratio))
