"""Joint damping (``Joint.damping``, a passive torque ``-b qd``) in the recursive dynamics:
against Pinocchio (which has none: ``rnea = pin.rnea + D qd``), the ABA/RNEA identity, the
power balance ``dE/dt = qd' tau - qd' D qd``, and the contact dynamics."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
from dynamics_helpers import assert_close, random_state, random_tree
from pinocchio_model import build

from gaitopt.dynamics import aba, bias_forces, contact_dynamics, rnea, total_energy
from gaitopt.robot import RobotModel, load_model
from gaitopt.robot.schema import model_from_dict


def damped(model: RobotModel, seed: int) -> RobotModel:
    """``model`` with a random damping on every joint (0.1-3 N m s/rad)."""
    rng = np.random.default_rng(seed)
    links = tuple(link if link.joint is None else dataclasses.replace(
        link, joint=dataclasses.replace(link.joint, damping=float(rng.uniform(0.1, 3.0))))
        for link in model.links)
    return dataclasses.replace(model, links=links)


def test_rnea_and_aba_add_the_damping_to_pinocchios_undamped_dynamics() -> None:
    for seed in (1, 2, 3):
        plain = random_tree(seed)
        model = damped(plain, seed)
        d = np.diag(model.coordinate_damping)
        assert np.all(np.diag(d)[:3] == 0.0) and np.all(np.diag(d)[3:] > 0.0)
        ref = build(plain)
        pm, pd, P, back = ref.model, ref.data(), ref.to_pin, ref.from_pin
        rng = np.random.default_rng(seed)
        for _ in range(20):
            q, qd, qdd = random_state(rng, model.nq)
            tau = 20.0 * rng.normal(size=model.nq)
            assert_close(rnea(model, q, qd, qdd),
                         back(pin.rnea(pm, pd, P(q), P(qd), P(qdd))) + d @ qd, what="rnea")
            assert_close(bias_forces(model, q, qd),
                         back(pin.nonLinearEffects(pm, pd, P(q), P(qd))) + d @ qd, what="bias")
            assert_close(aba(model, q, qd, tau),
                         back(pin.aba(pm, pd, P(q), P(qd), P(tau - d @ qd))), what="aba")


def test_aba_inverts_the_damped_rnea() -> None:
    model = damped(load_model("seven-link"), 7)
    rng = np.random.default_rng(7)
    for _ in range(20):
        q, qd, qdd = random_state(rng, model.nq)
        tau = np.asarray(rnea(model, q, qd, qdd), dtype=float).reshape(-1)
        assert_close(aba(model, q, qd, tau), qdd, rtol=1e-8, what="aba(rnea(qdd))")


def test_damping_dissipates_power_qd_d_qd() -> None:
    # dE/dt = qd' (tau - D qd) for the free tree (no contact), by a central difference of E
    # along the exact acceleration.
    model = damped(random_tree(4), 4)
    d = np.diag(model.coordinate_damping)
    rng = np.random.default_rng(4)
    for _ in range(10):
        q, qd, _ = random_state(rng, model.nq)
        tau = 5.0 * rng.normal(size=model.nq)
        qdd = np.asarray(aba(model, q, qd, tau), dtype=float).reshape(-1)
        h = 1e-6
        e = [float(total_energy(model, q + s * h * qd + 0.5 * (s * h) ** 2 * qdd,
                                qd + s * h * qdd)) for s in (-1.0, 1.0)]
        power = (e[1] - e[0]) / (2 * h)
        assert abs(power - qd @ (tau - d @ qd)) < 1e-5 * (1.0 + abs(qd @ d @ qd))


def test_held_contacts_see_the_damping_as_a_joint_force() -> None:
    # The contact dynamics of a damped model under tau equal the undamped model's under
    # tau - D qd.
    plain = load_model("seven-link")
    model = damped(plain, 9)
    d = np.diag(model.coordinate_damping)
    rng = np.random.default_rng(9)
    q, qd, _ = random_state(rng, model.nq)
    tau = 10.0 * rng.normal(size=model.nq)
    a = contact_dynamics(model, q, qd, tau, ["heel_1", "toe_1:y"])
    b = contact_dynamics(plain, q, qd, tau - d @ qd, ["heel_1", "toe_1:y"])
    assert_close(a.qdd, b.qdd, what="qdd")
    assert_close(a.forces, b.forces, what="forces")


def test_the_model_file_reads_and_writes_damping_and_refuses_a_negative_one() -> None:
    model = damped(load_model("five-link"), 5)
    data = model.to_dict()
    assert all("damping" in link["joint"] for link in data["links"][1:])
    assert model_from_dict(data) == model
    plain = load_model("five-link").to_dict()
    assert all("damping" not in link["joint"] for link in plain["links"][1:])
    data["links"][1]["joint"]["damping"] = -0.5
    try:
        model_from_dict(data)
    except ValueError as exc:
        assert "links[1].joint.damping" in str(exc) and ">= 0" in str(exc)
    else:
        raise AssertionError("a negative damping was accepted")
