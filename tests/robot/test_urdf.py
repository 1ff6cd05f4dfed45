"""URDF import and export (``gaitopt.robot.urdf``, ``gaitopt model import|export``).

References that do not come from the code under test: numbers worked out by hand from the text
of ``data/walker.urdf`` (written by hand, not by our export), Pinocchio's own URDF parser, and
the built-in model itself (a round trip must give it back).
"""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gaitopt.cli import cli
from gaitopt.dynamics import aba, crba, rnea
from gaitopt.robot import ModelError, RobotModel, load_model, model_from_dict
from gaitopt.robot.urdf import ContactSpec, model_from_urdf, urdf_from_model

DATA = Path(__file__).parent / "data"
WALKER = DATA / "walker.urdf"
WALKER_CONTACTS = (ContactSpec("left_toe", "left_foot", (0.1, -0.05)),
                   ContactSpec("right_tip", "right_shank", (0.0, -0.4)))


def five_link() -> RobotModel:
    return load_model("five-link")


def random_states(model: RobotModel, n: int, seed: int) -> list[tuple[np.ndarray, ...]]:
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-1.0, 1.0, model.nq), rng.normal(size=model.nq),
             rng.normal(size=model.nq)) for _ in range(n)]


# -- round trip of the built-in model ----------------------------------------------------------

def test_five_link_round_trip_is_the_same_model() -> None:
    original = five_link()
    back = model_from_urdf(urdf_from_model(original))
    assert back == original  # masses, coms, inertias, limits, actuators, contacts, gravity...
    assert back.content_hash() == original.content_hash()
    assert [link.shape for link in back.links] == [link.shape for link in original.links]


def test_seven_link_round_trip_keeps_feet_and_the_declared_symmetry() -> None:
    """The model with feet: heel and toe frames, joint ankles, and the declared symmetry
    (in ``<gaitopt>`` as ``<swap>`` pairs) come back as they were."""
    original = load_model("seven-link")
    text = urdf_from_model(original)
    assert '<swap kind="contact" a="heel_1" b="heel_2"' in text
    back = model_from_urdf(text)
    assert back == original and back.symmetry == original.symmetry
    assert back.content_hash() == original.content_hash()


# names with characters XML must escape; contact names apart from link names (one namespace)
names = st.text(st.sampled_from("ab_1 <&\"'é"), min_size=1, max_size=6).filter(
    lambda s: s == s.strip() and s not in ("x", "y"))
finite = st.floats(-5.0, 5.0, allow_nan=False, allow_infinity=False)
positive = st.floats(1e-4, 1e2, allow_nan=False, allow_infinity=False)


@st.composite
def random_models(draw: st.DrawFn) -> RobotModel:
    """A random valid model: a tree of 1 to 6 links in any directions, points anywhere,
    contacts, actuators on joints and contacts with any bounds in any order, any gravity."""
    n = draw(st.integers(1, 6))
    k = draw(st.integers(0, 3))
    every = draw(st.lists(names, min_size=2 * n - 1 + k, max_size=2 * n - 1 + k, unique=True))
    link_names, joint_names, contact_names = every[:n], every[n:2 * n - 1], every[2 * n - 1:]

    def pair() -> list[float]:
        return [draw(finite), draw(finite)]

    def sorted_pair() -> list[float]:
        return sorted(pair())

    links = []
    for i, name in enumerate(link_names):
        link = {"name": name, "parent": None if i == 0 else link_names[draw(st.integers(0, i - 1))],
                "direction": draw(st.sampled_from(["up", "down"])), "length": draw(positive),
                "mass": draw(positive), "com": pair()}
        if i > 0:
            link["joint"] = {"name": joint_names[i - 1], "at": pair(), "limits": sorted_pair()}
        link.update(draw(st.sampled_from([{"inertia": draw(positive)}, {"shape": {"type": "rod"}},
                                          {"shape": {"type": "ellipsoid",
                                                     "radius": draw(positive)}}])))
        links.append(link)
    contacts = [{"name": c, "link": draw(st.sampled_from(link_names)), "at": pair()}
                for c in contact_names]
    targets = [("joint", j) for j in joint_names] + [("contact", c) for c in contact_names]
    chosen = draw(st.permutations(targets).flatmap(
        lambda ts: st.integers(0, len(ts)).map(lambda m: ts[:m])))
    actuators = [{"name": f"u{i}", kind: target, "limits": sorted_pair()}
                 for i, (kind, target) in enumerate(chosen)]
    return model_from_dict({"name": draw(names), "links": links, "contacts": contacts,
                            "actuators": actuators, "gravity": pair(),
                            "description": draw(st.text(st.sampled_from("ab <&\n\t"),
                                                        max_size=8))})


