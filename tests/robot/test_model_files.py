"""Model files: round trips, defaults, and one clear error per kind of mistake."""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from gaitopt.robot import (
    ModelError,
    RobotModel,
    builtin_text,
    load_model,
    model_from_dict,
    model_from_yaml,
    model_to_dict,
    model_to_yaml,
)
from gaitopt.robot.inertia import ellipsoid_inertia, rod_inertia


def five_link_data() -> dict[str, Any]:
    data = yaml.safe_load(builtin_text("five-link"))
    assert isinstance(data, dict)
    return data


def minimal_data() -> dict[str, Any]:
    """A two-link pendulum-on-a-base written with as few fields as the schema allows."""
    return {
        "name": "mini",
        "links": [
            {"name": "body", "parent": None, "direction": "up", "length": 1.0, "mass": 2.0,
             "inertia": 0.3},
            {"name": "leg", "parent": "body", "direction": "down", "length": 0.8, "mass": 1.0,
             "shape": {"type": "rod"},
             "joint": {"name": "hip", "at": [0.0, 0.0], "limits": [-1.0, 1.0]}},
        ],
        "contacts": [{"name": "foot", "link": "leg"}],
        "actuators": [{"name": "hip", "joint": "hip", "limits": [-10, 10]}],
    }


# -- round trips ---------------------------------------------------------------------------

@pytest.mark.parametrize("make", [five_link_data, minimal_data])
def test_dict_and_yaml_round_trips_give_equal_models(make: Callable[[], dict[str, Any]]) -> None:
    model = model_from_dict(make())
    again = model_from_dict(model_to_dict(model))
    assert again == model and hash(again) == hash(model)
    assert model_to_dict(again) == model_to_dict(model)
    assert model_from_yaml(model_to_yaml(model)) == model
    assert model.content_hash() == again.content_hash()


def test_exported_dict_writes_every_default() -> None:
    d = model_to_dict(model_from_dict(minimal_data()))
    assert d["format"] == "gaitopt.model" and d["version"] == 1
    assert d["gravity"] == [0.0, -9.81]
    body, leg = d["links"]
    assert body["com"] == [0.5, 0.0] and leg["com"] == [0.4, 0.0]
    assert leg["inertia"] == pytest.approx(1.0 * 0.8**2 / 12) and leg["shape"] == {"type": "rod"}
    assert d["contacts"] == [{"name": "foot", "link": "leg", "at": [0.8, 0.0]}]


def test_written_file_loads_to_same_model(tmp_path: Path) -> None:
    model = load_model("five-link")
    path = tmp_path / "copy.yaml"
    path.write_text(model_to_yaml(model))
    assert load_model(path) == model
    assert load_model(str(path)) == model


def test_content_hash_changes_with_the_dynamics() -> None:
    data = five_link_data()
    base = model_from_dict(data).content_hash()
    data["links"][2]["mass"] = 4.5
    assert model_from_dict(data).content_hash() != base


def test_inertia_from_shapes() -> None:
    assert ellipsoid_inertia(20.0, 0.72, 0.12) == pytest.approx(0.576, rel=1e-15)
    assert rod_inertia(3.0, 2.0) == pytest.approx(1.0, rel=1e-15)
    leg = model_from_dict(minimal_data()).link("leg")
    assert leg.inertia == pytest.approx(1.0 * 0.8**2 / 12, rel=1e-15)


def test_inertia_and_shape_together_must_agree() -> None:
    data = five_link_data()
    data["links"][0]["inertia"] = 0.576
    assert model_from_dict(data).base.inertia == 0.576
    data["links"][0]["inertia"] = 0.6
    with pytest.raises(ModelError, match=r"links\[0\]\.inertia.*0\.6.*0\.576"):
        model_from_dict(data)


def test_optional_sections_may_be_absent_or_null() -> None:
    data = minimal_data()
    del data["contacts"], data["actuators"]
    data["description"] = None
    model = model_from_dict(data)
    assert model.contacts == () and model.actuators == () and model.description == ""


# -- errors: each names the file, the field path, the value and what is allowed ------------

Mutation = Callable[[dict[str, Any]], None]


def set_at(path: tuple[Any, ...], value: Any) -> Mutation:
    def mutate(d: dict[str, Any]) -> None:
        node: Any = d
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
    return mutate


def delete_at(path: tuple[Any, ...]) -> Mutation:
    def mutate(d: dict[str, Any]) -> None:
        node: Any = d
        for key in path[:-1]:
            node = node[key]
        del node[path[-1]]
    return mutate


