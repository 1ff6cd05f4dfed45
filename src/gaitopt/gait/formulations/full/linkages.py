"""The linkages of the full problem's period: the event maps, and the controls' continuity
and periodicity.

At each event the next phase starts from the state the event map gives
(:func:`event_linkage`): the configuration ``q`` (rad, m) is kept and the velocities
``qd`` (rad/s, m/s) jump by the impact or the liftoff impulse; after the last event the
period map too (the legs swapped and ``x`` moved on by a step, or by a stride). With the
paper's control model the actuator torques (N m) are continuous across the events within
the period, and optionally periodic with the legs swapped (:func:`periodic_controls`).
:func:`step_linkages` lists them in the NLP's order.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from gaitopt.dynamics.backend import as_scalars, vector
from gaitopt.gait.formulations.full.constraints import split_state
from gaitopt.gait.formulations.full.physics import (
    actuator_names,
    event_map,
    hold_axes,
    swap_state,
)
from gaitopt.gait.formulations.step_parameters import IMPULSE_INDEX, STEP_LENGTH_INDEX
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.sequence.contact_sequence import ContactSequence
from gaitopt.ocp.problem import ControlLinkage, Linkage
from gaitopt.robot.model import RobotModel
from gaitopt.robot.symmetry import LegSwap

_L, _P = STEP_LENGTH_INDEX, IMPULSE_INDEX


def step_linkages(model: RobotModel, options: GaitOptions, seq: ContactSequence,
                  symmetry: LegSwap) -> list[Linkage | ControlLinkage]:
    """The linkages of the period, in order: for each event its :func:`event_linkage` and,
    with the paper's control model and before the last event, the actuators both phases
    share continuous across it; then, with ``periodic_controls`` and the paper's control
    model, :func:`periodic_controls`."""
    actuators_of = {ph.name: actuator_names(model, ph.held, ankle=options.ankle)
                    for ph in seq.phases}
    paper = options.control_model == "paper"
    n_ph = len(seq.phases)
    linkages: list[Linkage | ControlLinkage] = []
    for i, ev in enumerate(seq.events):
        linkages.append(event_linkage(model, seq, symmetry, i))
        src, dst = seq.phases[i].name, seq.phases[(i + 1) % n_ph].name
        shared = [a for a in actuators_of[src] if a in actuators_of[dst]]
        if i != n_ph - 1 and paper and shared:
            linkages.append(ControlLinkage(src, dst, controls=shared,
                                           name=f"controls continuous at {ev.name}"))
    if options.periodic_controls and paper:
        linkages.append(periodic_controls(model, symmetry, seq, actuators_of))
    return linkages


def event_linkage(model: RobotModel, seq: ContactSequence, symmetry: LegSwap, event: int
                  ) -> Linkage:
    """``x_next(0) = [q, qd+]`` from the end ``[q, qd]`` of phase ``event``: ``qd+`` the
    event map's velocity after the event
    (:func:`~gaitopt.gait.formulations.full.physics.event_map`: the impact, or the liftoff
    impulse ``P``), and after the last event the period map too
    (:func:`~gaitopt.gait.formulations.full.physics.swap_state`: the legs swapped and ``x``
    moved on by ``L``, or by ``2 L`` with no swap for a stride)."""
    n_ph, nq = len(seq.phases), model.nq
    ev = seq.events[event]
    last = event == n_ph - 1

    def jump(xf: Any, uf: Any, p: Any) -> Any:
        q, qd = split_state(model, xf)
        after = event_map(model, seq, event, q, qd, p[_P]).qd_after
        if last:
            q_next, qd_next = swap_state(model, symmetry, q, after, seq.steps * p[_L])
            return vector(q_next + qd_next)
        return vector(as_scalars(q, nq, "q") + as_scalars(after, nq, "qd"))

    period = " (legs swapped)" if seq.steps == 1 else " (a stride: x + 2 L, no swap)"
    return Linkage(seq.phases[event].name, seq.phases[(event + 1) % n_ph].name, jump=jump,
                   name=f"{ev.name}: event map" + (f" and periodicity{period}" if last else ""))


def periodic_controls(model: RobotModel, symmetry: LegSwap, seq: ContactSequence,
                      actuators_of: Mapping[str, Sequence[str]]) -> ControlLinkage:
    """``u_first(0)[a] = (S_u u_last(T))[a] = sign_a u_last(T)[swap(a)]`` (N m) for every
    actuator ``a`` of the first phase whose swapped counterpart acts at the end of the last
    phase (``S_u`` a signed permutation: :meth:`LegSwap.actuator_source`; the identity for a
    stride)."""
    first, last = seq.phases[0].name, seq.phases[-1].name
    last_acts = list(actuators_of[last])
    names = [a.name for a in model.actuators]
    targets, sources = [], []
    for a in actuators_of[first]:
        j, sign = symmetry.actuator_source(model.actuator_index(a))
        if names[j] in last_acts:
            targets.append(a)
            sources.append((last_acts.index(names[j]), sign))
    n_last = len(last_acts) + 2 * len(hold_axes(seq.phases[-1].held))

    def fn(u_from: Any, p: Any) -> Any:
        us = as_scalars(u_from, n_last, "u")
        return vector([us[k] if sign > 0 else -us[k] for k, sign in sources])

    return ControlLinkage(last, first, fn=fn, controls=targets,
                          name="controls periodic (legs swapped)")
