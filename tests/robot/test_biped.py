"""The biped boundary (:mod:`gaitopt.robot.biped`): legs, stance and swing, the leg swap and
the base coordinates of a model, checked against the model's own names and coordinates."""

from __future__ import annotations

import numpy as np
import pytest

from gaitopt.robot import load_model, model_from_dict
from gaitopt.robot.biped import BipedStructureError, biped_of, has_reduced_shape, reduced_biped
from gaitopt.robot.model import BASE_COORDINATES, RobotModel
from gaitopt.robot.symmetry import leg_swap, swap_maps, swap_permutations


def _biped_with_an_arm() -> RobotModel:
    """The five-link biped with a sixth link on the torso: still two thigh-shank legs, but
    not the shape of the reduced coordinates."""
    data = load_model("five-link").to_dict()
    data["name"] = "six-link-arm"
    data["links"].append({
        "name": "arm", "parent": "torso", "direction": "down", "length": 0.6, "mass": 4.0,
        "com": [0.3, 0.0], "inertia": 0.12,
        "joint": {"name": "shoulder", "at": [0.72, 0.0], "limits": [-1.5, 1.5]}})
    return model_from_dict(data)


def test_stance_swing_and_contacts_follow_the_model_order() -> None:
    model = load_model("five-link")
    biped = biped_of(model)
    first, second = (c.name for c in model.contacts)
    assert biped.stance.contact == first and biped.swing.contact == second
    assert biped.contacts == (first, second)
    assert biped.legs == (biped.stance, biped.swing)
    assert [biped.other(i) for i in (0, 1)] == [1, 0]
    # each leg's joints are the joints of the links that carry its contact point
    for leg in biped.legs:
        shank = model.link(model.contact(leg.contact).link)
        assert shank.joint is not None and leg.knee == shank.joint.name
        assert model.coordinate_names[leg.knee_index] == leg.knee
        assert model.coordinate_names[leg.hip_index] == leg.hip


def test_the_base_coordinates_are_where_the_model_names_them() -> None:
    model = load_model("five-link")
    biped = biped_of(model)
    names = model.coordinate_names
    assert names[biped.base_position] == BASE_COORDINATES[:2]
    assert names[biped.base_angle] == model.base.name  # the base's angle is named after it


def test_the_leg_swap_exchanges_the_legs_and_keeps_the_base() -> None:
    model = load_model("five-link")
    biped = biped_of(model)
    assert biped.swap is leg_swap(model)
    perm_q, perm_u = swap_permutations(model)
    assert biped.swap.perm_q == tuple(perm_q) and biped.swap.perm_u == tuple(perm_u)
    assert dict(biped.swap.contacts) == swap_maps(model)[1]
    q = np.arange(model.nq, dtype=float)
    swapped = q[list(biped.swap.perm_q)]
    stance, swing = biped.legs
    assert swapped[stance.hip_index] == q[swing.hip_index]
    assert swapped[swing.knee_index] == q[stance.knee_index]
    assert np.array_equal(swapped[biped.base_position], q[biped.base_position])
    assert swapped[biped.base_angle] == q[biped.base_angle]
    assert np.array_equal(swapped[list(biped.swap.perm_q)], q)  # an involution
    assert biped.swap.contacts[stance.contact] == swing.contact


def test_an_extra_link_keeps_the_legs_but_not_the_reduced_shape() -> None:
    five, arm = load_model("five-link"), _biped_with_an_arm()
    assert biped_of(five).reduced and has_reduced_shape(five)
    assert reduced_biped(five) is biped_of(five)
    biped = biped_of(arm)
    assert not biped.reduced and not has_reduced_shape(arm)
    assert biped.legs == biped_of(five).legs  # same legs, same coordinates
    with pytest.raises(BipedStructureError, match=r"6 links.*\(5 links, 7 coordinates\)"):
        reduced_biped(arm)
