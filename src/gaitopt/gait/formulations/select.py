"""The two formulations of the walking problem, each one object behind one protocol.

``GaitOptions.formulation`` names one of them: the paper's reduced coordinates
(:data:`REDUCED`: :mod:`gaitopt.gait.formulations.reduced.problem`,
:mod:`gaitopt.gait.formulations.reduced.physics`,
:mod:`gaitopt.gait.formulations.reduced.extract`) or full coordinates on a contact sequence
(:data:`FULL`: :mod:`gaitopt.gait.formulations.full.problem`,
:mod:`gaitopt.gait.formulations.full.extract`). Each is a :class:`Formulation`: its legs, its
checked contact sequence, its problem, the bounds of a stage, the free phase fractions' first
guesses, the naive guess of a cold start, the record of a solution, and its
:class:`~gaitopt.gait.formulations.traits.FormulationTraits` (what it supports, how its stages are
tuned). :func:`formulation_of` is the one place that picks it by name; the staged solve
(:mod:`gaitopt.gait.solve.staged`), the stages, the record and the command line ask the object and
never test the name. Everything else (stages, warm starts, refinement) is shared. This is the only
module that imports both formulations.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from gaitopt.gait.formulations.full import problem as full
from gaitopt.gait.formulations.full.extract import full_record
from gaitopt.gait.formulations.full.physics import period_map
from gaitopt.gait.formulations.record_points import RecordParts
from gaitopt.gait.formulations.reduced.extract import reduced_record
from gaitopt.gait.formulations.reduced.problem import relaxed_bounds, walking_problem
from gaitopt.gait.formulations.step_parameters import Relaxation
from gaitopt.gait.formulations.traits import FULL as FULL_TRAITS
from gaitopt.gait.formulations.traits import REDUCED as REDUCED_TRAITS
from gaitopt.gait.formulations.traits import FormulationTraits
from gaitopt.gait.guess.naive import WalkingGuess, naive_guess, naive_running_guess
from gaitopt.gait.guess.sequence import sequence_guess
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError
from gaitopt.gait.sequence.builtin import heel_toe_sequence, running_sequence, walking_sequence
from gaitopt.gait.sequence.contact_sequence import (
    ContactSequence,
    ContactSequenceError,
    check_sequence,
    sequence_from_dict,
    stride_sequence,
)
from gaitopt.gait.sequence.phase_fractions import (
    fraction_parameters,
    with_first_fraction_bounds,
    with_free_fractions,
    with_shares,
)
from gaitopt.gait.solve.staged_run import StagedRun
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

Array = NDArray[np.float64]


class Formulation(Protocol):
    """One formulation of the walking problem: what the staged solve and the record ask of
    it."""

    traits: FormulationTraits

    def biped(self, model: RobotModel) -> Biped | None:
        """The legs of ``model``, or None for a tree the formulation walks without them."""
        ...

    def checked_sequence(self, model: RobotModel, options: GaitOptions
                         ) -> ContactSequence | None:
        """The contact sequence of ``options`` checked against ``model`` (None if the
        formulation has none to check); a bad one raises :class:`GaitOptionsError`."""
        ...

    def problem(self, model: RobotModel, options: GaitOptions) -> Problem:
        """The OCP of one step."""
        ...

    def stage_bounds(self, tr: Transcription, relax: Relaxation) -> Bounds:
        """The bounds of a stage: the unilateral conditions relaxed by ``relax``."""
        ...

    def fraction_guesses(self, model: RobotModel, options: GaitOptions) -> dict[str, float]:
        """The free phase fractions' parameters -> first guesses (empty: none is free)."""
        ...

    def cold_guess(self, model: RobotModel, options: GaitOptions, *, speed: float,
                   step_length: float, knots: tuple[int, int], r_max: float) -> WalkingGuess:
        """The naive guess a cold solve starts from at ``speed`` and ``step_length`` on the
        coarse grid ``knots``, the ankle torques zero; ``r_max`` (m) the legs' reach.

        Raises:
            ReachError: the guess puts a leg beyond its reach (the solve tries the next
                step length).
        """
        ...

    def record(self, solution: StagedRun,
               costates: Callable[[], Mapping[str, Array]]) -> RecordParts:
        """The phases, events and dense samples of a solution's gait record; ``costates``
        gives its phases' costates, for a formulation that records them."""
        ...


class Reduced:
    """The paper's reduced coordinates of a five-link biped (the two-phase walk only)."""

    traits = REDUCED_TRAITS

    def biped(self, model: RobotModel) -> Biped | None:
        """Exactly the five-link shape (:func:`reduced_biped` raises for any other)."""
        return reduced_biped(model)

    def checked_sequence(self, model: RobotModel, options: GaitOptions
                         ) -> ContactSequence | None:
        return None

    def problem(self, model: RobotModel, options: GaitOptions) -> Problem:
        return walking_problem(model, options)

    def stage_bounds(self, tr: Transcription, relax: Relaxation) -> Bounds:
        return relaxed_bounds(tr, relax)

    def fraction_guesses(self, model: RobotModel, options: GaitOptions) -> dict[str, float]:
        return {}

    def cold_guess(self, model: RobotModel, options: GaitOptions, *, speed: float,
                   step_length: float, knots: tuple[int, int], r_max: float) -> WalkingGuess:
        """The geometric walk (:func:`gaitopt.gait.guess.naive.naive_guess`) in reduced states."""
        return naive_guess(model, speed=speed, step_length=step_length,
                           single_support_fraction=options.single_support_fraction,
                           knots=knots, ankle=options.ankle, r_max=r_max, ankle_torques=False,
                           full=False)

    def record(self, solution: StagedRun,
               costates: Callable[[], Mapping[str, Array]]) -> RecordParts:
        return reduced_record(solution, costates)