def swap_first_links(d: dict[str, Any]) -> None:
    d["links"][0], d["links"][1] = d["links"][1], d["links"][0]


def rename_torso_x(d: dict[str, Any]) -> None:
    for link in d["links"]:
        if link["name"] == "torso":
            link["name"] = "x"
        if link["parent"] == "torso":
            link["parent"] = "x"


def massless_leaf(d: dict[str, Any]) -> None:
    """shank_2 (links[4], on knee_2) without mass: knee_2 moves nothing."""
    d["links"][4].update(mass=0.0, inertia=0.0)
    del d["links"][4]["shape"]


def point_mass_on_joint(d: dict[str, Any]) -> None:
    """shank_2 a point mass at its own joint: knee_2 moves it nowhere."""
    d["links"][4].update(com=[0.0, 0.0], inertia=0.0)
    del d["links"][4]["shape"]


# (id, mutation of five-link, field path, value as shown, text of what is allowed)
ERROR_CASES: list[tuple[str, Mutation, str, str, str]] = [
    ("unknown top key", set_at(("colour",), "red"), "colour", "'colour'", "the keys format"),
    ("unknown link key", set_at(("links", 1, "mas"), 7), "links[1].mas", "'mas'",
     "the keys name, parent, joint"),
    ("unknown joint key", set_at(("links", 2, "joint", "axis"), 1), "links[2].joint.axis",
     "'axis'", "the keys name, at, limits"),
    ("massless leaf", massless_leaf, "links[4].joint", "'knee_2'",
     "a model whose mass matrix is positive definite"),
    ("point mass on its joint", point_mass_on_joint, "links[4].joint", "'knee_2'",
     "a model whose mass matrix is positive definite"),
    ("negative mass", set_at(("links", 3, "mass"), -7), "links[3].mass", "-7",
     "a number >= 0 (kg)"),
    ("negative length", set_at(("links", 2, "length"), -0.5), "links[2].length", "-0.5",
     "a number > 0 (m)"),
    ("negative inertia", set_at(("links", 4, "inertia"), -0.1), "links[4].inertia", "-0.1",
     "a number >= 0 (kg m^2"),
    ("negative radius", set_at(("links", 0, "shape", "radius"), -0.12),
     "links[0].shape.radius", "-0.12", "a number > 0 (m)"),
    ("nan mass", set_at(("links", 1, "mass"), float("nan")), "links[1].mass", "nan",
     "a number >= 0 (kg)"),
    ("inf length", set_at(("links", 1, "length"), float("inf")), "links[1].length", "inf",
     "a number > 0 (m)"),
    ("-inf gravity", set_at(("gravity",), [0.0, float("-inf")]), "gravity[1]", "-inf",
     "a finite number"),
    ("huge int", set_at(("links", 1, "mass"), 10**400), "links[1].mass", "1000",
     "a number >= 0 (kg)"),
    ("text mass", set_at(("links", 1, "mass"), "heavy"), "links[1].mass", "'heavy'",
     "a number >= 0 (kg)"),
    ("bool length", set_at(("links", 1, "length"), True), "links[1].length", "True",
     "a number > 0 (m)"),
    ("1e3 as text", set_at(("links", 1, "mass"), "1e3"), "links[1].mass", "'1e3'",
     "write 1.0e+3"),
    ("missing parent", set_at(("links", 2, "parent"), "thigh_9"), "links[2].parent",
     "'thigh_9'", "the name of a link in this model (shank_1, shank_2, thigh_1"),
    ("cycle", set_at(("links", 1, "parent"), "shank_1"), "links[1].parent", "'shank_1'",
     "parents that lead to the floating base"),
    ("self parent", set_at(("links", 2, "parent"), "shank_1"), "links[2].parent",
     "'shank_1'", "parents that lead to the floating base"),
    ("child before parent", set_at(("links", 1, "parent"), "thigh_2"), "links[1].parent",
     "'thigh_2'", "a link listed before links[1]"),
    ("two bases", set_at(("links", 3, "parent"), None), "links", "['torso', 'thigh_2']",
     "exactly one floating base"),
    ("base not first", swap_first_links, "links[1].parent", "'torso' is link 1",
     "the floating base (parent: null) as the first link"),
    ("base named x", rename_torso_x, "links[0].name", "'x'",
     "a name other than x and y"),
    ("joint limits reversed", set_at(("links", 2, "joint", "limits"), [0.0, -2.5]),
     "links[2].joint.limits", "[0.0, -2.5]", "lower <= upper"),
    ("joint limits nan", set_at(("links", 2, "joint", "limits"), [float("nan"), 0.0]),
     "links[2].joint.limits[0]", "nan", "a finite number"),
    ("joint limits one number", set_at(("links", 2, "joint", "limits"), 1.0),
     "links[2].joint.limits", "1.0", "a list of two numbers [lower, upper] in rad"),
    ("actuator limits reversed", set_at(("actuators", 2, "limits"), [75, -75]),
     "actuators[2].limits", "[75.0, -75.0]", "lower <= upper"),
    ("contact on missing link", set_at(("contacts", 1, "link"), "foot_2"), "contacts[1].link",
     "'foot_2'", "the name of a link in this model"),
    ("contact at not a pair", set_at(("contacts", 0, "at"), [0.5]), "contacts[0].at", "[0.5]",
     "a list of two numbers [along, across] in m"),
    ("contact at inf", set_at(("contacts", 0, "at"), [0.5, float("inf")]), "contacts[0].at[1]",
     "inf", "a finite number"),
    ("actuator on missing joint", set_at(("actuators", 1, "joint"), "knee_3"),
     "actuators[1].joint", "'knee_3'", "the name of a joint in this model (hip_1, hip_2, knee_1"),
    ("actuator on missing contact", set_at(("actuators", 2, "contact"), "heel_1"),
     "actuators[2].contact", "'heel_1'", "the name of a contact in this model (tip_1, tip_2)"),
    ("actuator on joint and contact", set_at(("actuators", 0, "contact"), "tip_1"),
     "actuators[0]", "{'joint': 'hip_1', 'contact': 'tip_1'}", "exactly one of 'joint'"),
    ("two actuators on one joint", set_at(("actuators", 1, "joint"), "hip_1"),
     "actuators[1].joint", "'hip_1'", "a joint that no other actuator drives"),
    ("duplicate link name", set_at(("links", 3, "name"), "thigh_1"), "links[3].name",
     "'thigh_1'", "a link name not used by another link"),
    ("duplicate joint name", set_at(("links", 3, "joint", "name"), "hip_1"),
     "links[3].joint.name", "'hip_1'", "a joint name not used by another joint"),
    ("duplicate contact name", set_at(("contacts", 1, "name"), "tip_1"), "contacts[1].name",
     "'tip_1'", "a contact name not used by another contact"),
    ("duplicate actuator name", set_at(("actuators", 1, "name"), "hip_1"), "actuators[1].name",
     "'hip_1'", "an actuator name not used by another actuator"),
    ("joint named y", set_at(("links", 1, "joint", "name"), "y"), "links[1].joint.name", "'y'",
     "a name other than torso, x, y"),
    ("missing mass", delete_at(("links", 1, "mass")), "links[1].mass", "missing",
     "'mass' is required in a link"),
    ("missing joint", delete_at(("links", 1, "joint")), "links[1].joint", "missing",
     "a joint {name, at, limits}"),
    ("missing joint at", delete_at(("links", 2, "joint", "at")), "links[2].joint.at",
     "missing", "'at' is required in a joint"),
    ("missing inertia and shape", delete_at(("links", 1, "shape")), "links[1].inertia",
     "missing", "an 'inertia' (kg m^2, >= 0) or a 'shape'"),
    ("joint on base", set_at(("links", 0, "joint"), {"name": "j", "at": [0, 0],
                                                     "limits": [0, 1]}),
     "links[0].joint", "{'name': 'j'", "no joint (or null) on the floating base"),
    ("bad direction", set_at(("links", 1, "direction"), "sideways"), "links[1].direction",
     "'sideways'", "'up' or 'down'"),
    ("bad shape type", set_at(("links", 1, "shape"), {"type": "box", "radius": 1}),
     "links[1].shape.type", "'box'", "one of ellipsoid, rod"),
    ("rod with radius", set_at(("links", 1, "shape"), {"type": "rod", "radius": 0.1}),
     "links[1].shape.radius", "'radius'", "the keys type"),
    ("unknown major version", set_at(("version",), 2), "version", "2",
     "this gaitopt reads gaitopt.model version 1 only"),
    ("version as text", set_at(("version",), "1.0"), "version", "'1.0'", "1 (this gaitopt"),
    ("wrong format", set_at(("format",), "urdf"), "format", "'urdf'", "'gaitopt.model'"),
    ("links not a list", set_at(("links",), {"torso": 1}), "links", "{'torso': 1}",
     "a non-empty list of links"),
    ("empty links", set_at(("links",), []), "links", "[]", "a non-empty list of links"),
    ("link not a mapping", set_at(("links", 1), "thigh"), "links[1]", "'thigh'",
     "a mapping (key: value) describing a link"),
    ("contacts not a list", set_at(("contacts",), {}), "contacts", "{}", "a list of contact"),
    ("name a number", set_at(("name",), 5), "name", "5", "a non-empty printable text"),
    ("name with newline", set_at(("links", 1, "name"), "thigh\n1"), "links[1].name",
     "'thigh\\n1'", "a non-empty printable text without leading or trailing spaces"),
    ("odd unknown key", set_at(("links", 1, "the mass"), 7), "links[1]['the mass']",
     "'the mass'", "the keys name, parent"),
    ("gravity three numbers", set_at(("gravity",), [0, -9.81, 0]), "gravity",
     "[0, -9.81, 0]", "a list of two numbers [gx, gy] in m/s^2"),
    ("description with control character", set_at(("description",), "a\x85b"),
     "description", "'a\\x85b'", "printable characters, new lines and tabs"),
    ("shape inertia overflows", set_at(("links", 1, "length"), 1e200), "links[1].shape",
     "{'type': 'ellipsoid', 'radius': 0.07}", "a finite number >= 0 kg m^2, not inf"),
    ("com not a pair", set_at(("links", 2, "com"), 0.25), "links[2].com", "0.25",
     "a list of two numbers [along, across] in m"),
]


