"""Orbital stability of a walk with feet (the seven-link heel-toe step): a step with two
state-triggered touchdowns (the heel strike, then the toe of the same foot at foot flat) and a
Poincare section on a flat foot (heel pinned, toe held along the normal).

The gait (``data/heel_toe_60.gait.json``) is the seven-link model's heel-toe walk at 60 m/min
on 8 + 5 knots, solved by ``gaitopt solve --model seven-link --gait heel-toe --speed 60m/min
--knots 8,5``. Independent reference: central finite differences of the simulated return map
against the variational equations with one saltation factor per touchdown.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gaitopt.analysis.return_map import section_constraints, simulate_step
from gaitopt.analysis.stability import gait_stability, gait_start, step_from_gait
from gaitopt.gait.record.file import Gait

DATA = Path(__file__).parent / "data"
GAINS = (300.0, 30.0)


@pytest.fixture(scope="module")
def gait() -> Gait:
    return Gait.load(DATA / "heel_toe_60.gait.json")


def test_heel_toe_step_has_two_guards_and_a_flat_foot_section(gait: Gait) -> None:
    spec = step_from_gait(gait, pd=GAINS)
    assert [ph.contacts for ph in spec.phases] == [("heel_1", "toe_1:y"), ("toe_1",),
                                                   ("toe_1", "heel_2"), ("heel_2",)]
    # heel_off ends when heel 2 strikes; heel_rocker when toe 2 lands (foot flat).
    assert spec.guard_phases == (1, 3)
    assert [spec.guard_point(i) for i in spec.guard_phases] == ["heel_2", "toe_2"]
    assert spec.phases[0].duration is not None and spec.phases[2].duration is not None
    kinds = [[(e.kind, e.contact, e.contacts) for e in ev] for ev in spec.events]
    assert kinds == [[("liftoff", "heel_1", ("toe_1",))],
                     [("strike", "heel_2", ("toe_1", "heel_2"))],
                     [("liftoff", "toe_1", ("heel_2",))],
                     [("strike", "toe_2", ("heel_2", "toe_2:y"))]]
    assert spec.holds == ("heel_1", "toe_1:y") and spec.stance == "heel_1"
    # The gait's start lies on the section: heel at the origin, toe on the ground, at rest.
    values, jac = section_constraints(spec, gait_start(gait))
    assert values.shape == (6,) and jac.shape == (6, 2 * gait.model.nq)
    assert np.max(np.abs(values)) < 1e-8


def test_linearized_about_its_knots_it_is_periodic(gait: Gait) -> None:
    rep = gait_stability(gait, about="gait")
    nq = gait.model.nq
    assert rep.multipliers.size == 2 * nq - 6
    assert rep.removed[0].count == 6
    assert rep.start_residual < 1e-8  # the transcription's own periodicity
    assert np.isfinite(rep.spectral_radius) and rep.verdict in ("stable", "unstable",
                                                                 "marginal")


def test_tracked_replay_reaches_both_touchdowns_near_the_gait(gait: Gait) -> None:
    """With PD tracking the simulated step strikes with the heel when the gait does, lands
    the toe, and returns near its start (the coarse gait's knots are tracked, not followed
    exactly: positions within 2 cm or 0.02 rad, rates within 0.2 per second)."""
    spec = step_from_gait(gait, pd=GAINS, rtol=1e-8)
    y0 = gait_start(gait)
    result = simulate_step(spec, y0)
    heel_off = gait.phases[1].duration
    assert abs(result.strike_time - heel_off) < 0.05 * heel_off
    step_time = sum(ph.duration for ph in gait.phases)
    assert abs(result.step_time - step_time) < 0.05 * step_time
    nq = gait.model.nq
    assert np.max(np.abs(result.y_next[:nq] - y0[:nq])) < 0.02
    assert np.max(np.abs(result.y_next[nq:] - y0[nq:])) < 0.2


@pytest.mark.slow
def test_heel_toe_monodromies_agree(gait: Gait) -> None:
    """Variational equations with two saltation factors against central finite differences of
    the simulated map (a few minutes)."""
    rep = gait_stability(gait, pd=GAINS)
    assert rep.fd_agreement is not None and rep.fd_agreement < 1e-4, rep.fd_agreement
    assert rep.multipliers.size == 2 * gait.model.nq - 6
