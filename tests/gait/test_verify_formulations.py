"""``verify_gait`` works from the full-coordinate fields whatever formulation computed the gait:
the default gait rewritten as full-coordinate phases (``state_names`` = the coordinates and
their rates, ``x = [q, qd]``, ``xdot = [qd, qdd]``, samples on that interpolant) verifies, and
its corrupted copies fail the same checks."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest

from gaitopt.analysis.checks.knots import full_state_names, state_map
from gaitopt.analysis.verify import UnknownStatesError, verify_gait
from gaitopt.dynamics.kinematics import contact_position, point_position
from gaitopt.gait.record.file import Gait, GaitPhase
from gaitopt.gait.record.interpolation import phase_states_at
from gaitopt.robot import load_model
from tests.gait.test_verify import CORRUPTIONS


def _points(gait: Gait, q: np.ndarray) -> dict[str, list[list[float]]]:
    """The sample points by the kinematics functions (hip, knees, tips, torso top)."""
    model = gait.model
    torso = model.base
    rows: dict[str, list[list[float]]] = {n: [] for n in gait.samples.points}
    for qk in q:
        pts = {"hip": qk[0:2],
               "knee_1": point_position(model, qk, "shank_1", (0.0, 0.0)),
               "knee_2": point_position(model, qk, "shank_2", (0.0, 0.0)),
               "tip_1": contact_position(model, qk, "tip_1"),
               "tip_2": contact_position(model, qk, "tip_2"),
               "torso_top": point_position(model, qk, torso.name,
                                           torso.local_point(torso.length))}
        for name in rows:
            rows[name].append([float(v) for v in np.asarray(pts[name]).ravel()])
    return rows


def full_coordinate_copy(gait: Gait) -> dict[str, Any]:
    """The gait as full-coordinate phases; samples re-drawn from their Hermite interpolant."""
    data = copy.deepcopy(gait.to_dict())
    names = list(full_state_names(gait.model))
    s = gait.samples
    q_s, qd_s = s.q.copy(), s.qd.copy()
    taken = np.zeros(s.t.size, dtype=bool)
    for ph, raw in zip(gait.phases, data["phases"], strict=True):
        raw["state_names"] = names
        raw["x"] = np.hstack([ph.q, ph.qd]).tolist()
        raw["xdot"] = np.hstack([ph.qd, ph.qdd]).tolist()
        del raw["error_estimate"]  # the reduced grid's estimate; not one of these states
        raw.pop("costates", None)  # the reduced states' costates, likewise
        full = GaitPhase(**{k: v for k, v in raw.items() if k != "error_estimate"})
        mask = (s.t <= ph.t[-1]) & ~taken
        taken |= mask
        x = phase_states_at(full, s.t[mask])
        q_s[mask], qd_s[mask] = x[:, :gait.model.nq], x[:, gait.model.nq:]
    data["samples"]["q"], data["samples"]["qd"] = q_s.tolist(), qd_s.tolist()
    data["samples"]["points"] = _points(gait, q_s)
    return data


@pytest.fixture(scope="module")
def full_gait(default_gait: Gait) -> Gait:
    return Gait.from_dict(full_coordinate_copy(default_gait))


def test_the_state_map_of_full_coordinate_phases_is_the_identity() -> None:
    model = load_model("five-link")
    rng = np.random.default_rng(1)
    q, qd, qdd = rng.normal(size=(3, model.nq))
    x, xdot = (np.asarray(v, dtype=float).ravel()
               for v in state_map(model, full_state_names(model))(q, qd, qdd))
    np.testing.assert_array_equal(x, np.concatenate([q, qd]))
    np.testing.assert_allclose(xdot, np.concatenate([qd, qdd]), rtol=0, atol=1e-15)


def test_a_full_coordinate_gait_verifies(full_gait: Gait) -> None:
    assert full_gait.phases[0].state_names[:3] == ("x", "y", "torso")
    report = verify_gait(full_gait)
    assert report.passed, [(c.id, c.value, c.where) for c in report.checks if not c.passed]
    assert report.check("integration.interval").limit == 0.05  # no estimate: fixed limit


@pytest.mark.parametrize("name", ["torso angle + 2 mrad (q)", "hip_1 torque + 5 % (u)",
                                  "torso acceleration + 0.05 rad/s^2 (qdd)",
                                  "stance knee rate of a sample + 0.01 rad/s (samples.qd)"])
def test_a_corrupted_full_coordinate_gait_fails(default_gait: Gait, name: str) -> None:
    data = full_coordinate_copy(default_gait)
    CORRUPTIONS[name][0](data)
    failed = set(verify_gait(Gait.from_dict(data)).failed_ids)
    assert CORRUPTIONS[name][1] <= failed, (CORRUPTIONS[name][1], failed)


def test_unknown_state_names_are_an_error(default_gait: Gait) -> None:
    data = copy.deepcopy(default_gait.to_dict())
    data["phases"][1]["state_names"] = ["a", "b", "c", "a_rate", "b_rate", "c_rate"]
    with pytest.raises(UnknownStatesError, match=r"state names \['a', 'b'"):
        verify_gait(Gait.from_dict(data))
