"""URDF files written elsewhere: infinite limits, point masses, transmissions, contacts
inferred from collision shapes, and what ``gaitopt model import`` says it assumed.

References that do not come from the code under test: Pinocchio's own URDF parser (mass
matrix and gravity torques of the kneed compass gait), the numbers of the hand-written files
(``data/kneed_compass_gait.urdf``, the small bipeds below), and the built-in models.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.dynamics import crba, rnea
from gaitopt.robot import ModelError, load_model, model_from_yaml, model_to_yaml
from gaitopt.robot.mass_matrix import mass_matrix
from gaitopt.robot.urdf import ContactSpec, import_urdf, model_from_urdf, urdf_from_model

DATA = Path(__file__).parent / "data"
KCG = DATA / "kneed_compass_gait.urdf"
G = 9.81


# -- the kneed compass gait (after Drake's example) --------------------------------------------

def test_kneed_compass_gait_imports_with_the_published_numbers() -> None:
    result = import_urdf(KCG)
    m = result.model
    assert m.coordinate_names == ("x", "y", "hip", "hip_pin", "left_knee_pin",
                                  "right_knee_pin")
    hip = m.base  # the hip's 10 kg and the welded left upper leg's 2.5 kg, 0.25 m below it
    assert (hip.name, hip.mass) == ("hip", 12.5)
    assert hip.com == pytest.approx((2.5 * 0.25 / 12.5, 0.0), abs=1e-15)
    assert hip.inertia == pytest.approx(10 * 0.05**2 + 2.5 * 0.2**2, rel=1e-12)
    for name, mass in (("right_upper_leg", 2.5), ("left_lower_leg", 0.5),
                       ("right_lower_leg", 0.5)):
        link = m.link(name)  # point masses at the segment centres
        assert (link.mass, link.inertia, link.com, link.direction, link.length) == (
            mass, 0.0, (0.25, 0.0), "down", 0.5)
    # Inf limits about +y: gaitopt's knee bends to negative angles without a lower bound
    assert m.link("left_lower_leg").joint.limits == (-math.inf, 0.0)  # type: ignore[union-attr]
    assert m.link("right_lower_leg").joint.limits == (-math.inf, 0.0)  # type: ignore[union-attr]
    assert m.link("right_upper_leg").joint.limits == (-math.inf, math.inf)  # type: ignore[union-attr]
    assert [(c.name, c.link, c.at) for c in m.contacts] == [
        ("tip_1", "left_lower_leg", (0.5, 0.0)), ("tip_2", "right_lower_leg", (0.5, 0.0))]
    # transmissions without efforts: +- total mass x g x standing height (1 m)
    bound = 16.0 * G * 1.0
    assert [(a.name, a.joint) for a in m.actuators] == [
        ("hip_pin", "hip_pin"), ("left_knee_pin", "left_knee_pin"),
        ("right_knee_pin", "right_knee_pin")]
    for a in m.actuators:
        assert a.limits == pytest.approx((-bound, bound), rel=1e-15)
    lines = result.lines()
    assert lines[0].startswith("floating base: link 'hip' (with left_upper_leg fixed to it); "
                               "the URDF joints x (prismatic), z (prismatic), pitch "
                               "(continuous) became its coordinates x, y, hip")
    assert any(line.startswith("actuators: hip_pin +-157") and "<transmission>" in line
               for line in lines)
    assert any(line.startswith("warning: no effort on hip_pin, left_knee_pin, right_knee_pin")
               for line in lines)
    assert any(line.startswith("contacts: tip_1, tip_2 (inferred") for line in lines)
    # The left thigh is welded to the hip: the swap pairs the hip (with that thigh) with the
    # right thigh, a linear map of q (new base angle = base + hip), no permutation.
    assert lines[-1].startswith("symmetry: hip <-> right_upper_leg, left_lower_leg <-> "
                                "right_lower_leg, tip_1 <-> tip_2 (inferred")


def pinocchio_kcg() -> tuple[object, object, np.ndarray]:
    """Pinocchio's model of the kneed compass gait URDF as written (its world, prismatic x and
    z and continuous pitch joints included), Inf replaced by 1e9 (urdfdom does not read Inf;
    limits do not enter the mass matrix) and efforts added; its joint names; and the map
    ``v_pin = S v`` (nv_pin, nq): all its revolute axes are +y, so its angles are minus
    gaitopt's."""
    pin = pytest.importorskip("pinocchio")
    text = re.sub(r'"[+-]?[Ii]nf"', lambda mt: '"-1e9"' if "-" in mt.group() else '"1e9"',
                  KCG.read_text())
    # urdfdom also wants an effort and a velocity in every <limit>; Drake does not
    text = re.sub(r'<limit (lower="[^"]*" upper="[^"]*")/>', r'<limit \1 effort="0" '
                  r'velocity="0"/>', text)
    pm = pin.buildModelFromXML(text)
    names = ("x", "z", "pitch", "hip_pin", "left_knee_pin", "right_knee_pin")
    signs = (1.0, 1.0, -1.0, -1.0, -1.0, -1.0)
    s = np.zeros((pm.nv, len(names)))
    for i, (name, sign) in enumerate(zip(names, signs, strict=True)):
        s[pm.joints[pm.getJointId(name)].idx_v, i] = sign
    return pm, names, s


