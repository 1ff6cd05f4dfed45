"""MJCF import (``gaitopt.robot.mjcf``) against MuJoCo itself: Gymnasium's Walker2d v5 and
dm_control's planar walker (``data/dm_control``, Apache-2.0)."""

from __future__ import annotations

import functools
import sys
from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from gaitopt.dynamics import bias_forces, crba, point_position  # noqa: E402
from gaitopt.robot import ModelError, model_to_yaml  # noqa: E402
from gaitopt.robot.mjcf import MjcfImport, import_mjcf, is_mjcf  # noqa: E402
from gaitopt.robot.urdf import ContactSpec  # noqa: E402

DATA = Path(__file__).parent / "data"
DM_WALKER = DATA / "dm_control" / "walker.xml"
N_STATES = 50


def walker2d_path() -> Path:
    gym = pytest.importorskip("gymnasium")
    return Path(gym.__file__).parent / "envs" / "mujoco" / "assets" / "walker2d_v5.xml"


MODELS = {"walker2d": walker2d_path, "dm_walker": lambda: DM_WALKER}


@pytest.fixture(scope="module", params=sorted(MODELS))
def imported(request: pytest.FixtureRequest) -> tuple[Path, MjcfImport]:
    path = MODELS[request.param]()
    return path, import_mjcf(path)


@functools.lru_cache(maxsize=8)
def compiled(source: Path | str) -> object:
    """MuJoCo's model of a file or of MJCF text (compiled once per source)."""
    if isinstance(source, Path):
        return mujoco.MjModel.from_xml_path(str(source))
    return mujoco.MjModel.from_xml_string(source)


def mujoco_state(source: Path | str, imp: MjcfImport, q: np.ndarray, qd: np.ndarray
                 ) -> tuple[object, object]:
    """MuJoCo's model and data after ``mj_forward`` at gaitopt's (q, qd)."""
    m = compiled(source)
    d = mujoco.MjData(m)
    d.qpos[:] = imp.coordinates.qpos_from_q(q)
    d.qvel[:] = imp.coordinates.qvel_from_qd(qd)
    mujoco.mj_forward(m, d)
    return m, d


def random_states(nq: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(N_STATES):
        q = rng.uniform(-np.pi, np.pi, nq)
        q[:2] = rng.uniform(-2.0, 2.0, 2)
        out.append((q, 3.0 * rng.normal(size=nq)))
    return out


def full_mass_matrix(m: object, d: object) -> np.ndarray:
    """``mj_fullM``: MuJoCo 4 takes (m, d, dst), MuJoCo 3 (m, dst, qM); pyproject allows both."""
    full = np.zeros((m.nv, m.nv))  # type: ignore[attr-defined]
    try:
        mujoco.mj_fullM(m, d, full)
    except TypeError:
        mujoco.mj_fullM(m, full, d.qM)  # type: ignore[attr-defined]
    return full


def dynamics_errors(source: Path | str, imp: MjcfImport) -> tuple[float, float]:
    """The largest entry of ``M + diag(armature) - P M_mujoco P^T`` and of
    ``bias - P (qfrc_bias - qfrc_passive)`` over the random states (armature is dropped by the
    import; the hinges' damping kept)."""
    p = imp.coordinates.velocity_matrix()
    worst_m = worst_b = 0.0
    for q, qd in random_states(imp.model.nq, seed=24):
        m, d = mujoco_state(source, imp, q, qd)
        full = full_mass_matrix(m, d)
        ours = np.asarray(crba(imp.model, q)) + np.diag(imp.armature)
        worst_m = max(worst_m, float(np.max(np.abs(ours - p @ full @ p.T))))
        bias = np.asarray(bias_forces(imp.model, q, qd)).ravel()
        # gaitopt's bias holds the hinges' damping D qd, MuJoCo's passive force is -D qd (the
        # floating base's damping is dropped by the import).
        passive = p @ d.qfrc_passive
        passive[:3] = 0.0
        worst_b = max(worst_b, float(np.max(np.abs(bias - (p @ d.qfrc_bias - passive)))))
    return worst_m, worst_b


def test_mass_matrix_and_bias_equal_mujocos(imported: tuple[Path, MjcfImport]) -> None:
    path, imp = imported
    worst_m, worst_b = dynamics_errors(path, imp)
    print(f"{path.name}: max |M error| {worst_m:.2e}, max |bias error| {worst_b:.2e}")
    assert worst_m <= 1e-9 and worst_b <= 1e-9


def test_link_origins_and_centres_follow_mujocos_kinematics(
        imported: tuple[Path, MjcfImport]) -> None:
    # The map's base offsets and signs: each link origin is its hinge's anchor (xanchor) and
    # each one-body link's centre of mass is MuJoCo's xipos, in the plane x-z.
    path, imp = imported
    model = imp.model
    for q, qd in random_states(model.nq, seed=7)[:10]:
        m, d = mujoco_state(path, imp, q, qd)
        for i, link in enumerate(model.links):
            j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT,
                                  link.joint.name if link.joint else imp.coordinates.names[2])
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, link.name)
            origin = np.asarray(point_position(model, q, i, (0.0, 0.0))).ravel()
            np.testing.assert_allclose(origin, d.xanchor[j][[0, 2]], atol=1e-12)
            com = np.asarray(point_position(model, q, i, link.com_local)).ravel()
            np.testing.assert_allclose(com, d.xipos[b][[0, 2]], atol=1e-12)


