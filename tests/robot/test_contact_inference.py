"""Contact points inferred from collision shapes (``gaitopt.robot.contact_inference``).

References: the built-in models' own contact points (``five-link``'s tips, ``seven-link``'s
heels and toes, written by hand in their files) and points worked out by hand below.
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from gaitopt.robot import ModelError, RobotModel, load_model
from gaitopt.robot.contact_inference import (
    Capsule,
    Circle,
    Rectangle,
    Shape,
    infer_contacts,
    shape_points,
)
from gaitopt.robot.model import Contact


def bare(name: str) -> RobotModel:
    """A built-in model without its contact points (and their ground actuators)."""
    m = load_model(name)
    return dataclasses.replace(m, contacts=(), symmetry=None,
                               actuators=tuple(a for a in m.actuators if a.joint is not None))


def approx_contacts(got: tuple[Contact, ...], want: tuple[Contact, ...]) -> None:
    assert [(c.name, c.link) for c in got] == [(c.name, c.link) for c in want]
    for g, w in zip(got, want, strict=True):
        assert g.at == pytest.approx(w.at, abs=1e-12)


def test_spheres_of_radius_zero_at_the_shank_ends_give_five_links_tips() -> None:
    # a shank points down 0.5 m: its far end is (0, -0.5) in its frame at the zero pose
    shapes = [Circle(f"shank_{i}", (0.0, -0.5), 0.0) for i in (2, 1)]  # any order
    got = infer_contacts(bare("five-link"), shapes)
    assert got.contacts == load_model("five-link").contacts  # tip_1, tip_2 at [0.5, 0]
    assert "tip_1 at (0, -0.5) m in link 'shank_1'" in got.lines()[0]
    assert "sphere r=0" in got.lines()[0]


def test_a_sphere_gives_its_lowest_point() -> None:
    got = infer_contacts(bare("five-link"), [Circle("shank_1", (0.02, -0.45), 0.05)])
    (tip,) = got.contacts
    assert (tip.name, tip.link) == ("tip_1", "shank_1")
    assert tip.at == pytest.approx((0.5, 0.02), abs=1e-15)  # [along, across] of a down link


def seven_link_sole() -> tuple[tuple[float, float], tuple[float, float]]:
    """The heel and toe of seven-link's foot_1 as (x, y) in the foot frame (down link:
    (x, y) = (across, -along))."""
    m = load_model("seven-link")
    heel, toe = m.contact("heel_1").at, m.contact("toe_1").at
    return (heel[1], -heel[0]), (toe[1], -toe[0])


def test_a_box_foot_gives_seven_links_heels_and_toes() -> None:
    (hx, hy), (tx, ty) = seven_link_sole()
    assert hy == ty
    thickness = 0.02
    box = [Rectangle(f"foot_{i}", ((hx + tx) / 2, hy + thickness / 2),
                     ((tx - hx) / 2, thickness / 2), 0.0) for i in (1, 2)]
    got = infer_contacts(bare("seven-link"), box)
    approx_contacts(got.contacts, load_model("seven-link").contacts)  # heel_1, toe_1, ...
    # the same box turned a quarter turn, its half sizes exchanged
    turned = [dataclasses.replace(b, half_size=b.half_size[::-1], angle=math.pi / 2)
              for b in box]
    approx_contacts(infer_contacts(bare("seven-link"), turned).contacts,
                    load_model("seven-link").contacts)
    assert "heel_1 at" in got.lines()[0] and "toe_1 at" in got.lines()[0]


def test_a_lying_capsule_and_a_lying_cylinder_give_heel_and_toe() -> None:
    (hx, hy), (tx, _) = seven_link_sole()
    r = 0.015
    capsule = [Capsule(f"foot_{i}", ((hx, hy + r), (tx, hy + r)), r) for i in (1, 2)]
    approx_contacts(infer_contacts(bare("seven-link"), capsule).contacts,
                    load_model("seven-link").contacts)


def test_a_sloped_capsule_gives_the_ends_of_its_lower_edge() -> None:
    # axis from (0, 0) to (0.2, 0.02); the unit normal pointing down is (0.1, -1)/sqrt(1.01)
    r = 0.01
    heel, toe = shape_points(Capsule("foot", ((0.2, 0.02), (0.0, 0.0)), r))
    n = (0.1 / math.sqrt(1.01), -1.0 / math.sqrt(1.01))
    assert heel == pytest.approx((r * n[0], r * n[1]), abs=1e-15)
    assert toe == pytest.approx((0.2 + r * n[0], 0.02 + r * n[1]), abs=1e-15)


def test_upright_shapes_on_a_leaf_give_one_point() -> None:
    # a shank-like capsule and box standing up: the lowest point, the middle of the bottom
    assert shape_points(Capsule("s", ((0.0, -0.1), (0.01, -0.45)), 0.03)) == (
        (0.01, -0.48),)
    assert shape_points(Rectangle("s", (0.0, -0.25), (0.03, 0.25), 0.0)) == ((0.0, -0.5),)
    # a quarter turn: the first half size now vertical
    (p,) = shape_points(Rectangle("s", (0.0, -0.25), (0.25, 0.03), math.pi / 2))
    assert p == pytest.approx((0.0, -0.5), abs=1e-15)


def test_a_turned_box_gives_its_bottom_side_or_its_lowest_corner() -> None:
    (p,) = shape_points(Rectangle("f", (0.0, 0.0), (0.1, 0.1), math.pi / 4))
    assert p == pytest.approx((0.0, -0.1 * math.sqrt(2.0)), abs=1e-15)
    # turned 0.3 rad: the bottom side is still the long one; its ends (not level) are the
    # heel -u hx - v hy and the toe +u hx - v hy, u = (cos .3, sin .3), v = (-sin .3, cos .3)
    heel, toe = shape_points(Rectangle("f", (0.0, 0.0), (0.2, 0.05), 0.3))
    c, s = math.cos(0.3), math.sin(0.3)
    assert heel == pytest.approx((-0.2 * c + 0.05 * s, -0.2 * s - 0.05 * c), abs=1e-15)
    assert toe == pytest.approx((0.2 * c + 0.05 * s, 0.2 * s - 0.05 * c), abs=1e-15)


def test_several_shapes_on_a_leaf_only_the_lowest_count() -> None:
    m = bare("five-link")
    # a heel and a toe sphere, and a higher sphere that does not touch the ground
    shapes: list[Shape] = [Circle("shank_1", (-0.03, -0.48), 0.02),
                           Circle("shank_1", (0.1, -0.48), 0.02),
                           Circle("shank_1", (0.05, -0.3), 0.02)]
    got = infer_contacts(m, shapes)
    assert [(c.name, c.at) for c in got.contacts] == [
        ("heel_1", pytest.approx((0.5, -0.03))), ("toe_1", pytest.approx((0.5, 0.1)))]
    assert "(0.05, -0.3)" not in got.lines()[0]


def test_shapes_on_links_that_are_not_leaves_are_skipped() -> None:
    shapes: list[Shape] = [Capsule("thigh_1", ((0.0, 0.0), (0.0, -0.5)), 0.05),
                           Circle("torso", (0.0, 0.5), 0.1),
                           Circle("shank_1", (0.0, -0.5), 0.0)]
    got = infer_contacts(bare("five-link"), shapes)
    assert [c.name for c in got.contacts] == ["tip_1"]
    assert got.lines()[-1].endswith("not feet: thigh_1, torso")


def test_no_shape_on_a_leaf_infers_nothing() -> None:
    got = infer_contacts(bare("five-link"), [Circle("torso", (0.0, 0.5), 0.1)])
    assert got.contacts == ()
    assert got.lines()[0] == "no collision shape on a leaf link"


@pytest.mark.parametrize(("shape", "message"), [
    (Circle("calf", (0.0, 0.0), 0.1), "link 'calf' circle: no link 'calf'; allowed: a "
                                       "collision shape on a link of the model"),
    (Circle("shank_1", (0.0, 0.0), -0.1), "link 'shank_1' circle: got 'sphere r=-0.1 at "
                                           "(0, 0)'; allowed: a radius and half sizes >= 0"),
    (Capsule("shank_1", ((0.0, math.nan), (0.0, 0.0)), 0.1), "link 'shank_1' capsule: got "
                                                             "'capsule r=0.1 from (0, nan)"),
    (Rectangle("shank_1", (0.0, 0.0), (0.1, -0.01), 0.0), "link 'shank_1' rectangle: got "
                                                          "'box 0.2 x -0.02"),
])
def test_unusable_shapes_are_refused_in_one_line(shape: Shape, message: str) -> None:
    with pytest.raises(ModelError) as info:
        infer_contacts(bare("five-link"), [shape], source="robot.urdf")
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith("robot.urdf: " + message)