@settings(deadline=None, max_examples=60, suppress_health_check=[HealthCheck.too_slow])
@given(random_models())
def test_any_model_round_trips_exactly(model: RobotModel) -> None:
    assert model_from_urdf(urdf_from_model(model)) == model


def strip_gaitopt_element(text: str, contact_frames: bool = False) -> str:
    """``text`` without the ``<gaitopt>`` element (and the contact frames if asked)."""
    root = ET.fromstring(text)
    ext = root.find("gaitopt")
    assert ext is not None
    root.remove(ext)
    if contact_frames:
        for joint in root.findall("joint"):
            if (joint.get("name") or "").startswith("gaitopt_contact_"):
                child = joint.find("child")
                assert child is not None
                root.remove(joint)
                root.remove(next(e for e in root.findall("link")
                                 if e.get("name") == child.get("link")))
    return ET.tostring(root, encoding="unicode")


FIVE_LINK_TIPS = [ContactSpec("tip_1", "shank_1", (0.0, -0.5)),
                  ContactSpec("tip_2", "shank_2", (0.0, -0.5))]


@pytest.mark.parametrize("contact_frames", [False, True])
def test_without_the_gaitopt_element_only_what_urdf_cannot_hold_is_lost(
        contact_frames: bool) -> None:
    # The direction/length rule, the contact frames (or --contact) and the efforts alone give
    # back every link, joint and contact; lost: the ankle (ground) torques, the shapes (the
    # inertias stay), the description. Gravity is gaitopt's default anyway.
    original = five_link()
    text = strip_gaitopt_element(urdf_from_model(original), contact_frames)
    assert ("gaitopt_contact" in text) != contact_frames
    bare = model_from_urdf(text, contacts=FIVE_LINK_TIPS if contact_frames else ())
    assert bare.links == tuple(dataclasses.replace(link, shape=None) for link in original.links)
    assert bare.contacts == original.contacts
    assert bare.gravity == original.gravity
    assert bare.description == "" != original.description
    assert bare.actuators == tuple(a for a in original.actuators if a.contact is None)
    assert [a.name for a in original.actuators if a.contact is not None] == ["ankle_1", "ankle_2"]


def test_gaitopt_element_keeps_directions_and_lengths_the_rule_would_change() -> None:
    # shank_1 longer than its tip (0.6 m, tip at 0.5 m): the rule alone says 0.5
    original = five_link()
    links = list(original.links)
    links[2] = dataclasses.replace(links[2], length=0.6, shape=None)
    model = dataclasses.replace(original, links=tuple(links))
    text = urdf_from_model(model)
    assert model_from_urdf(text) == model
    assert model_from_urdf(strip_gaitopt_element(text)).links[2].length == 0.5


def test_export_writes_joint_axes_about_minus_y_and_contact_frames() -> None:
    root = ET.fromstring(urdf_from_model(five_link()))
    joints = {j.get("name"): j for j in root.findall("joint")}
    for name in ("hip_1", "knee_1", "hip_2", "knee_2"):
        axis = joints[name].find("axis")
        assert axis is not None and axis.get("xyz") == "0 -1 0"
    knee = joints["knee_1"]
    origin, limit = knee.find("origin"), knee.find("limit")
    assert origin is not None and limit is not None
    assert [float(v) for v in (origin.get("xyz") or "").split()] == [0.0, 0.0, -0.5]
    assert (limit.get("lower"), limit.get("upper"), limit.get("effort")) == ("-2.5", "0.0",
                                                                            "50.0")
    tip = joints["gaitopt_contact_tip_1"]
    assert tip.get("type") == "fixed"
    assert [e.get("link") for e in (tip.find("parent"), tip.find("child"))] == ["shank_1",
                                                                                 "tip_1"]
    tip_link = next(link for link in root.findall("link") if link.get("name") == "tip_1")
    assert tip_link.find("inertial") is None  # massless


