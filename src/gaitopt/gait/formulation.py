"""The two formulations of the walking problem behind one interface.

``GaitOptions.formulation`` chooses between the paper's reduced coordinates
(:mod:`gaitopt.gait.problem`, :mod:`gaitopt.gait.walking`) and full coordinates on a contact
sequence (:mod:`gaitopt.gait.full_coordinates`). The staged solve (:mod:`gaitopt.gait.solve`)
asks this module for the legs, the problem and the bounds of a stage; everything else
(guesses, stages, warm starts, refinement) is shared.
"""

from __future__ import annotations

from gaitopt.gait import full_coordinates as full
from gaitopt.gait.builtin_sequences import heel_toe_sequence, running_sequence, walking_sequence
from gaitopt.gait.contact_sequence import (
    ContactSequence,
    ContactSequenceError,
    check_sequence,
    sequence_from_dict,
    stride_sequence,
)
from gaitopt.gait.full_physics import period_map
from gaitopt.gait.options import GaitOptions, GaitOptionsError
from gaitopt.gait.phase_fractions import (
    with_first_fraction_bounds,
    with_free_fractions,
    with_shares,
)
from gaitopt.gait.problem import Relaxation, relaxed_bounds, walking_problem
from gaitopt.ocp import Bounds, Problem, Transcription
from gaitopt.robot.biped import (
    Biped,
    BipedStructureError,
    biped_of,
    has_reduced_shape,
    reduced_biped,
)
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import contact_pairing


def biped_for(model: RobotModel, options: GaitOptions) -> Biped | None:
    """The legs of ``model``: the reduced formulation needs exactly the five-link shape; in the
    full one, a torso with two thigh-shank legs (other links allowed), or None for any other
    tree (feet, knee-less legs: the guess is then :mod:`gaitopt.gait.sequence_guess`)."""
    if options.formulation == "reduced":
        return reduced_biped(model)
    try:
        return biped_of(model)
    except BipedStructureError:
        return None


def default_formulation(model: RobotModel, gait: str, custom_sequence: bool,
                        stride: bool = False) -> str:
    """The formulation a user gets without asking: the paper's reduced coordinates for the
    walk of a five-link-shaped biped, else full coordinates (the only one for other models,
    runs, heel-toe walks, given sequences and strides)."""
    if gait != "walk" or custom_sequence or stride or not has_reduced_shape(model):
        return "full"
    return "reduced"


def contact_sequence(model: RobotModel, options: GaitOptions) -> ContactSequence:
    """The contact sequence of ``options``: the one given as data, or the paper's walk, the
    single-support walk, a run or a heel-toe walk; doubled into a stride with ``stride``
    (:func:`stride_sequence`); with its fractions freed by
    ``single_support_fraction_bounds`` (phase 0 of two) or ``free_phase_fractions`` (every
    phase, default bounds)."""
    seq = _sequence(model, options)
    if options.stride:
        seq = stride_sequence(seq, contact_pairing(model))
    if options.single_support_fraction_bounds is not None:
        seq = with_first_fraction_bounds(seq, options.single_support_fraction_bounds)
    if options.free_phase_fractions:
        seq = with_free_fractions(seq)
    if options.phase_shares is not None:
        seq = with_shares(seq, options.phase_shares)
    return seq


def _sequence(model: RobotModel, options: GaitOptions) -> ContactSequence:
    if options.contact_sequence is not None:
        return sequence_from_dict(options.contact_sequence)
    if options.gait == "heel-toe":
        return heel_toe_sequence(model, contact_pairing(model),
                                 options.single_support_fraction, impulse=options.impulse)
    if options.gait == "run":
        return running_sequence(model, options.single_support_fraction)
    return walking_sequence(model, options.single_support_fraction,
                            impulse=options.impulse and options.double_support)


def checked_sequence(model: RobotModel, options: GaitOptions) -> ContactSequence | None:
    """The contact sequence of ``options`` checked against ``model`` (None in the reduced
    formulation); a bad one raises :class:`GaitOptionsError` naming what is wrong."""
    if options.formulation != "full":
        return None
    try:
        seq = contact_sequence(model, options)
        check_sequence(model, seq, dict(period_map(model, seq).contacts))
    except (ContactSequenceError, ValueError) as exc:
        raise GaitOptionsError(f"contact sequence: {exc}") from None
    if options.free_phase_fractions and len(seq.phases) < 2:
        raise GaitOptionsError(f"free_phase_fractions: sequence {seq.name!r} has one phase, "
                               "whose share is the whole step: nothing to free")
    return seq


def problem_for(model: RobotModel, options: GaitOptions) -> Problem:
    """The OCP of one step in the formulation ``options.formulation``."""
    if options.formulation == "full":
        return full.full_problem(model, options, contact_sequence(model, options))
    return walking_problem(model, options)


def stage_bounds(tr: Transcription, relax: Relaxation, options: GaitOptions) -> Bounds:
    """The bounds of a stage: the unilateral conditions relaxed by ``relax``."""
    if options.formulation == "full":
        return full.full_stage_bounds(tr, relax.force, relax.impulse)
    return relaxed_bounds(tr, relax)