def test_walker2d_coordinate_map() -> None:
    imp = import_mjcf(walker2d_path())
    cm = imp.coordinates
    joints = ("thigh_joint", "leg_joint", "foot_joint", "thigh_left_joint", "leg_left_joint",
              "foot_left_joint")
    assert cm.names == ("rootx", "rootz", "rooty", *joints)
    assert imp.model.coordinate_names == ("x", "y", "torso", *joints)
    # rooty turns about +y: gaitopt's angle (CCW about z = -y) is -rooty; the legs' hinges
    # are about -y: as MuJoCo's. rootz has ref 1.25 (qpos0), the torso's height at qpos0.
    assert cm.sign == (1.0, 1.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0)
    assert cm.offset == pytest.approx((0.0, 1.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
                                      abs=1e-12)
    qpos = np.array([0.3, 1.1, 0.2, -0.5, -0.4, 0.1, -0.2, -0.3, -0.1])
    np.testing.assert_array_equal(cm.q_from_qpos(qpos),
                                  [0.3, 1.1, -0.2, -0.5, -0.4, 0.1, -0.2, -0.3, -0.1])
    np.testing.assert_array_equal(cm.qpos_from_q(cm.q_from_qpos(qpos)), qpos)
    qvel = np.arange(1.0, 10.0)
    np.testing.assert_array_equal(cm.qvel_from_qd(cm.qd_from_qvel(qvel)), qvel)
    assert cm.qd_from_qvel(qvel)[2] == -3.0


def test_dm_walker_map_and_projection() -> None:
    # rootz comes first in MuJoCo's qpos; the legs sit at y = +-0.05 (projected out)
    imp = import_mjcf(DM_WALKER)
    cm = imp.coordinates
    assert cm.names[:3] == ("rootx", "rootz", "rooty")
    assert cm.qpos_index[:3] == (1, 0, 2)
    assert cm.offset[:3] == pytest.approx((0.0, 1.3, 0.0), abs=1e-12)
    right, left = imp.model.link("right_thigh"), imp.model.link("left_thigh")
    assert right.joint is not None and left.joint is not None
    assert right.joint.at == pytest.approx(left.joint.at, abs=1e-12)
    assert right.mass == left.mass
    assert right.com == pytest.approx(left.com, abs=1e-12)
    assert right.inertia == pytest.approx(left.inertia, rel=1e-12)


def test_walker2d_imports_what_mujoco_compiled() -> None:
    path = walker2d_path()
    imp = import_mjcf(path)
    m = mujoco.MjModel.from_xml_path(str(path))
    model = imp.model
    assert model.name == "walker2d"
    assert [link.name for link in model.links] == [
        "torso", "thigh", "leg", "foot", "thigh_left", "leg_left", "foot_left"]
    assert [link.mass for link in model.links] == list(m.body_mass[1:])
    # about y, a principal axis; through MuJoCo's kinematics: to 1e-12 (docs/testing.md)
    assert model.link("thigh").inertia == pytest.approx(m.body_inertia[2][1], rel=1e-12)
    # the knee sits 0.25 m above the leg body's origin: 0.45 m below the hip
    assert model.link("leg").joint.at == pytest.approx((0.45, 0.0), abs=1e-12)  # type: ignore
    assert model.link("thigh").joint.limits == pytest.approx(  # type: ignore[union-attr]
        (-150 * np.pi / 180, 0.0), rel=1e-12)
    assert [a.limits for a in model.actuators] == [(-100.0, 100.0)] * 6
    assert [a.joint for a in model.actuators] == list(imp.coordinates.names[3:])
    assert imp.armature == (0.0,) * 3 + (0.01,) * 6
    notes = "\n".join(imp.notes)
    assert "armature: dropped" in notes and "damping: kept as joint damping" in notes
    hinges = [link.joint for link in model.links[1:]]
    assert [j.damping for j in hinges] == pytest.approx([0.1] * 6)  # type: ignore[union-attr]
    assert "torso = -rooty" in notes


def test_gravity_convention(imported: tuple[Path, MjcfImport]) -> None:
    # MuJoCo's (0, 0, -9.81) is gaitopt's (0, -9.81); at rest the bias is the weight: the
    # generalized force holding the base up is +m g along y, on both sides.
    path, imp = imported
    assert imp.model.gravity == (0.0, -9.81)
    q = np.zeros(imp.model.nq)
    bias = np.asarray(bias_forces(imp.model, q, np.zeros_like(q))).ravel()
    m, d = mujoco_state(path, imp, q, np.zeros_like(q))
    assert bias[1] == pytest.approx(imp.model.total_mass * 9.81, rel=1e-12)
    assert imp.coordinates.velocity_matrix()[1] @ d.qfrc_bias == pytest.approx(bias[1],
                                                                             rel=1e-12)


WALKER_TEMPLATE = """<mujoco model="one-leg">
  <option gravity="{gravity}"/>
  <worldbody>
    <body name="torso" pos="0 0 1">
      <joint name="rootx" type="slide" axis="1 0 0"/>
      <joint name="rootz" type="slide" axis="0 0 1"/>
      <joint name="rooty" type="hinge" axis="0 1 0"/>
      <geom type="capsule" size="0.05 0.2"/>
      <body name="leg" pos="0 0.1 -0.2">
        <joint name="hip" type="hinge" axis="{axis}" range="-10 40"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.04"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="hip" gear="30" ctrlrange="-2 1"/></actuator>
</mujoco>"""


def one_leg(axis: str = "0 1 0", gravity: str = "0 0 -9.81") -> str:
    return WALKER_TEMPLATE.format(axis=axis, gravity=gravity)


def test_an_out_of_plane_hinge_is_refused_by_name() -> None:
    with pytest.raises(ModelError, match=r"^<string>: joint 'hip' axis: got '1 0 0'; "
                                         r"allowed: a hinge axis along \+-y"):
        import_mjcf(one_leg(axis="1 0 0"))


def test_plus_y_hinge_flips_limits_and_torques_and_gravity_is_read() -> None:
    imp = import_mjcf(one_leg(gravity="0.5 0 -3"))
    leg = imp.model.link("leg")
    # MuJoCo's range [-10, 40] degrees about +y is [-40, 10] degrees in gaitopt's sense
    assert leg.joint is not None
    np.testing.assert_allclose(leg.joint.limits, np.radians([-40.0, 10.0]), rtol=1e-15)
    assert imp.model.actuators[0].limits == (-30.0, 60.0)  # -(30 x [-2, 1])
    assert imp.model.gravity == (0.5, -3.0)
    assert imp.coordinates.sign[3] == -1.0


@pytest.mark.parametrize(("edit", "message"), [
    (('<joint name="rootx" type="slide" axis="1 0 0"/>', ""),
     r"body 'torso' joints: got rootz \(slide\), rooty \(hinge\); allowed: one body with two "
     r"slide joints"),
    (('<joint name="hip" type="hinge"', '<joint name="hip" type="slide"'),
     r"body 'leg' joints: got hip \(slide\); allowed: one hinge about y per body"),
    (('gear="30"', 'gear="30" ctrllimited="false"'), r"actuator 'actuator0': got 'no "
     r"ctrlrange or forcerange'"),
    (('<body name="torso"', '<body name="other" pos="3 0 0"><joint type="slide"/>'
      '<geom size="0.1"/></body><body name="torso"'), r"worldbody: 2 bodies with joints"),
    (('fromto="0 0 0 0 0 -0.5" size="0.04"/>', 'fromto="0 0 0 0 0 -0.5" size="0.04"/>'
      '<geom name="sole" type="capsule" fromto="0 -0.1 -0.5 0.1 0.1 -0.5" size="0.02"/>'),
     r"link 'leg' geom 'sole': its axis neither in the plane nor normal to it"),
])
def test_what_is_refused(edit: tuple[str, str], message: str) -> None:
    with pytest.raises(ModelError, match=message):
        import_mjcf(one_leg().replace(*edit))


def test_contact_option_points_in_the_body_frame() -> None:
    imp = import_mjcf(one_leg(), contacts=[ContactSpec("tip", "leg", (0.0, -0.5))])
    tip = imp.model.contact("tip")
    assert tip.link == "leg"
    assert imp.model.link("leg").local_point(*tip.at) == (0.0, -0.5)
    with pytest.raises(ModelError, match=r"contact 'tip': no body 'shin'"):
        import_mjcf(one_leg(), contacts=[ContactSpec("tip", "shin", (0.0, -0.5))])


def test_the_import_is_deterministic() -> None:
    first, second = import_mjcf(DM_WALKER), import_mjcf(DM_WALKER)
    assert model_to_yaml(first.model) == model_to_yaml(second.model)
    assert first == second


def test_a_missing_mujoco_says_how_to_install_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(ModelError, match=r"pip install 'gaitopt\[mujoco\]'"):
        import_mjcf(DM_WALKER)


def test_mjcf_is_recognised(tmp_path: Path) -> None:
    renamed = tmp_path / "robot.mjcf"
    renamed.write_text("<?xml version='1.0'?>\n<!-- a comment -->\n" + one_leg())
    urdf = tmp_path / "robot.xml"
    urdf.write_text("<robot name='r'/>")
    assert is_mjcf(DM_WALKER) and is_mjcf(renamed) and is_mjcf(tmp_path / "missing.xml")
    assert not is_mjcf(urdf) and not is_mjcf(tmp_path / "missing.urdf")


def test_inferred_heels_and_toes_sit_on_the_foot_capsules(
        imported: tuple[Path, MjcfImport]) -> None:
    # heel_k and toe_k are the ends of the bottom line of foot k's capsule at qpos0: at any
    # state, in the capsule's own frame (axis z, half length h, radius r), they lie at z = -h
    # and +h (either way round) and at distance r from the axis.
    path, imp = imported
    model = imp.model
    assert [c.name for c in model.contacts] == ["heel_1", "toe_1", "heel_2", "toe_2"]
    assert model.symmetry is not None
    assert model.symmetry.contacts == (("heel_1", "heel_2"), ("toe_1", "toe_2"))
    for q, qd in random_states(model.nq, seed=3)[:10]:
        m, d = mujoco_state(path, imp, q, qd)
        for c in model.contacts:
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, c.link)
            g = next(i for i in range(m.ngeom) if m.geom_bodyid[i] == b)
            r, h = m.geom_size[g][:2]
            x, z = np.asarray(point_position(model, q, c.link,
                                             model.link(c.link).local_point(*c.at))).ravel()
            world = np.array([x, d.geom_xpos[g][1], z])
            local = d.geom_xmat[g].reshape(3, 3).T @ (world - d.geom_xpos[g])
            assert abs(abs(local[2]) - h) < 1e-12 and abs(np.hypot(*local[:2]) - r) < 1e-12