class Full:
    """Full coordinates ``q, qd`` of the whole tree on a contact sequence."""

    traits = FULL_TRAITS

    def biped(self, model: RobotModel) -> Biped | None:
        """A torso with two thigh-shank legs (other links allowed), or None for any other
        tree (feet, knee-less legs: the guess is then :mod:`gaitopt.gait.guess.sequence`)."""
        try:
            return biped_of(model)
        except BipedStructureError:
            return None

    def checked_sequence(self, model: RobotModel, options: GaitOptions
                         ) -> ContactSequence | None:
        try:
            seq = contact_sequence(model, options)
            check_sequence(model, seq, dict(period_map(model, seq).contacts))
        except (ContactSequenceError, ValueError) as exc:
            raise GaitOptionsError(f"contact sequence: {exc}") from None
        if options.free_phase_fractions and len(seq.phases) < 2:
            raise GaitOptionsError(f"sequence.free_phase_fractions: sequence {seq.name!r} has one "
                                   "phase, whose share is the whole step: nothing to free")
        return seq

    def problem(self, model: RobotModel, options: GaitOptions) -> Problem:
        return full.full_problem(model, options, contact_sequence(model, options))

    def stage_bounds(self, tr: Transcription, relax: Relaxation) -> Bounds:
        return full.full_stage_bounds(tr, relax.force, relax.impulse)

    def fraction_guesses(self, model: RobotModel, options: GaitOptions) -> dict[str, float]:
        return {fp.name: fp.guess
                for fp in fraction_parameters(contact_sequence(model, options))}

    def cold_guess(self, model: RobotModel, options: GaitOptions, *, speed: float,
                   step_length: float, knots: tuple[int, int], r_max: float) -> WalkingGuess:
        """A model without thigh-shank legs, a heel-toe walk, a given sequence or a stride:
        :func:`gaitopt.gait.guess.sequence.sequence_guess` on the contact sequence; a run:
        :func:`gaitopt.gait.guess.naive.naive_running_guess`; else the geometric walk
        (:func:`gaitopt.gait.guess.naive.naive_guess`) in ``[q, qd]``."""
        o = options
        if (self.biped(model) is None or o.gait == "heel-toe"
                or o.contact_sequence is not None or o.stride):
            seq = contact_sequence(model, o)
            return sequence_guess(model, seq, period_map(model, seq).contacts, speed=speed,
                                  step_length=step_length, knots=knots, ankle=o.ankle,
                                  ankle_torques=False)
        if o.gait == "run":
            return naive_running_guess(model, speed=speed, step_length=step_length,
                                       stance_fraction=o.single_support_fraction,
                                       knots=knots, ankle=o.ankle, r_max=r_max,
                                       ankle_torques=False)
        return naive_guess(model, speed=speed, step_length=step_length,
                           single_support_fraction=o.single_support_fraction, knots=knots,
                           ankle=o.ankle, r_max=r_max, ankle_torques=False, full=True)

    def record(self, solution: StagedRun,
               costates: Callable[[], Mapping[str, Array]]) -> RecordParts:
        """(The full formulation records no costates.)"""
        return full_record(solution, contact_sequence(solution.model, solution.options))


#: The formulations by name (``GaitOptions.formulation``).
FORMULATIONS: dict[str, Formulation] = {f.traits.name: f for f in (Reduced(), Full())}
REDUCED: Formulation = FORMULATIONS["reduced"]
FULL: Formulation = FORMULATIONS["full"]


def formulation_of(options: GaitOptions) -> Formulation:
    """The formulation ``options`` name: the one place the name is looked up."""
    return FORMULATIONS[options.formulation]


def biped_for(model: RobotModel, options: GaitOptions) -> Biped | None:
    """The legs of ``model`` in the formulation of ``options`` (:meth:`Formulation.biped`)."""
    return formulation_of(options).biped(model)


def default_formulation(model: RobotModel, gait: str, custom_sequence: bool,
                        stride: bool = False) -> str:
    """The formulation a user gets without asking: the paper's reduced coordinates for the
    walk of a five-link-shaped biped, else full coordinates (the only one for other models,
    runs, heel-toe walks, given sequences and strides)."""
    if gait != "walk" or custom_sequence or stride or not has_reduced_shape(model):
        return FULL.traits.name
    return REDUCED.traits.name


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
    """The contact sequence of ``options`` checked against ``model``
    (:meth:`Formulation.checked_sequence`: None in the reduced formulation); a bad one raises
    :class:`GaitOptionsError` naming what is wrong."""
    return formulation_of(options).checked_sequence(model, options)


def problem_for(model: RobotModel, options: GaitOptions) -> Problem:
    """The OCP of one step in the formulation of ``options`` (:meth:`Formulation.problem`)."""
    return formulation_of(options).problem(model, options)


def stage_bounds(tr: Transcription, relax: Relaxation, options: GaitOptions) -> Bounds:
    """The bounds of a stage: the unilateral conditions relaxed by ``relax``
    (:meth:`Formulation.stage_bounds`)."""
    return formulation_of(options).stage_bounds(tr, relax)
