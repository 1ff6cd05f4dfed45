"""The leg swap as a linear map of the coordinates (:func:`swap_matrices`), checked against
the dynamics it must preserve: the mass matrix, gravity, the velocity terms, the actuation
and the contact points' positions, on models whose legs are and are not permutations of each
other's coordinates (``tests/gait/data/kcg.yaml``: thigh 1 welded to the base)."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gaitopt.dynamics import (
    bias_forces,
    contact_position,
    crba,
    generalized_forces,
    potential_energy,
)
from gaitopt.robot import ModelError, RobotModel, load_model, model_from_dict
from gaitopt.robot.symmetry import (
    SymmetryError,
    contact_pairing,
    leg_swap,
    model_symmetry,
    swap_matrices,
    swap_names,
    swap_permutations,
)

DATA = Path(__file__).parents[1] / "gait" / "data"
KCG = DATA / "kcg.yaml"
MODELS = ["five-link", "seven-link", str(DATA / "compass.yaml"), str(KCG)]


def _random_states(model: RobotModel, n: int, seed: int
                   ) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-1.0, 1.0, model.nq), rng.normal(size=model.nq)) for _ in range(n)]


@pytest.mark.parametrize("name", MODELS)
def test_the_swap_is_an_involution_that_keeps_the_base_position(name: str) -> None:
    model = load_model(name)
    s_q, s_u = swap_matrices(model)
    np.testing.assert_array_equal(s_q @ s_q, np.eye(model.nq))
    np.testing.assert_array_equal(s_u @ s_u, np.eye(model.nu))
    np.testing.assert_array_equal(s_q[:2], np.eye(model.nq)[:2])  # x, y stay
    swap = leg_swap(model)
    np.testing.assert_array_equal(swap.s_q, s_q)
    q = np.arange(1.0, model.nq + 1.0)
    np.testing.assert_array_equal(swap.swap_q(list(q)), s_q @ q)


@pytest.mark.parametrize("name", MODELS)
def test_the_swap_preserves_the_dynamics(name: str) -> None:
    """With ``q' = S q``, ``qd' = S qd`` (S = S^-1): ``S^T M(q') S = M(q)``, the potential
    energy and gravity forces ``S^T g(q') = g(q)``, the velocity terms ``S^T C(q', qd') =
    C(q, qd)``, the actuation ``S^T B S_u = B`` (both contacts held), and contact point c
    of the swapped pose is where its partner is (x shifted, base position unchanged)."""
    model = load_model(name)
    s_q, s_u = swap_matrices(model)
    contacts = dict(leg_swap(model).contacts)
    held = [c.name for c in model.contacts]
    for q, qd in _random_states(model, 5, seed=3):
        m, m_s = np.asarray(crba(model, q)), np.asarray(crba(model, s_q @ q))
        np.testing.assert_allclose(s_q.T @ m_s @ s_q, m, atol=1e-12 * np.abs(m).max())
        v, v_s = float(potential_energy(model, q)), float(potential_energy(model, s_q @ q))
        assert v_s == pytest.approx(v, rel=1e-12, abs=1e-12)
        c, c_s = (np.asarray(bias_forces(model, q, qd)),
                  np.asarray(bias_forces(model, s_q @ q, s_q @ qd)))
        np.testing.assert_allclose(s_q.T @ c_s, c, atol=1e-11 * np.abs(c).max())
        u = np.random.default_rng(5).normal(size=model.nu)
        tau = np.asarray(generalized_forces(model, q, u, held)).ravel()
        tau_s = np.asarray(generalized_forces(model, s_q @ q, s_u @ u, held)).ravel()
        np.testing.assert_allclose(s_q.T @ tau_s, tau, atol=1e-12)
        for a, b in contacts.items():
            np.testing.assert_allclose(np.asarray(contact_position(model, s_q @ q, a)).ravel(),
                                       np.asarray(contact_position(model, q, b)).ravel(),
                                       atol=1e-12)


def test_on_the_five_link_the_map_is_the_old_permutation() -> None:
    model = load_model("five-link")
    s_q, s_u = swap_matrices(model)
    # q = [x, y, torso, hip_1, knee_1, hip_2, knee_2]; u = [hip, knee, ankle] x 2
    np.testing.assert_array_equal(s_q, np.eye(7)[[0, 1, 2, 5, 6, 3, 4]])
    np.testing.assert_array_equal(s_u, np.eye(6)[[3, 4, 5, 0, 1, 2]])
    perm_q, perm_u = swap_permutations(model)
    assert leg_swap(model).perm_q == tuple(perm_q) == (0, 1, 2, 5, 6, 3, 4)
    assert leg_swap(model).perm_u == tuple(perm_u) == (3, 4, 5, 0, 1, 2)


def test_a_leg_welded_into_the_base_changes_the_base_angle() -> None:
    """Drake's kneed compass gait: q = [x, y, thigh_1 (the base), knee_1, hip, knee_2], hip
    = thigh 2 relative to thigh 1: base' = base + hip, hip' = -hip, knees exchanged; the hip
    actuator maps to itself with the sign flipped, the knee actuators exchange."""
    model = load_model(str(KCG))
    assert model_symmetry(model).links == (("thigh_1", "thigh_2"), ("shank_1", "shank_2"))
    s_q, s_u = swap_matrices(model)
    x, y, base, knee_1, hip, knee_2 = 0.1, 0.9, 0.3, -0.2, 0.5, -0.7
    np.testing.assert_array_equal(s_q @ [x, y, base, knee_1, hip, knee_2],
                                  [x, y, base + hip, knee_2, -hip, knee_1])
    np.testing.assert_array_equal(s_u, [[-1, 0, 0], [0, 0, 1], [0, 1, 0]])  # hip, knees
    assert leg_swap(model).actuator_source(0) == (0, -1.0)
    with pytest.raises(SymmetryError, match="no permutation"):
        swap_permutations(model)
    with pytest.raises(SymmetryError, match="no permutation"):
        _ = leg_swap(model).perm_q
    names = swap_names(model)
    assert names["knee_1"] == "knee_2" and names["hip"] == "hip" and names["tip_1"] == "tip_2"


def _kcg() -> dict[str, Any]:
    return copy.deepcopy(load_model(str(KCG)).to_dict())


def test_what_has_no_swap_is_refused_by_name() -> None:
    # Legs two links apart in length: nothing to pair.
    data = _kcg()
    data["links"].append({"name": "foot_2", "parent": "shank_2", "direction": "down",
                          "length": 0.1, "mass": 0.5, "inertia": 1e-3,
                          "joint": {"name": "ankle_2", "at": [0.5, 0.0],
                                    "limits": [-1.0, 1.0]}})
    data["contacts"][1]["link"], data["contacts"][1]["at"] = "foot_2", [0.1, 0.0]
    with pytest.raises(SymmetryError, match="not two separate chains of equal length"):
        model_symmetry(model_from_dict(data))
    # Thigh 2's hip away from the base's origin: the base cannot take its place.
    data = _kcg()
    data["links"][2]["joint"]["at"] = [0.05, 0.0]
    with pytest.raises(SymmetryError, match=r"pairs 'thigh_1' with 'thigh_2'.*joint at its "
                                            "origin"):
        swap_matrices(model_from_dict(data))
    # Leg 2 one link longer (a pylon below shank 2) on a torso: the chains look like a leg
    # welded into the base, but the torso points up and thigh 2 down: no swap (a stride
    # needs none: the contacts still pair).
    data = copy.deepcopy(load_model("five-link").to_dict())
    data["links"].append({"name": "pylon_2", "parent": "shank_2", "direction": "down",
                          "length": 0.05, "mass": 0.3, "inertia": 1e-4,
                          "joint": {"name": "pylon_joint_2", "at": [0.5, 0.0],
                                    "limits": [-0.3, 0.3]}})
    data["contacts"][1] = {"name": "tip_2", "link": "pylon_2", "at": [0.05, 0.0]}
    data["actuators"].append({"name": "pylon_2", "joint": "pylon_joint_2",
                              "limits": [-25.0, 25.0]})
    long_leg = model_from_dict(data)
    with pytest.raises(SymmetryError, match=r"pairs 'torso' with 'thigh_2', but they differ "
                                            "in shape"):
        swap_matrices(long_leg)
    assert contact_pairing(long_leg)["tip_1"] == "tip_2"
    # An actuator without a counterpart: only knee 1 is actuated.
    data = _kcg()
    data["actuators"] = [a for a in data["actuators"] if a["name"] != "knee_2"]
    with pytest.raises(SymmetryError, match="actuator 'knee_1' has no unique counterpart"):
        swap_matrices(model_from_dict(data))


def test_a_declared_welded_symmetry_names_the_base_and_gives_the_same_maps() -> None:
    data = _kcg()
    data["symmetry"] = {"links": [["thigh_1", "thigh_2"], ["shank_1", "shank_2"]],
                        "contacts": [["tip_1", "tip_2"]]}
    model = model_from_dict(data)
    assert model_symmetry(model).source == "declared"
    for mine, inferred in zip(swap_matrices(model), swap_matrices(load_model(str(KCG))),
                              strict=True):
        np.testing.assert_array_equal(mine, inferred)
    data["symmetry"]["links"] = [["thigh_1", "shank_2"], ["shank_1", "thigh_2"]]
    with pytest.raises(ModelError, match="symmetry"):
        model_from_dict(data)