@pytest.mark.parametrize(("mutate", "path", "value", "allowed"),
                         [case[1:] for case in ERROR_CASES], ids=[c[0] for c in ERROR_CASES])
def test_error_names_file_path_value_and_allowed(tmp_path: Path, mutate: Mutation, path: str,
                                                 value: str, allowed: str) -> None:
    data = five_link_data()
    mutate(data)
    file = tmp_path / "bad-model.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(ModelError) as info:
        load_model(file)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{file}: {path}: "), message
    assert value in message, message
    assert "; allowed: " in message and allowed in message.split("; allowed: ", 1)[1], message
    assert info.value.source == str(file) and info.value.path == path


def test_dict_errors_say_dict_source() -> None:
    data = five_link_data()
    data["links"][1]["mass"] = -1
    with pytest.raises(ModelError, match=r"^<dict>: links\[1\]\.mass: got -1; allowed"):
        model_from_dict(data)


def test_the_valid_base_case_loads() -> None:
    # Guard for the table above: without the mutation, the data is valid.
    assert isinstance(model_from_dict(copy.deepcopy(five_link_data())), RobotModel)


@pytest.mark.parametrize(("text", "where", "problem"), [
    ("name: five\nlinks: [1, 2\n", "line 3, column 1", "not valid YAML: expected ',' or ']'"),
    ("name: a\n  links: b: c\n", "line 2, column 8", "not valid YAML: mapping values are not "
                                                     "allowed here"),
    ("when: 2001-13-01\n", None, "not valid YAML: month must be in 1..12"),
    ("\t- a\n", "line 1, column 1", "not valid YAML"),
])
def test_bad_yaml_is_one_line_with_position(tmp_path: Path, text: str, where: str | None,
                                            problem: str) -> None:
    file = tmp_path / "broken.yaml"
    file.write_text(text)
    with pytest.raises(ModelError) as info:
        load_model(file)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{file}: ")
    if where is not None:
        assert f"{file}: {where}: " in message, message
    assert problem in message and message.endswith("allowed: well-formed YAML")


@pytest.mark.parametrize(("content", "problem"), [
    (b"", "empty model"),
    (b"# only a comment\n", "empty model"),
    (b"[1, 2]\n", r"got \[1, 2\]; allowed: a mapping"),
    (b"\xff\xfe\x00garbage", "not UTF-8 text at byte 0"),
])
def test_unusable_files(tmp_path: Path, content: bytes, problem: str) -> None:
    file = tmp_path / "model.yaml"
    file.write_bytes(content)
    with pytest.raises(ModelError, match=problem) as info:
        load_model(file)
    assert str(info.value).startswith(str(file))


def test_missing_file_and_folder(tmp_path: Path) -> None:
    with pytest.raises(ModelError, match=r"nope\.yaml: no such file or built-in model; allowed:"
                                         r" a model file \(YAML\) or a built-in model name "
                                         r"\(adult-point-feet, five-link, seven-link\)"):
        load_model(tmp_path / "nope.yaml")
    with pytest.raises(ModelError, match="not a file"):
        load_model(tmp_path)
    with pytest.raises(ModelError, match="no such built-in model"):
        builtin_text("six-link")