def test_kneed_compass_gait_mass_matrix_and_gravity_match_pinocchio() -> None:
    pin = pytest.importorskip("pinocchio")
    m = model_from_urdf(KCG)
    pm, names, s = pinocchio_kcg()
    pd = pm.createData()
    signs = s.sum(axis=0)
    rng = np.random.default_rng(11)
    for _ in range(8):
        q = rng.uniform(-1.5, 1.5, m.nq)
        qp = np.zeros(pm.nq)
        for i, name in enumerate(names):
            jm = pm.joints[pm.getJointId(name)]
            angle = signs[i] * q[i]
            if jm.nq == 2:  # the continuous pitch: (cos, sin)
                qp[jm.idx_q:jm.idx_q + 2] = math.cos(angle), math.sin(angle)
            else:
                qp[jm.idx_q] = angle
        m_pin = pin.crba(pm, pd, qp)
        m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T
        reference = s.T @ m_pin @ s
        np.testing.assert_allclose(np.asarray(crba(m, q)), reference, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(mass_matrix(m, q), reference, rtol=1e-10, atol=1e-10)
        zero = np.zeros(m.nq)
        np.testing.assert_allclose(np.asarray(rnea(m, q, zero, zero)).ravel(),
                                   s.T @ pin.computeGeneralizedGravity(pm, pd, qp),
                                   rtol=1e-10, atol=1e-9)


def test_forward_dynamics_of_point_masses_inverts_the_inverse() -> None:
    """The ABA works on the point-mass model: rnea(q, qd, aba(q, qd, tau)) = tau."""
    from gaitopt.dynamics import aba

    m = model_from_urdf(KCG)
    rng = np.random.default_rng(12)
    for _ in range(5):
        q, qd, tau = (rng.uniform(-1.5, 1.5, m.nq), rng.normal(size=m.nq),
                      rng.normal(size=m.nq))
        qdd = np.asarray(aba(m, q, qd, tau)).ravel()
        np.testing.assert_allclose(np.asarray(rnea(m, q, qd, qdd)).ravel(), tau,
                                   rtol=1e-9, atol=1e-9)


def test_kneed_compass_gait_round_trips_through_yaml_and_urdf() -> None:
    m = model_from_urdf(KCG)
    text = model_to_yaml(m)
    assert "limits: [null, 0.0]" in text and "limits: [null, null]" in text
    assert model_from_yaml(text) == m
    exported = urdf_from_model(m)  # the unbounded hip as a continuous joint, the knees 'inf'
    assert '<joint name="hip_pin" type="continuous">' in exported
    assert 'lower="-inf" upper="0.0"' in exported
    assert model_from_urdf(exported) == m


def test_the_robot_mass_matrix_is_crbas() -> None:
    """``robot.mass_matrix`` (the load-time check, from the kinetic energy) and
    ``dynamics.crba`` are two codes for one matrix."""
    rng = np.random.default_rng(3)
    for model in (load_model("five-link"), load_model("seven-link"), model_from_urdf(KCG)):
        for _ in range(5):
            q = rng.uniform(-2.0, 2.0, model.nq)
            np.testing.assert_allclose(mass_matrix(model, q), np.asarray(crba(model, q)),
                                       rtol=1e-12, atol=1e-12)


# -- small bipeds written here -----------------------------------------------------------------

def biped(*, efforts: tuple[str, str] = ("", ""), transmissions: str = "", foot: str = "",
          foot_link: str = "", shank_mass: float = 4.0, extra: str = "") -> str:
    """A five-link biped as another tool writes it: the torso is the root, legs 1 and 2 have
    hips and knees about URDF -y (no sign flips) with ``efforts`` (hip, knee: the attribute
    text, e.g. ``effort="50"``), thighs and shanks of 0.5 m; ``foot`` is collision XML in
    each shank (``{i}`` is the leg), ``foot_link`` a link fixed to each shank."""
    legs = []
    for i in (1, 2):
        legs.append(f"""
  <link name="thigh_{i}"><inertial><origin xyz="0 0 -0.25"/><mass value="7"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.01"/></inertial></link>
  <link name="shank_{i}"><inertial><origin xyz="0 0 -0.25"/><mass value="{shank_mass}"/>
    <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.01"/></inertial>
    {foot.format(i=i)}</link>
  <joint name="hip_{i}" type="revolute"><parent link="torso"/><child link="thigh_{i}"/>
    <axis xyz="0 -1 0"/><limit lower="-2" upper="2" {efforts[0]} velocity="10"/></joint>
  <joint name="knee_{i}" type="revolute"><parent link="thigh_{i}"/><child link="shank_{i}"/>
    <origin xyz="0 0 -0.5"/><axis xyz="0 -1 0"/>
    <limit lower="-2.5" upper="0" {efforts[1]} velocity="10"/></joint>""")
        if foot_link:
            legs.append(foot_link.format(i=i))
    return f"""<?xml version="1.0"?>
<robot name="biped" xmlns:drake="http://drake.mit.edu">
  <link name="torso"><inertial><origin xyz="0 0 0.36"/><mass value="20"/>
    <inertia ixx="0.6" ixy="0" ixz="0" iyy="0.576" iyz="0" izz="0.1"/></inertial></link>
  {''.join(legs)}
  {transmissions}
  {extra}
</robot>"""


OLD_FORMAT = """
  <transmission type="SimpleTransmission" name="t_{j}">
    <actuator name="motor_{j}"/><joint name="{j}"/><mechanicalReduction>1</mechanicalReduction>
  </transmission>"""
ROS_CONTROL = """
  <transmission name="t_{j}">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="{j}"><hardwareInterface>hardware_interface/EffortJointInterface
      </hardwareInterface></joint>
    <actuator name="motor_{j}"><mechanicalReduction>50</mechanicalReduction></actuator>
  </transmission>"""
SPHERE_FOOT = ('<collision><origin xyz="0.01 0 -0.48"/><geometry><sphere radius="0.02"/>'
               '</geometry></collision>')


def actuators(text: str) -> list[tuple[str, tuple[float, float]]]:
    return [(a.joint or "", a.limits) for a in model_from_urdf(text).actuators]


@pytest.mark.parametrize("form", [OLD_FORMAT, ROS_CONTROL], ids=["old format", "ros_control"])
def test_transmissions_choose_the_actuated_joints_efforts_bound_them(form: str) -> None:
    text = biped(efforts=('effort="80"', 'effort="60"'), foot=SPHERE_FOOT,
                 transmissions="".join(form.format(j=j) for j in ("hip_1", "hip_2")))
    # efforts on every joint, transmissions on the hips: only the hips are actuated
    assert actuators(text) == [("hip_1", (-80.0, 80.0)), ("hip_2", (-80.0, 80.0))]


def test_without_transmissions_every_joint_with_an_effort_is_actuated() -> None:
    text = biped(efforts=('effort="80"', ""), foot=SPHERE_FOOT)
    assert actuators(text) == [("hip_1", (-80.0, 80.0)), ("hip_2", (-80.0, 80.0))]
    assert actuators(biped(foot=SPHERE_FOOT)) == []


def test_a_transmission_joint_without_effort_gets_the_weight_at_standing_height() -> None:
    text = biped(efforts=('effort="80"', 'effort="0"'), foot=SPHERE_FOOT,
                 transmissions="".join(OLD_FORMAT.format(j=j) for j in ("hip_1", "knee_1")))
    result = import_urdf(text)
    bound = 42.0 * G * 1.0  # 42 kg; the sphere feet reach 0.48 + 0.02 below the knees
    got = [(a.joint, a.limits) for a in result.model.actuators]
    assert got == [("hip_1", (-80.0, 80.0)), ("knee_1", pytest.approx((-bound, bound)))]
    assert any(line.startswith("warning: no effort on knee_1: torque bound +-412")
               for line in result.lines())


@pytest.mark.parametrize(("joint", "problem"), [
    ("ankle_1", "transmission joint 'ankle_1': no joint 'ankle_1'"),
    ("mount_1", "transmission joint 'mount_1': joint 'mount_1' is fixed"),
])
def test_a_transmission_on_no_gaitopt_joint_is_refused(joint: str, problem: str) -> None:
    foot_link = ('<link name="foot_{i}"/><joint name="mount_{i}" type="fixed">'
                 '<parent link="shank_{i}"/><child link="foot_{i}"/></joint>')
    text = biped(foot=SPHERE_FOOT, foot_link=foot_link, transmissions=OLD_FORMAT.format(j=joint))
    with pytest.raises(ModelError) as info:
        model_from_urdf(text)
    assert str(info.value).startswith(f"<string>: {problem}; allowed: a revolute or "
                                      "continuous joint below the floating base")


# -- contacts from collision shapes ------------------------------------------------------------

def test_sphere_feet_give_tips_and_the_five_link_symmetry() -> None:
    result = import_urdf(biped(foot=SPHERE_FOOT))
    m = result.model
    # lowest point of the sphere: x 0.01, z -0.48 - 0.02 in the shank frame: [0.5, 0.01]
    assert [(c.name, c.link) for c in m.contacts] == [("tip_1", "shank_1"), ("tip_2", "shank_2")]
    for c in m.contacts:
        assert c.at == pytest.approx((0.5, 0.01), abs=1e-15)
    assert result.lines()[-1].startswith("symmetry: thigh_1 <-> thigh_2, shank_1 <-> shank_2, "
                                         "tip_1 <-> tip_2 (inferred")


SEVEN_LINK_SOLE = (-0.0532, 0.1463, -0.06825)  # heel x, toe x, sole z below the ankle


@pytest.mark.parametrize("shape", ["box", "capsule", "drake:capsule", "cylinder"])
def test_elongated_feet_give_heels_and_toes_and_a_declared_symmetry(shape: str) -> None:
    """A foot fixed below each shank's end with a box, capsule or cylinder whose bottom is
    seven-link's sole: the contacts are seven-link's heel and toe points, on the shank."""
    heel, toe, sole = SEVEN_LINK_SOLE
    centre, half, r = (heel + toe) / 2, (toe - heel) / 2, 0.02
    geometry = {
        "box": f'<origin xyz="{centre} 0 {sole + r}"/><geometry><box size="{2 * half} 0.1 '
               f'{2 * r}"/></geometry>',
        # capsules and cylinders along their z: turned by pitch pi/2 to lie along x
        "capsule": f'<origin xyz="{centre} 0 {sole + r}" rpy="0 1.5707963267948966 0"/>'
                   f'<geometry><capsule radius="{r}" length="{2 * half}"/></geometry>',
        "drake:capsule": f'<origin xyz="{centre} 0 {sole + r}" rpy="0 1.5707963267948966 0"/>'
                         f'<geometry><drake:capsule radius="{r}" length="{2 * half}"/>'
                         '</geometry>',
        "cylinder": f'<origin xyz="{centre} 0 {sole + r}" rpy="0 1.5707963267948966 0"/>'
                    f'<geometry><cylinder radius="{r}" length="{2 * half}"/></geometry>',
    }[shape]
    foot_link = ('<link name="foot_{i}"><collision>' + geometry.replace("{", "{{").replace(
        "}", "}}") + '</collision></link><joint name="mount_{i}" type="fixed"><parent '
        'link="shank_{i}"/><child link="foot_{i}"/><origin xyz="0 0 -0.5"/></joint>')
    result = import_urdf(biped(foot_link=foot_link))
    m = result.model
    want = [("heel_1", "shank_1", heel), ("toe_1", "shank_1", toe),
            ("heel_2", "shank_2", heel), ("toe_2", "shank_2", toe)]
    assert [(c.name, c.link) for c in m.contacts] == [(n, k) for n, k, _ in want]
    for c, (_, _, x) in zip(m.contacts, want, strict=True):
        assert c.at == pytest.approx((0.5 - sole, x), abs=1e-12)
    assert m.symmetry is not None
    assert m.symmetry.contacts == (("heel_1", "heel_2"), ("toe_1", "toe_2"))
    assert m.symmetry.links == (("thigh_1", "thigh_2"), ("shank_1", "shank_2"))
    assert "declared by the import" in result.lines()[-1]


def test_a_cylinder_across_the_plane_is_a_circle_and_contact_overrides_inference() -> None:
    foot = ('<collision><origin xyz="0 0 -0.45" rpy="1.5707963267948966 0 0"/><geometry>'
            '<cylinder radius="0.05" length="0.1"/></geometry></collision>')
    m = model_from_urdf(biped(foot=foot))
    assert [c.at for c in m.contacts] == [(0.5, 0.0), (0.5, 0.0)]
    given = model_from_urdf(biped(foot=foot), contacts=[ContactSpec("p", "shank_1", (0, -0.3))])
    assert [(c.name, c.at) for c in given.contacts] == [("p", (0.3, 0.0))]


def test_shapes_that_are_not_feet_are_not_read_and_the_import_says_so() -> None:
    """A thigh's collision cylinder tilted out of the plane is no foot: not refused; a mesh
    on a foot gives nothing; both are said."""
    thigh = ('<collision><origin xyz="0 0 -0.25" rpy="0.3 0.2 0"/><geometry><cylinder '
             'radius="0.05" length="0.5"/></geometry></collision>')
    mesh = '<collision><geometry><mesh filename="foot.stl"/></geometry></collision>'
    text = biped(foot=SPHERE_FOOT + mesh).replace(
        '<link name="thigh_1"><inertial>', f'<link name="thigh_1">{thigh}<inertial>')
    result = import_urdf(text)
    assert [c.name for c in result.model.contacts] == ["tip_1", "tip_2"]
    lines = result.lines()
    assert "  meshes are not read (no contact from them): shank_1, shank_2" in lines
    assert "  shapes on links that are not leaves are not feet: thigh_1" in lines


def test_no_collision_shape_on_a_leaf_says_how_to_give_contacts() -> None:
    result = import_urdf(biped())
    assert result.model.contacts == ()
    assert any(line.startswith("contacts: none (no collision shape on a leaf link; give them "
                               "with --contact") for line in result.lines())


def test_a_tilted_foot_cylinder_is_refused_naming_link_and_shape() -> None:
    foot = ('<collision><origin xyz="0 0 -0.45" rpy="0.3 0.2 0"/><geometry>'
            '<cylinder radius="0.05" length="0.1"/></geometry></collision>')
    with pytest.raises(ModelError) as info:
        model_from_urdf(biped(foot=foot))
    assert str(info.value).startswith("<string>: link 'shank_1' collision cylinder: ")
    assert "a shape tilted out of the sagittal plane" in str(info.value)


# -- point masses, singular models, infinite limits --------------------------------------------

def test_a_massless_leaf_on_a_revolute_joint_is_refused_naming_the_joint() -> None:
    extra = ('<link name="antenna"/><joint name="antenna_pin" type="revolute"><parent '
             'link="torso"/><child link="antenna"/><axis xyz="0 -1 0"/>'
             '<limit lower="-1" upper="1"/></joint>')
    with pytest.raises(ModelError) as info:
        model_from_urdf(biped(foot=SPHERE_FOOT, extra=extra))
    message = str(info.value)
    assert "\n" not in message
    assert ("the mass matrix is singular at the standing pose (q = 0): joint 'antenna_pin' "
            "(link 'antenna') moves no mass or inertia") in message


def test_a_point_mass_shank_loads_and_a_point_mass_on_its_joint_is_refused() -> None:
    point = biped(foot=SPHERE_FOOT).replace(
        '<mass value="4.0"/>\n    <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.05"',
        '<mass value="4.0"/>\n    <inertia ixx="0" ixy="0" ixz="0" iyy="0"')
    assert model_from_urdf(point).link("shank_1").inertia == 0.0
    on_joint = point.replace('<origin xyz="0 0 -0.25"/><mass value="4.0"/>',
                             '<origin xyz="0 0 0"/><mass value="4.0"/>')
    with pytest.raises(ModelError, match="joint 'knee_1' \\(link 'shank_1'\\) moves no mass"):
        model_from_urdf(on_joint)


@pytest.mark.parametrize(("lower", "upper", "limits"), [
    ("-Inf", "Inf", (-math.inf, math.inf)), ("-inf", "+inf", (-math.inf, math.inf)),
    ("-INF", "0", (-math.inf, 0.0)), ("-2", "infinity", (-2.0, math.inf)),
])
def test_infinite_limits_are_no_bounds(lower: str, upper: str, limits: tuple[float, float]
                                       ) -> None:
    text = biped(foot=SPHERE_FOOT).replace('<limit lower="-2.5" upper="0"',
                                           f'<limit lower="{lower}" upper="{upper}"')
    assert model_from_urdf(text).link("shank_1").joint.limits == limits  # type: ignore[union-attr]


@pytest.mark.parametrize(("lower", "upper", "why"), [
    ("nan", "0", "joint 'knee_1' limit lower: got 'nan'; allowed: a number (inf or -inf: no "
                 "bound)"),
    ("inf", "inf", "joint 'knee_1' limit: got 'lower inf, upper inf'; allowed: lower < inf"),
])
def test_bad_limits_are_refused_in_one_line(lower: str, upper: str, why: str) -> None:
    text = biped(foot=SPHERE_FOOT).replace('<limit lower="-2.5" upper="0"',
                                           f'<limit lower="{lower}" upper="{upper}"')
    with pytest.raises(ModelError) as info:
        model_from_urdf(text)
    assert str(info.value).startswith(f"<string>: {why}")


# -- the command ---------------------------------------------------------------------------------

def test_cli_imports_the_kneed_compass_gait_and_shows_it(tmp_path: Path) -> None:
    runner = CliRunner()
    out = tmp_path / "kcg.yaml"
    result = runner.invoke(cli, ["model", "import", str(KCG), "-o", str(out)])
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0] == f"wrote {out}"
    assert lines[1] == ("model KneedCompassGait: 4 links, 2 contact points, 3 actuators, "
                        "total mass 16 kg")
    for topic in ("floating base:", "actuators:", "warning:", "contacts:", "symmetry:"):
        assert any(line.startswith(topic) for line in lines), topic
    shown = runner.invoke(cli, ["model", "show", str(out)])
    assert shown.exit_code == 0, shown.output
    assert "[-inf, 0]" in shown.stdout and "left_knee_pin" in shown.stdout


def test_cli_import_to_stdout_keeps_the_yaml_clean(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["model", "import", str(KCG), "-o", "-"])
    assert result.exit_code == 0
    assert model_from_yaml(result.stdout) == model_from_urdf(KCG)
    assert "symmetry: hip <-> right_upper_leg" in result.stderr


def test_cli_refuses_a_singular_model_in_one_line(tmp_path: Path) -> None:
    extra = ('<link name="antenna"/><joint name="antenna_pin" type="continuous"><parent '
             'link="torso"/><child link="antenna"/><axis xyz="0 -1 0"/></joint>')
    file = tmp_path / "bad.urdf"
    file.write_text(biped(foot=SPHERE_FOOT, extra=extra))
    result = CliRunner().invoke(cli, ["model", "import", str(file), "-o",
                                      str(tmp_path / "bad.yaml")])
    assert result.exit_code == 2
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"Error: {file}: links[5].joint: the mass matrix is singular")
    assert "joint 'antenna_pin'" in line
