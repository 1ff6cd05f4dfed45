"""The built-in five-link model holds the paper's Table 1 and the project's conventions."""

from __future__ import annotations

import math

import pytest

from gaitopt.robot import RobotModel, Shape, builtin_names, load_model

# Paper, Table 1 (mass kg, length m, radius m), typed in from the paper independently of the
# model file.
TABLE_1 = {"torso": (20.0, 0.72, 0.12), "thigh": (7.0, 0.50, 0.07), "shank": (4.0, 0.50, 0.05)}


def kind(link_name: str) -> str:
    return link_name.split("_")[0]


@pytest.fixture(scope="module")
def five_link() -> RobotModel:
    return load_model("five-link")


def test_five_link_is_listed() -> None:
    assert "five-link" in builtin_names()


def test_masses_lengths_and_total_mass_match_table_1(five_link: RobotModel) -> None:
    assert [link.name for link in five_link.links] == [
        "torso", "thigh_1", "shank_1", "thigh_2", "shank_2"]
    for link in five_link.links:
        mass, length, radius = TABLE_1[kind(link.name)]
        assert link.mass == mass
        assert link.length == length
        assert link.shape == Shape(type="ellipsoid", radius=radius)
    assert five_link.total_mass == pytest.approx(42.0, abs=1e-12)


def test_inertia_is_ellipsoid_about_normal_axis(five_link: RobotModel) -> None:
    # Semi-axes a = L/2 (along the link), b = c = r; about the axis normal to the plane
    # (perpendicular to a and b): I = m (a^2 + b^2) / 5.
    expected = {"torso": 20.0 * (0.36**2 + 0.12**2) / 5,      # 0.576
                "thigh": 7.0 * (0.25**2 + 0.07**2) / 5,       # 0.09436
                "shank": 4.0 * (0.25**2 + 0.05**2) / 5}       # 0.052
    assert expected["torso"] == pytest.approx(0.576)
    assert expected["thigh"] == pytest.approx(0.09436)
    assert expected["shank"] == pytest.approx(0.052)
    for link in five_link.links:
        assert link.inertia == pytest.approx(expected[kind(link.name)], rel=1e-14)


def test_centres_of_mass_at_link_centres(five_link: RobotModel) -> None:
    for link in five_link.links:
        assert link.com == (link.length / 2, 0.0)
    # The torso points up from the hip, the legs down from their proximal joints.
    assert five_link.link("torso").com_local == pytest.approx((0.0, 0.36))
    assert five_link.link("thigh_1").com_local == pytest.approx((0.0, -0.25))


def test_joints_hips_at_torso_lower_end_knees_at_thigh_ends(five_link: RobotModel) -> None:
    torso = five_link.base
    assert torso.name == "torso" and torso.parent is None and torso.joint is None
    assert torso.direction == "up"
    for leg in ("1", "2"):
        thigh, shank = five_link.link(f"thigh_{leg}"), five_link.link(f"shank_{leg}")
        assert thigh.parent == "torso" and shank.parent == f"thigh_{leg}"
        assert thigh.joint is not None and shank.joint is not None
        assert thigh.joint.name == f"hip_{leg}" and thigh.joint.at == (0.0, 0.0)
        assert shank.joint.name == f"knee_{leg}" and shank.joint.at == (thigh.length, 0.0)
        assert thigh.direction == shank.direction == "down"
        # A knee never bends backwards: flexion is negative, straight is 0.
        assert shank.joint.limits[1] == 0.0 and shank.joint.limits[0] < -math.pi / 2
        lo, hi = thigh.joint.limits
        assert lo < 0.0 < hi


def test_contacts_are_the_shank_tips(five_link: RobotModel) -> None:
    assert [(c.name, c.link, c.at) for c in five_link.contacts] == [
        ("tip_1", "shank_1", (0.5, 0.0)), ("tip_2", "shank_2", (0.5, 0.0))]


def test_coordinate_and_control_order_follow_design(five_link: RobotModel) -> None:
    assert five_link.coordinate_names == (
        "x", "y", "torso", "hip_1", "knee_1", "hip_2", "knee_2")
    assert five_link.nq == 7 and five_link.nu == 6
    assert [a.name for a in five_link.actuators] == [
        "hip_1", "knee_1", "ankle_1", "hip_2", "knee_2", "ankle_2"]
    assert five_link.gravity == (0.0, -9.81)


def test_default_torque_bounds_ankles_half_of_hips_and_knees(five_link: RobotModel) -> None:
    bounds = {a.name: a.limits for a in five_link.actuators}
    for leg in ("1", "2"):
        assert bounds[f"hip_{leg}"] == bounds[f"knee_{leg}"] == (-50.0, 50.0)
        assert bounds[f"ankle_{leg}"] == (-25.0, 25.0)
        ankle = five_link.actuators[five_link.actuator_index(f"ankle_{leg}")]
        assert ankle.kind == "contact" and ankle.contact == f"tip_{leg}"


def test_model_is_immutable_and_hashable(five_link: RobotModel) -> None:
    assert hash(five_link) == hash(load_model("five-link"))
    assert five_link == load_model("five-link")
    with pytest.raises(AttributeError):
        five_link.links[0].mass = 1.0  # type: ignore[misc]