# -- a URDF written another way: flipped axes, a split torso, a prismatic floating base -------

def rewritten_five_link() -> str:
    """The exported five-link URDF rewritten by hand: hip_1 and knee_1 about +y (their limits
    negated and swapped), the torso split into a 12 kg torso and an 8 kg head fixed to it in a
    frame pitched by 0.5 rad (combined: 20 kg, centre at 0.36 m, 0.576 kg m^2 about it), and
    a floating base of two prismatic joints and a revolute joint through massless links."""
    root = ET.fromstring(urdf_from_model(five_link()))
    for joint in root.findall("joint"):
        if joint.get("name") in ("hip_1", "knee_1"):
            axis, limit = joint.find("axis"), joint.find("limit")
            assert axis is not None and limit is not None
            axis.set("xyz", "0 1 0")
            lo, hi = float(limit.get("lower", "")), float(limit.get("upper", ""))
            limit.set("lower", repr(-hi))
            limit.set("upper", repr(-lo))
    torso = next(link for link in root.findall("link") if link.get("name") == "torso")
    torso.clear()
    torso.set("name", "torso")
    # 12 (0.36 - 0.3)^2 + 8 (0.45 - 0.36)^2 = 0.108, so 0.3 + 0.168 + 0.108 = 0.576
    torso.append(ET.fromstring('<inertial><origin xyz="0 0 0.3"/><mass value="12"/>'
                               '<inertia ixx="0.2" ixy="0" ixz="0" iyy="0.3" iyz="0" '
                               'izz="0.1"/></inertial>'))
    pitch = 0.5
    # head frame at z = 0.4, pitched: its centre at world z = 0.45 is R_y(pitch)^T (0, 0, 0.05)
    cx, cz = -0.05 * math.sin(pitch), 0.05 * math.cos(pitch)
    extra = [
        f'<link name="head"><inertial><origin xyz="{cx!r} 0 {cz!r}"/><mass value="8"/>'
        '<inertia ixx="0.05" ixy="0" ixz="0" iyy="0.168" iyz="0" izz="0.02"/></inertial></link>',
        f'<joint name="neck" type="fixed"><parent link="torso"/><child link="head"/>'
        f'<origin xyz="0 0 0.4" rpy="0 {pitch!r} 0"/></joint>',
        '<link name="world"/>', '<link name="slider_x"/>', '<link name="slider_z"/>',
        '<joint name="base_x" type="prismatic"><parent link="world"/><child link="slider_x"/>'
        '<axis xyz="1 0 0"/><limit lower="-9" upper="9" effort="0" velocity="1"/></joint>',
        '<joint name="base_z" type="prismatic"><parent link="slider_x"/>'
        '<child link="slider_z"/><origin xyz="0 0 1.2"/><axis xyz="0 0 1"/>'
        '<limit lower="-9" upper="9" effort="0" velocity="1"/></joint>',
        '<joint name="base_pitch" type="continuous"><parent link="slider_z"/>'
        '<child link="torso"/><axis xyz="0 1 0"/></joint>',
    ]
    for i, text in enumerate(extra):
        root.insert(i, ET.fromstring(text))
    return ET.tostring(root, encoding="unicode")


def test_rewritten_urdf_gives_the_same_model_up_to_rounding() -> None:
    original, imported = five_link(), model_from_urdf(rewritten_five_link())
    assert [link.name for link in imported.links] == [link.name for link in original.links]
    for a, b in zip(original.links, imported.links, strict=True):
        assert (a.parent, a.joint, a.direction, a.length, a.mass) == \
            (b.parent, b.joint, b.direction, b.length, b.mass)
        np.testing.assert_allclose(b.com, a.com, rtol=0, atol=1e-14)
        assert b.inertia == pytest.approx(a.inertia, rel=1e-13)
    assert (imported.contacts, imported.actuators, imported.gravity) == \
        (original.contacts, original.actuators, original.gravity)
    assert imported.links[0].shape == original.links[0].shape  # consistent: kept


