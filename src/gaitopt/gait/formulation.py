"""The two formulations of the walking problem behind one interface.

``GaitOptions.formulation`` chooses between the paper's reduced coordinates
(:mod:`gaitopt.gait.problem`, :mod:`gaitopt.gait.walking`) and full coordinates on a contact
sequence (:mod:`gaitopt.gait.full_coordinates`). The staged solve (:mod:`gaitopt.gait.solve`)
asks this module for the problem, the bounds of a stage and the guess; everything else
(stages, warm starts, refinement) is shared.
"""

from __future__ import annotations

import numpy as np

from gaitopt.dynamics.reduced import checked_biped
from gaitopt.gait import full_coordinates as full
from gaitopt.gait import walking
from gaitopt.gait.contact_sequence import ContactSequence, walking_sequence
from gaitopt.gait.options import GaitOptions
from gaitopt.gait.problem import Relaxation, relaxed_bounds, walking_problem
from gaitopt.ocp import Bounds, Guess, PhaseGuess, Problem, Transcription
from gaitopt.robot.biped import BipedStructure, biped_structure
from gaitopt.robot.model import RobotModel


def biped_of(model: RobotModel, options: GaitOptions) -> BipedStructure:
    """The legs of ``model``: the reduced formulation needs exactly the five-link shape, the
    full one any torso with two thigh-shank legs (other links allowed)."""
    return checked_biped(model) if options.formulation == "reduced" else biped_structure(model)


def contact_sequence(model: RobotModel, options: GaitOptions) -> ContactSequence:
    """The contact sequence of ``options`` (the paper's walk, or the single-support walk)."""
    return walking_sequence(model, options.single_support_fraction,
                            impulse=options.impulse and options.double_support)


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


def formulation_guess(model: RobotModel, options: GaitOptions, guess: Guess) -> Guess:
    """A guess in reduced coordinates (:func:`gaitopt.gait.guess.naive_guess`) turned into
    one for ``options.formulation``: full states ``[q, qd]`` by name, the same actuator
    torques, projection controls left at 0."""
    if options.formulation != "full":
        return guess
    names = full.state_names(model)
    phases = {}
    for name, ph in guess.phases.items():
        x_red = np.asarray(ph.x, dtype=float)
        rows = []
        for x in x_red:
            if name == walking.SINGLE:
                q, qd = walking.single_support_to_full(model, x)
            else:
                z, zd = walking.split_state(x, len(x) // 2)
                from gaitopt.dynamics.reduced import double_support_state

                step = guess.parameters["step_length"]
                q, qd = double_support_state(model, 0, z, zd, walking.ORIGIN, (step, 0.0))
            rows.append(np.concatenate([np.asarray(q, float).ravel(),
                                        np.asarray(qd, float).ravel()]))
        xs = np.array(rows)
        controls = walking.control_names(model, name, ankle=options.ankle)
        u = np.asarray(ph.u, dtype=float)
        phases[name] = PhaseGuess(x={n: xs[:, j] for j, n in enumerate(names)},
                                  u={n: u[:, j] for j, n in enumerate(controls)}, tau=ph.tau)
    return Guess(phases=phases, parameters=guess.parameters)
