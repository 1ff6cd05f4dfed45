"""What each formulation of the walking problem supports, as data.

The formulations themselves (problem, bounds, guess, record) are objects behind one protocol in
:mod:`gaitopt.gait.formulation`, selected there by :func:`~gaitopt.gait.formulation.formulation_of`.
Their traits live here, below :mod:`gaitopt.gait.options`, so that the options' checks can ask
what a formulation supports (the options module cannot import the formulations, which are
built from the options). Nothing else looks a formulation up by its name.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class FormulationTraits:
    """What one formulation supports and how its solve is tuned.

    Attributes:
        name: ``GaitOptions.formulation``'s value for it.
        contact_sequences: any contact sequence (heel-toe walks, runs, given sequences,
            strides, free phase fractions); without it only the paper's two-phase walk.
        straight_stance_knee: ``min_stance_knee_flexion`` may be 0 (the reduced coordinates'
            leg inverse kinematics is singular at a straight knee).
        quasi_newton_fine_stages: the stages on fine grids use IPOPT's limited-memory
            Hessian (:data:`gaitopt.gait.stages.FINE_STAGE_OPTIONS`).
        unscaled_mumps_fine_walk: the walk's fine-grid stages add
            :data:`gaitopt.gait.stages.FULL_WALK_FINE_GRID_OPTIONS`.
        warm_enforced_contact: the enforced-contact stage takes
            :data:`gaitopt.gait.stages.ENFORCED_CONTACT_OPTIONS` for its warm start.
        multistart_by_default: ``gaitopt solve`` uses multistart far from the reference
            speed (where it was measured: the paper's walk in reduced coordinates).
    """

    name: str
    contact_sequences: bool
    straight_stance_knee: bool
    quasi_newton_fine_stages: bool
    unscaled_mumps_fine_walk: bool
    warm_enforced_contact: bool
    multistart_by_default: bool


#: The paper's reduced coordinates of a five-link biped.
REDUCED = FormulationTraits(
    name="reduced", contact_sequences=False, straight_stance_knee=False,
    quasi_newton_fine_stages=True, unscaled_mumps_fine_walk=False,
    warm_enforced_contact=False, multistart_by_default=True)
#: Full coordinates on a contact sequence.
FULL = FormulationTraits(
    name="full", contact_sequences=True, straight_stance_knee=True,
    quasi_newton_fine_stages=False, unscaled_mumps_fine_walk=True,
    warm_enforced_contact=True, multistart_by_default=False)

#: Every formulation's traits by name, the first one the paper's.
FORMULATION_TRAITS: dict[str, FormulationTraits] = {t.name: t for t in (REDUCED, FULL)}