def test_rewritten_urdf_gives_the_same_dynamics() -> None:
    original, imported = five_link(), model_from_urdf(rewritten_five_link())
    for q, qd, tau in random_states(original, 20, seed=3):
        np.testing.assert_allclose(np.asarray(crba(imported, q)), np.asarray(crba(original, q)),
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(np.asarray(aba(imported, q, qd, tau)),
                                   np.asarray(aba(original, q, qd, tau)), rtol=1e-10,
                                   atol=1e-10)


@pytest.mark.slow
def test_rewritten_urdf_gives_the_same_optimal_gait() -> None:
    from gaitopt.gait.api import solve_gait
    from gaitopt.gait.options.gait_options import GaitOptions

    original, imported = five_link(), model_from_urdf(rewritten_five_link())
    assert imported.content_hash() != original.content_hash()  # not a cached copy
    a = solve_gait(original, GaitOptions.paper(speed=0.2))
    b = solve_gait(imported, GaitOptions.paper(speed=0.2))
    assert a.success and b.success
    assert b.cost_value == pytest.approx(a.cost_value, rel=1e-6)
    assert b.step_length == pytest.approx(a.step_length, rel=1e-6)


# -- a hand-written URDF: every number worked out by hand from its text -----------------------

def test_hand_written_urdf_imports_with_the_expected_numbers() -> None:
    m = model_from_urdf(WALKER, contacts=WALKER_CONTACTS)
    assert [link.name for link in m.links] == ["pelvis", "left_thigh", "left_shank",
                                               "right_thigh", "right_shank"]
    assert m.coordinate_names == ("x", "y", "pelvis", "left_hip", "left_knee", "right_hip",
                                  "right_knee")
    pelvis, lthigh, lshank, rthigh, rshank = m.links
    # pelvis: centre at URDF (x, z) = (0.02, 0.15), above the hips: up, length 2 x 0.15;
    # inertia rotated by roll 0.4 about x: I_yy = cos^2 0.4 * 0.2 + sin^2 0.4 * 0.1
    assert (pelvis.direction, pelvis.length, pelvis.mass) == ("up", 0.3, 10.0)
    assert pelvis.com == pytest.approx((0.15, -0.02), abs=1e-15)
    assert pelvis.inertia == pytest.approx(math.cos(0.4) ** 2 * 0.2 + math.sin(0.4) ** 2 * 0.1,
                                           rel=1e-14)
    # left leg: axis +y, so gaitopt limits are the URDF ones negated and swapped
    assert lthigh.joint is not None and lshank.joint is not None
    assert lthigh.joint.limits == (-1.5, 1.0) and lshank.joint.limits == (-2.2, 0.0)
    assert lthigh.joint.at == (0.0, 0.0)  # the hip's y = 0.1 is out of the plane
    assert (lthigh.direction, lthigh.length, lthigh.mass, lthigh.com, lthigh.inertia) == \
        ("down", 0.4, 5.0, (0.2, 0.0), 0.08)
    # left shank: its frame is pitched by 0.2 about y; the foot (0.5 kg) is fixed to it
    c, s = math.cos(0.2), math.sin(0.2)
    shank_com = np.array([-0.2 * s, -0.2 * c])            # gaitopt (x, y), thigh-parallel
    foot_com = np.array([-0.4 * s + 0.05 * c - 0.02 * s, -0.4 * c - 0.05 * s - 0.02 * c])
    com = (3.0 * shank_com + 0.5 * foot_com) / 3.5
    inertia = (0.05 + 0.002 + 3.0 * np.sum((shank_com - com) ** 2)
               + 0.5 * np.sum((foot_com - com) ** 2))
    toe = np.array([-0.4 * s + 0.1 * c - 0.05 * s, -0.4 * c - 0.1 * s - 0.05 * c])
    assert lshank.mass == 3.5 and lshank.direction == "down"
    assert lshank.com == pytest.approx((-com[1], com[0]), abs=1e-15)  # (along, across), down
    assert lshank.inertia == pytest.approx(inertia, rel=1e-14)
    assert lshank.length == pytest.approx(-toe[1], rel=1e-15)  # down to its lowest point
    assert m.contact("left_toe").link == "left_shank"
    assert m.contact("left_toe").at == pytest.approx((-toe[1], toe[0]), abs=1e-15)
    # right leg: axis -y, no flip; a continuous knee is unbounded and has no actuator
    assert rthigh.joint is not None and rshank.joint is not None
    assert rthigh.joint.limits == (-1.0, 1.5)
    assert rshank.joint.limits == (-math.inf, math.inf)
    assert (rshank.mass, rshank.inertia, rshank.length) == (3.0, 0.05, 0.4)
    assert rshank.com == pytest.approx((0.2, 0.0), abs=1e-15)
    assert m.contact("right_tip").at == (0.4, 0.0)
    assert [(a.name, a.joint, a.limits) for a in m.actuators] == [
        ("left_hip", "left_hip", (-80.0, 80.0)), ("left_knee", "left_knee", (-60.0, 60.0)),
        ("right_hip", "right_hip", (-80.0, 80.0))]
    assert m.total_mass == 26.5 and m.gravity == (0.0, -9.81) and m.name == "walker"


BASES = {
    "prismatic": (
        '<link name="world"/><link name="sx"/><link name="sz"/>'
        '<joint name="px" type="prismatic"><parent link="world"/><child link="sx"/>'
        '<origin xyz="0.3 0 0.1"/><axis xyz="1 0 0"/>'
        '<limit lower="-5" upper="5" effort="0" velocity="1"/></joint>'
        '<joint name="pz" type="prismatic"><parent link="sx"/><child link="sz"/>'
        '<axis xyz="0 0 -1"/><limit lower="-5" upper="5" effort="0" velocity="1"/></joint>'
        '<joint name="ry" type="continuous"><parent link="sz"/><child link="pelvis"/>'
        '<origin xyz="0 0 1"/><axis xyz="0 1 0"/></joint>'),
    "planar": ('<link name="world"/><joint name="base" type="planar"><parent link="world"/>'
               '<child link="pelvis"/><origin xyz="0 0 1"/><axis xyz="0 -1 0"/></joint>'),
    "floating": ('<link name="world"/><joint name="base" type="floating">'
                 '<parent link="world"/><child link="pelvis"/></joint>'),
}


def walker_with_base(kind: str) -> str:
    text = WALKER.read_text()
    marker = '<robot name="walker">'
    assert marker in text
    return text.replace(marker, marker + BASES[kind])


@pytest.mark.parametrize("kind", sorted(BASES))
def test_floating_base_variants_give_the_same_model_and_dynamics(kind: str) -> None:
    reference = model_from_urdf(WALKER, contacts=WALKER_CONTACTS)
    m = model_from_urdf(walker_with_base(kind), contacts=WALKER_CONTACTS)
    assert m == reference
    for q, qd, tau in random_states(m, 5, seed=4):
        np.testing.assert_array_equal(np.asarray(crba(m, q)), np.asarray(crba(reference, q)))
        np.testing.assert_array_equal(np.asarray(aba(m, q, qd, tau)),
                                      np.asarray(aba(reference, q, qd, tau)))


# -- Pinocchio's URDF parser as the reference ---------------------------------------------------

def pinocchio_reference(urdf: str, model: RobotModel) -> tuple[object, object, object]:
    """Pinocchio's model of the URDF with a planar root (x, z, rotation about y), and the maps
    between our (q, v) and Pinocchio's: q_pin(q) and S with v_pin = S v."""
    pin = pytest.importorskip("pinocchio")
    root = pin.JointModelComposite()
    for joint in (pin.JointModelPX(), pin.JointModelPZ(), pin.JointModelRY()):
        root.addJoint(joint)
    pm = pin.buildModelFromXML(urdf, root)
    # joint signs from the URDF text: an axis along +y turns the other way than gaitopt's z
    axis_y = {j.get("name"): float((j.find("axis").get("xyz") or "").split()[1])
              for j in ET.fromstring(urdf).findall("joint") if j.find("axis") is not None}
    s = np.zeros((pm.nv, model.nq))
    s[0, 0], s[1, 1], s[2, 2] = 1.0, 1.0, -1.0  # base: x, z, rotation about y = -angle
    slots = []
    for i, name in enumerate(model.coordinate_names[3:], start=3):
        jm = pm.joints[pm.getJointId(name)]
        sign = -axis_y[name]
        s[jm.idx_v, i] = sign
        slots.append((jm.idx_q, jm.nq, i, sign))

    def q_pin(q: np.ndarray) -> np.ndarray:
        out = np.zeros(pm.nq)
        out[:3] = q[0], q[1], -q[2]
        for idx, nq, i, sign in slots:
            if nq == 2:  # a continuous joint: (cos, sin)
                out[idx:idx + 2] = math.cos(sign * q[i]), math.sin(sign * q[i])
            else:
                out[idx] = sign * q[i]
        return out

    return pm, q_pin, s


@pytest.mark.parametrize("which", ["five-link export", "hand-written walker"])
def test_pinocchio_mass_matrix_and_gravity_match(which: str) -> None:
    pin = pytest.importorskip("pinocchio")
    if which == "five-link export":
        model = five_link()
        urdf = urdf_from_model(model)
    else:
        urdf = WALKER.read_text()
        model = model_from_urdf(urdf, contacts=WALKER_CONTACTS)
    pm, q_pin, s = pinocchio_reference(urdf, model)
    pd = pm.createData()
    for q, _, _ in random_states(model, 10, seed=5):
        qp = q_pin(q)
        m_pin = pin.crba(pm, pd, qp)
        m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T
        np.testing.assert_allclose(np.asarray(crba(model, q)), s.T @ m_pin @ s,
                                   rtol=1e-10, atol=1e-10)
        g_pin = pin.computeGeneralizedGravity(pm, pd, qp)
        zero = np.zeros(model.nq)
        np.testing.assert_allclose(np.asarray(rnea(model, q, zero, zero)).ravel(),
                                   s.T @ g_pin, rtol=1e-10, atol=1e-9)


@settings(deadline=None, max_examples=25, suppress_health_check=[HealthCheck.too_slow])
@given(random_models())
def test_pinocchio_agrees_on_the_export_of_any_model(model: RobotModel) -> None:
    pin = pytest.importorskip("pinocchio")
    pm, q_pin, s = pinocchio_reference(urdf_from_model(model), model)
    pd = pm.createData()
    for q, _, _ in random_states(model, 3, seed=6):
        m_pin = pin.crba(pm, pd, q_pin(q))
        m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T
        np.testing.assert_allclose(np.asarray(crba(model, q)), s.T @ m_pin @ s,
                                   rtol=1e-9, atol=1e-9)


# -- refusals ------------------------------------------------------------------------------------

def edit_walker(old: str, new: str) -> str:
    text = WALKER.read_text()
    assert text.count(old) == 1
    return text.replace(old, new)


REFUSALS = {
    "joint about x": (edit_walker('<axis xyz="0 1 0"/>\n    <limit lower="-1.0"',
                                  '<axis xyz="1 0 0"/>\n    <limit lower="-1.0"'),
                      "joint 'left_hip' axis", "an axis along +-y"),
    "closed loop": (edit_walker("</robot>", '<joint name="loop" type="fixed"><parent '
                                'link="right_shank"/><child link="left_foot"/></joint></robot>'),
                    "joint 'loop'", "already has parent joint 'left_ankle_mount'"),
    "cycle": (edit_walker("</robot>", '<joint name="up" type="fixed"><parent link="imu"/>'
                          '<child link="pelvis"/></joint></robot>'),
              "closed loop of links", "pelvis -> imu -> pelvis (joints imu_mount, up)"),
    "mimic": (edit_walker('<axis xyz="0 -1 0"/>\n    <limit', '<axis xyz="0 -1 0"/><mimic '
                          'joint="left_hip"/>\n    <limit'), "joint 'right_hip'", "mimic"),
    "no inertia": (edit_walker('<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" '
                               'izz="0.002"/>', ""), "link 'left_foot'", "no <inertia>"),
    "no ixx": (edit_walker('<inertia ixx="0.001" ixy="0"', '<inertia ixy="0"'),
               "link 'left_foot' inertia ixx", "missing"),
    "no joint limit": (edit_walker('<limit lower="0" upper="2.2" effort="60" velocity="10"/>',
                                   ""), "joint 'left_knee' <limit>", "missing"),
    "tilted prismatic base": (walker_with_base("prismatic").replace(
        '<axis xyz="1 0 0"/>', '<axis xyz="1 0 1"/>'), "joint 'px'", "floating-base chain"),
    "prismatic knee": (edit_walker('name="right_knee" type="continuous"',
                                   'name="right_knee" type="prismatic"'),
                       "joint 'right_knee'", "prismatic joint outside the floating-base"),
    "one prismatic base": (walker_with_base("prismatic").replace('<joint name="pz" type='
                                                                 '"prismatic"',
                                                                 '<joint name="pz" type="fixed"'),
                           "joint 'px'", "floating-base chain"),
}


@pytest.mark.parametrize("case", sorted(REFUSALS))
def test_refusals_name_the_joint_or_link(case: str) -> None:
    text, where, why = REFUSALS[case]
    with pytest.raises(ModelError) as info:
        model_from_urdf(text)
    message = str(info.value)
    assert len(message.splitlines()) == 1
    assert where in message and why in message, message


@pytest.mark.parametrize(("text", "message"), [
    ('<robot name="r"/>', "<string>: no links; allowed: a <robot> with <link> elements"),
    ("<robot", "<string>: not valid XML"),
    ('<urdf name="r"/>', "<string>: the root element is <urdf>"),
    ('<robot name="r"><link name="a"/><link name="b"/></robot>',
     "<string>: 2 links without a parent"),
    ('<robot name="r"><link name="a"><inertial><mass value="-1"/></inertial></link></robot>',
     "<string>: link 'a' mass: got -1.0; allowed: a mass >= 0 (kg)"),
])
def test_malformed_urdf_gives_one_line(text: str, message: str) -> None:
    with pytest.raises(ModelError) as info:
        model_from_urdf(text)
    assert str(info.value).startswith(message) and "\n" not in str(info.value), info.value


def test_missing_file_is_a_model_error(tmp_path: Path) -> None:
    with pytest.raises(ModelError, match="none.urdf: cannot be read"):
        model_from_urdf(tmp_path / "none.urdf")


def test_unknown_contact_link_is_refused() -> None:
    with pytest.raises(ModelError, match=r"contact 'heel'.*no link 'calf'"):
        model_from_urdf(WALKER, contacts=[ContactSpec("heel", "calf", (0.0, 0.0))])


def test_contacts_on_exported_frames_and_flags_may_not_share_a_name() -> None:
    with pytest.raises(ModelError, match="contact 'tip_1'.*duplicate"):
        model_from_urdf(urdf_from_model(five_link()),
                        contacts=[ContactSpec("tip_1", "shank_1", (0.0, -0.4))])


def test_axis_x_reads_a_robot_in_the_y_z_plane() -> None:
    # the walker turned by -90 degrees about z: a vector (x, y, z) becomes (y, -x, z), so the
    # plane is y-z and the joints turn about x; with axis x it is the same model
    root = ET.fromstring(WALKER.read_text())
    for elem in root.iter():
        if elem.tag in ("origin", "axis") and elem.get("xyz"):
            x, y, z = (float(v) for v in (elem.get("xyz") or "").split())
            elem.set("xyz", f"{y!r} {-x!r} {z!r}")
        if elem.tag == "origin" and elem.get("rpy"):  # only roll or pitch in this file
            r, p, yaw = (float(v) for v in (elem.get("rpy") or "").split())
            assert yaw == 0.0 and r * p == 0.0
            elem.set("rpy", f"{p!r} {-r!r} 0")  # about x -> about -y; about y -> about x
        if elem.tag == "inertia":
            ixx, iyy = elem.get("ixx") or "", elem.get("iyy") or ""
            elem.set("ixx", iyy)
            elem.set("iyy", ixx)
    turned = ET.tostring(root, encoding="unicode")
    contacts = [ContactSpec(c.name, c.link, (-c.point[0], c.point[1])) for c in WALKER_CONTACTS]
    reference = model_from_urdf(WALKER, contacts=WALKER_CONTACTS)
    m = model_from_urdf(turned, axis="x", contacts=contacts)
    assert [link.name for link in m.links] == [link.name for link in reference.links]
    for a, b in zip(reference.links, m.links, strict=True):
        assert (a.joint, a.direction, a.mass) == (b.joint, b.direction, b.mass)
        assert b.length == pytest.approx(a.length, rel=1e-12)
        np.testing.assert_allclose(b.com, a.com, atol=1e-12)
        assert b.inertia == pytest.approx(a.inertia, rel=1e-12)
    with pytest.raises(ModelError, match="joint 'left_hip' axis"):
        model_from_urdf(turned)  # read with the default axis y: joints about x are refused


# -- the command line ------------------------------------------------------------------------------

@pytest.fixture
def runner() -> CliRunner:
    return CliRunner(env={"COLUMNS": None})


def test_cli_export_urdf_and_import_it_back(runner: CliRunner, tmp_path: Path) -> None:
    urdf, yaml = tmp_path / "fl.urdf", tmp_path / "fl.yaml"
    result = runner.invoke(cli, ["model", "export", "five-link", "--format", "urdf", "-o",
                                 str(urdf)])
    assert result.exit_code == 0, result.output
    assert urdf.read_text() == urdf_from_model(five_link())
    result = runner.invoke(cli, ["model", "import", str(urdf), "-o", str(yaml)])
    assert result.exit_code == 0, result.output
    assert load_model(yaml) == five_link()
    assert "5 links, 2 contact points, 6 actuators, total mass 42 kg" in result.stdout
    # an existing file is kept without --force
    result = runner.invoke(cli, ["model", "import", str(urdf), "-o", str(yaml)])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [f"Error: {yaml} exists; pass --force to overwrite it"]
    assert runner.invoke(cli, ["model", "import", str(urdf), "-o", str(yaml),
                               "--force"]).exit_code == 0
    # a model file exports too (YAML by default, as before)
    result = runner.invoke(cli, ["model", "export", str(yaml), "-o", "-"])
    assert result.exit_code == 0 and "name: five-link" in result.stdout


def test_cli_import_with_contacts(runner: CliRunner, tmp_path: Path) -> None:
    out = tmp_path / "walker.yaml"
    result = runner.invoke(cli, ["model", "import", str(WALKER), "-o", str(out),
                                 "--contact", "left_toe=left_foot:0.1,-0.05",
                                 "--contact", "right_tip=right_shank:0,-0.4",
                                 "--name", "my-walker"])
    assert result.exit_code == 0, result.output
    expected = dataclasses.replace(model_from_urdf(WALKER, contacts=WALKER_CONTACTS),
                                   name="my-walker")
    assert load_model(out) == expected


@pytest.mark.parametrize(("args", "message"), [
    (["--contact", "tip=shank"], "Error: --contact: got 'tip=shank'; allowed: NAME=LINK:X,Z"),
    (["--contact", "tip=right_shank:0,-0.4,1"], "Error: --contact: got"),
    (["--contact", "tip=calf:0,0"], "contact 'tip': no link 'calf'"),
])
def test_cli_import_errors_exit_2_with_one_line(runner: CliRunner, tmp_path: Path,
                                                args: list[str], message: str) -> None:
    out = tmp_path / "w.yaml"
    result = runner.invoke(cli, ["model", "import", str(WALKER), "-o", str(out), *args])
    assert result.exit_code == 2
    assert len(result.stderr.splitlines()) == 1 and message in result.stderr, result.stderr
    assert "Traceback" not in result.output and not out.exists()


def test_cli_import_refuses_a_joint_about_x(runner: CliRunner, tmp_path: Path) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text(REFUSALS["joint about x"][0])
    result = runner.invoke(cli, ["model", "import", str(bad), "-o", str(tmp_path / "b.yaml")])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"Error: {bad}: joint 'left_hip' axis: got '1 0 0'")
    assert len(result.stderr.splitlines()) == 1