def test_cli_imports_walker2d_and_prints_what_it_assumed(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from gaitopt.cli import cli
    from gaitopt.robot import load_model

    out = tmp_path / "walker2d.yaml"
    result = CliRunner().invoke(cli, ["model", "import", str(walker2d_path()), "-o", str(out)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[:2] == [f"wrote {out}", "model walker2d: 7 links, 4 contact points, 6 "
                         "actuators, total mass 23.6771 kg"]
    for start in ("floating base: body 'torso'", "contacts: heel_1, toe_1, heel_2, toe_2",
                  "  heel_1 at (0, -0.06), toe_1 at (0.2, -0.06) m in link 'foot'",
                  "actuators: [-100, 100] N m on thigh_joint", "armature: dropped",
                  "damping: kept as joint damping",
                  "symmetry: thigh <-> thigh_left"):
        assert any(line.startswith(start) for line in lines), (start, lines)
    assert load_model(out) == import_mjcf(walker2d_path()).model
    result = CliRunner().invoke(cli, ["model", "import", str(walker2d_path()), "-o", "-",
                                      "--contact", "tip=foot:-0.2,0.1"])
    assert result.exit_code == 0, result.output
    assert "contacts: tip from --contact (the geoms are not used)" in result.stderr
    assert "name: tip" in result.stdout and "heel_1" not in result.stdout
    assert "at: [0.0, 0.0]" in result.stdout  # (-0.2, 0.1) in the foot body: the ankle
    result = CliRunner().invoke(cli, ["model", "import", str(tmp_path / "none.xml")])
    assert result.exit_code == 2 and "MuJoCo cannot compile it" in result.output


def test_axis_x_armature_and_a_static_body() -> None:
    # The same one-legged robot turned to walk along -y (hinges about x, plane y-z), with
    # armature on the hip and an obstacle fixed to the world: the dynamics still equal
    # MuJoCo's, the armature is reported per coordinate and the obstacle is not the robot.
    text = (one_leg().replace('axis="1 0 0"/>', 'axis="0 -1 0"/>')
            .replace('<joint name="rooty" type="hinge" axis="0 1 0"/>',
                     '<joint name="rooty" type="hinge" axis="1 0 0"/>')
            .replace('axis="0 1 0" range', 'axis="-1 0 0" armature="0.02" range')
            .replace('pos="0 0.1 -0.2"', 'pos="0.1 0.05 -0.2"')
            .replace("<worldbody>", '<worldbody><body name="obstacle" pos="2 0 0">'
                     '<geom type="box" size="0.1 0.1 0.1"/></body>'))
    imp = import_mjcf(text, axis="x")
    assert imp.coordinates.sign == (1.0, 1.0, -1.0, 1.0)
    assert imp.armature == (0.0, 0.0, 0.0, 0.02)
    assert "static bodies (fixed to the world, not the robot): obstacle" in imp.notes
    worst_m, worst_b = dynamics_errors(text, imp)
    assert worst_m <= 1e-9 and worst_b <= 1e-9


def test_a_pitched_body_a_hinge_ref_and_a_welded_body() -> None:
    # The leg body pitched 30 degrees about y (its frame is not the link's), its hinge with
    # ref=20 degrees (qpos0 = 20 degrees: the angle is 0 there, the range is shifted) and
    # a foot welded to it: still MuJoCo's dynamics, and the masses add.
    text = (one_leg()
            .replace('<body name="leg" pos="0 0.1 -0.2">',
                     '<body name="leg" pos="0 0.1 -0.2" euler="0 30 0">')
            .replace('range="-10 40"', 'range="-10 40" ref="20"')
            .replace('size="0.04"/>', 'size="0.04"/><body name="foot" pos="0.1 0 -0.5">'
                     '<geom type="box" size="0.1 0.03 0.02" euler="0 10 0"/></body>'))
    imp = import_mjcf(text)
    m = compiled(text)
    leg = imp.model.link("leg")
    assert leg.joint is not None
    # about +y: gaitopt's angle is -(qpos - 20 deg), so [-10, 40] deg becomes [-20, 30] deg
    np.testing.assert_allclose(leg.joint.limits, np.radians([-20.0, 30.0]), rtol=1e-14)
    assert leg.mass == pytest.approx(float(m.body_mass[2] + m.body_mass[3]), rel=1e-15)
    assert [link.name for link in imp.model.links] == ["torso", "leg"]
    worst_m, worst_b = dynamics_errors(text, imp)
    assert worst_m <= 1e-9 and worst_b <= 1e-9


def test_an_unlimited_hinge_has_no_bounds() -> None:
    imp = import_mjcf(one_leg().replace('range="-10 40"', 'limited="false"'))
    assert imp.model.link("leg").joint.limits == (-np.inf, np.inf)  # type: ignore[union-attr]
