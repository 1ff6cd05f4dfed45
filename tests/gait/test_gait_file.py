"""The gait file: round trips, corruption, leg relabelling, interpolation between knots."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from gaitopt.gait.gait_file import (
    FAILED_WARNING,
    Gait,
    GaitFileError,
    GaitPhase,
)
from gaitopt.gait.interpolation import phase_controls_at, phase_states_at
from gaitopt.robot import load_model
from gaitopt.robot.symmetry import swap_names, swap_permutations
from tests.viz.synthetic import forward_kinematics, synthetic_gait


@pytest.fixture(scope="module")
def gait() -> Gait:
    return synthetic_gait(speed=0.5, step_length=0.4)


def _assert_same(a: Gait, b: Gait) -> None:
    assert json.dumps(a.to_dict(), sort_keys=True) == json.dumps(b.to_dict(), sort_keys=True)
    for pa, pb in zip(a.phases, b.phases, strict=True):
        for name in ("t", "q", "qd", "qdd", "u", "x", "xdot"):
            np.testing.assert_array_equal(getattr(pa, name), getattr(pb, name))
    np.testing.assert_array_equal(a.samples.points["knee_2"], b.samples.points["knee_2"])


def test_save_load_round_trip_is_exact(gait: Gait, tmp_path: Path) -> None:
    path = gait.save(tmp_path / "walk.gait.json")
    loaded = Gait.load(path)
    _assert_same(gait, loaded)
    assert loaded.speed == gait.speed and loaded.step_length == gait.step_length
    assert loaded.cost_value == gait.cost_value and loaded.success
    assert loaded.model.nq == 7 and loaded.model.nu == 6
    assert loaded.phases[1].contacts == ("tip_1", "tip_2")
    assert loaded.events[0].name == "heel_strike" and loaded.events[0].leg == "tip_2"
    assert [p.name for p in tmp_path.iterdir()] == ["walk.gait.json"]  # no temporary left


def test_from_dict_of_to_dict_is_identity(gait: Gait) -> None:
    data = gait.to_dict()
    json.dumps(data, allow_nan=False)  # plain JSON data
    _assert_same(gait, Gait.from_dict(data))


def test_file_is_readable_json_with_numbers_rows_on_one_line(gait: Gait, tmp_path: Path) -> None:
    path = gait.save(tmp_path / "g.gait.json")
    text = path.read_text()
    data = json.loads(text)
    assert data["format"] == "gaitopt.gait" and data["version"] == 2
    assert set(data["parameters"]) >= {"step_length", "speed", "step_time",
                                       "single_support_time", "liftoff_impulse"}
    n_samples = len(data["samples"]["t"])
    # one line per sample row of q, qd, u and 6 points, plus the t line: compact, not 1 number
    # per line
    assert len(text.splitlines()) < 20 * n_samples


def test_data_is_immutable(gait: Gait) -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        gait.parameters = {}
    with pytest.raises(ValueError, match="read-only"):
        gait.samples.q[0, 0] = 1.0
    with pytest.raises(TypeError):
        gait.parameters["speed"] = 2.0


def test_failed_gait_is_refused_unless_allowed_and_then_marked(tmp_path: Path) -> None:
    failed = synthetic_gait(success=False)
    with pytest.raises(GaitFileError, match=r"solver\.success.*allow_failed"):
        failed.save(tmp_path / "f.gait.json")
    assert not (tmp_path / "f.gait.json").exists()
    path = failed.save(tmp_path / "f.gait.json", allow_failed=True)
    data = json.loads(path.read_text())
    assert data["WARNING"] == FAILED_WARNING
    assert list(data)[:3] == ["format", "version", "WARNING"]  # near the top, seen first
    assert not Gait.load(path).success


def _corrupt(gait: Gait, tmp_path: Path, edit: object) -> Path:
    data = gait.to_dict()
    edit(data)  # type: ignore[operator]
    path = tmp_path / "bad.gait.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(("edit", "field", "words"), [
    (lambda d: d.update(format="gaitopt.model"), "format", "not a gait file"),
    (lambda d: d.update(version=3), "version", "major version 3 is not supported"),
    (lambda d: d.update(version="3.1"), "version", "not supported"),
    (lambda d: d.pop("samples"), "", "missing required key 'samples'"),
    (lambda d: d["phases"][1].update(q=d["phases"][1]["q"][:-1]), "phases[1].q", "shape"),
    (lambda d: d["phases"][0].update(contacts=["tip_1", "tip_2"]),
     "phases[0].contact_forces", "contacts on the ground"),
    (lambda d: d["phases"][0].update(t=d["phases"][0]["t"][::-1]), "phases[0].t", "increasing"),
    (lambda d: d["samples"]["points"].pop("torso_top"), "samples.points", "torso_top"),
    (lambda d: d["events"][0].update(leg="foot_9"), "events[0].leg", "not a contact"),
    (lambda d: d["events"][1].update(name="a jump!"), "events[1].name", "heel_strike"),
    (lambda d: d["parameters"].update(step_time=9.0), "parameters.step_time", "span"),
    (lambda d: d["parameters"].update(speed=-1.0), "parameters.speed", ">= 0"),
    (lambda d: d["parameters"].pop("liftoff_impulse"), "parameters", "liftoff_impulse"),
    (lambda d: d["solver"].update(success="yes"), "solver.success", "true or false"),
    (lambda d: d["solver"]["evaluations"].update(nlp_f=-3), "solver.evaluations.nlp_f", ">= 0"),
    (lambda d: d["model"]["links"][1].update(mass=-7), "model.links[1].mass", ">= 0"),
    (lambda d: d["samples"]["u"][3].__setitem__(0, "x"), "samples.u", "numbers"),
])
def test_corrupted_files_give_errors_naming_file_and_field(
        gait: Gait, tmp_path: Path, edit: object, field: str, words: str) -> None:
    path = _corrupt(gait, tmp_path, edit)
    with pytest.raises(GaitFileError) as info:
        Gait.load(path)
    assert info.value.source == str(path)
    assert info.value.path == field
    assert words in str(info.value)
    assert str(path) in str(info.value)


def test_nan_in_a_file_is_rejected(gait: Gait, tmp_path: Path) -> None:
    text = json.dumps(gait.to_dict())
    first_t = json.dumps(gait.samples.t[5].item())
    bad = tmp_path / "nan.gait.json"
    bad.write_text(text.replace(f", {first_t},", ", NaN,", 1))
    with pytest.raises(GaitFileError, match=r"samples\.t: contains NaN"):
        Gait.load(bad)


def test_not_json_and_truncated_and_missing_files(gait: Gait, tmp_path: Path) -> None:
    text = json.dumps(gait.to_dict())
    half = tmp_path / "half.gait.json"
    half.write_text(text[: len(text) // 2])
    with pytest.raises(GaitFileError, match=r"half\.gait\.json: line 1, column \d+: not valid"):
        Gait.load(half)
    with pytest.raises(GaitFileError, match="no such file"):
        Gait.load(tmp_path / "nothing.gait.json")
    arr = tmp_path / "list.gait.json"
    arr.write_text("[1, 2]")
    with pytest.raises(GaitFileError, match="expected an object"):
        Gait.load(arr)


def test_version_1_files_still_load(gait: Gait) -> None:
    """A file written before contact sequences (version 1: no contact_sequence) loads."""
    data = gait.to_dict()
    data["version"] = 1
    data.pop("contact_sequence", None)
    old = Gait.from_dict(data)
    assert old.version == 1 and old.contact_sequence is None
    assert old.cost_value == gait.cost_value


def test_minor_version_string_of_major_1_is_read(gait: Gait) -> None:
    data = gait.to_dict()
    data["version"] = "1.4"
    assert Gait.from_dict(data).version == 1


def test_constructor_checks_shapes_against_the_model(gait: Gait) -> None:
    phase = gait.phases[0]
    short = GaitPhase(name="p", contacts=("tip_1",), t=phase.t, q=phase.q[:, :5],
                      qd=phase.qd[:, :5], qdd=phase.qdd[:, :5], u=phase.u,
                      contact_forces=dict(phase.contact_forces), state_names=phase.state_names,
                      x=phase.x, xdot=phase.xdot)
    with pytest.raises(GaitFileError, match=r"phases\[0\]\.q: the model has nq=7"):
        dataclasses.replace(gait, phases=(short, gait.phases[1]))


# -- legs ----------------------------------------------------------------------------------------

def test_swap_permutations_of_the_five_link_model() -> None:
    perm_q, perm_u = swap_permutations(load_model("five-link"))
    # q = [x, y, torso, hip_1, knee_1, hip_2, knee_2]; u = [hip, knee, ankle] x 2
    assert perm_q.tolist() == [0, 1, 2, 5, 6, 3, 4]
    assert perm_u.tolist() == [3, 4, 5, 0, 1, 2]


def test_stride_is_periodic_and_points_follow_physical_legs(gait: Gait) -> None:
    n = gait.samples.t.size
    stride = gait.stride_samples(3)
    L, T = gait.step_length, gait.step_time
    assert stride.t.size == 3 * n - 2  # step boundaries shared
    np.testing.assert_allclose(stride.t[[0, n - 1, -1]], [0.0, T, 3 * T])
    # Independent check of the relabelling: the points of every sample are the forward
    # kinematics of the relabelled q.
    fk = forward_kinematics(gait.model, stride.q)
    for name in ("hip", "knee_1", "knee_2", "tip_1", "tip_2", "torso_top"):
        np.testing.assert_allclose(stride.points[name], fk[name], atol=1e-12)
    # Physical leg 1 stands at x = 0 during step 0, swings to 2L in step 1, stands in step 2.
    tip1, tip2 = stride.points["tip_1"], stride.points["tip_2"]
    step = np.minimum((stride.t / T * (1 - 1e-12)).astype(int), 2)
    np.testing.assert_allclose(tip1[step == 0], 0.0, atol=1e-9)
    assert tip1[step == 1, 1].max() > 0.02  # lifted while swinging
    np.testing.assert_allclose(tip1[step == 2], np.tile([2 * L, 0.0], ((step == 2).sum(), 1)),
                               atol=1e-9)
    np.testing.assert_allclose(tip2[step == 1], np.tile([L, 0.0], ((step == 1).sum(), 1)),
                               atol=1e-9)
    # positions are continuous across the step boundaries (no jump larger than a sample's travel)
    for name in ("hip", "knee_1", "knee_2", "tip_1", "tip_2"):
        jumps = np.linalg.norm(np.diff(stride.points[name], axis=0), axis=1)
        assert jumps.max() < 0.05, name
    # the hip advances by exactly one step length per step
    hip = stride.points["hip"]
    np.testing.assert_allclose(hip[n - 1 + (n - 1), 0] - hip[n - 1, 0], L, atol=1e-12)
    with pytest.raises(ValueError, match="n_steps"):
        gait.stride_samples(0)


# -- interpolation between knots -----------------------------------------------------------------

def _phase(t: np.ndarray, x: np.ndarray, xdot: np.ndarray) -> GaitPhase:
    k = t.size
    z = np.zeros((k, 7))
    return GaitPhase(name="p", contacts=(), t=t, q=z, qd=z, qdd=z,
                     u=np.stack([t, t**2], axis=1), contact_forces={}, state_names=("a",),
                     x=x[:, None], xdot=xdot[:, None])


def test_hermite_interpolation_is_exact_for_cubics_and_fourth_order() -> None:
    t = np.array([0.0, 0.1, 0.35, 0.4, 1.0])
    phase = _phase(t, t**3 - 2 * t**2 + t, 3 * t**2 - 4 * t + 1)
    tt = np.linspace(0.0, 1.0, 57)
    np.testing.assert_allclose(phase_states_at(phase, tt)[:, 0], tt**3 - 2 * tt**2 + tt,
                               atol=1e-14)
    errors = []
    for k in (9, 17, 33):  # knot spacing 0.25, 0.125, 0.0625
        tk = np.linspace(0.0, 2.0, k)
        err = phase_states_at(_phase(tk, np.sin(3 * tk), 3 * np.cos(3 * tk)), tt * 2)[:, 0]
        errors.append(np.max(np.abs(err - np.sin(6 * tt))))
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    assert all(12 < r < 20 for r in ratios), ratios  # ~2^4 per halving of the knot spacing


def test_controls_are_piecewise_linear_between_knots() -> None:
    t = np.array([0.0, 0.5, 1.0])
    phase = _phase(t, t, np.ones(3))
    u = phase_controls_at(phase, np.array([0.0, 0.25, 0.75, 1.0]))
    np.testing.assert_allclose(u[:, 0], [0.0, 0.25, 0.75, 1.0])
    np.testing.assert_allclose(u[:, 1], [0.0, 0.125, 0.625, 1.0])  # chords of t^2


def test_repr_is_one_short_line(gait: Gait) -> None:
    text = repr(gait)
    assert "\n" not in text and len(text) < 200
    assert "speed=0.5 m/s" in text and "single_support(8)+double_support(5)" in text


def test_non_json_options_are_refused_at_construction(gait: Gait) -> None:
    with pytest.raises(GaitFileError, match=r"options: must be plain JSON data"):
        dataclasses.replace(gait, options={"knots": np.array([8, 5])})
    with pytest.raises(GaitFileError, match=r"options: must be plain JSON data"):
        dataclasses.replace(gait, options={"tol": float("nan")})
    with pytest.raises(GaitFileError, match=r"solver: must be plain JSON data"):
        dataclasses.replace(gait, solver={**gait.solver, "stages": [object()]})


def test_swap_names_follow_the_models_symmetry() -> None:
    """Joint, link and contact names swap by the model's symmetry (declared for the seven-link
    model: heels and toes with their feet), not by a naming rule; unpaired names stay."""
    names = swap_names(load_model("seven-link"))
    assert names["heel_1"] == "heel_2" and names["toe_2"] == "toe_1"
    assert names["ankle_1"] == "ankle_2" and names["knee_2"] == "knee_1"
    assert names["foot_1"] == "foot_2" and names["torso"] == "torso"
    assert all(names[names[n]] == n for n in names)  # an involution


def test_the_record_interpolant_is_the_transcriptions_bit_for_bit() -> None:
    """:func:`cubic_hermite` (NumPy, the gait file's rule) and the transcription's
    ``HermiteSimpson.state_at`` do the same arithmetic: equal on identical inputs."""
    from gaitopt.gait.interpolation import cubic_hermite
    from gaitopt.ocp.hermite_simpson import HermiteSimpson

    rng = np.random.default_rng(3)
    s = rng.uniform(0.0, 1.0, (40, 1))
    h = rng.uniform(0.01, 0.2, (40, 1))
    x_k, x_k1, f_k, f_k1 = (rng.normal(size=(40, 7)) for _ in range(4))
    np.testing.assert_array_equal(cubic_hermite(s, x_k, x_k1, f_k, f_k1, h),
                                  HermiteSimpson().state_at(s, x_k, x_k1, f_k, f_k1, h))
