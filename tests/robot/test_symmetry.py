"""Left/right symmetry: inferred from the legs, or declared in the model file and checked."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.robot import ModelError, load_model, model_from_dict
from gaitopt.robot.symmetry import SymmetryError, model_symmetry, swap_permutations


def _five_link() -> dict[str, Any]:
    return copy.deepcopy(load_model("five-link").to_dict())


def _with_feet() -> dict[str, Any]:
    """Heel and toe points on each shank, listed heel 1, toe 1, heel 2, toe 2: the first two
    contacts are on one leg, so no symmetry can be inferred."""
    data = _five_link()
    data["contacts"] = [{"name": f"{kind}_{i}", "link": f"shank_{i}", "at": [0.5, x]}
                        for i in (1, 2) for kind, x in (("heel", -0.03), ("toe", 0.1))]
    data["actuators"] = [a for a in data["actuators"] if "joint" in a]
    return data


def test_five_link_symmetry_is_inferred_from_the_legs() -> None:
    model = load_model("five-link")
    sym = model_symmetry(model)
    assert sym.source == "inferred"
    assert sym.links == (("thigh_1", "thigh_2"), ("shank_1", "shank_2"))
    assert sym.contacts == (("tip_1", "tip_2"),)
    perm_q, perm_u = swap_permutations(model)
    # q = [x, y, torso, hip_1, knee_1, hip_2, knee_2]; u = [hip, knee, ankle] x 2
    np.testing.assert_array_equal(perm_q, [0, 1, 2, 5, 6, 3, 4])
    np.testing.assert_array_equal(perm_u, [3, 4, 5, 0, 1, 2])


def test_declared_symmetry_loads_round_trips_and_matches() -> None:
    data = _five_link()
    data["symmetry"] = {"links": [["thigh_1", "thigh_2"], ["shank_1", "shank_2"]],
                        "contacts": [["tip_1", "tip_2"]]}
    model = model_from_dict(data)
    assert model_symmetry(model).source == "declared"
    assert model_from_dict(model.to_dict()) == model
    for a, b in zip(swap_permutations(model), swap_permutations(load_model("five-link")),
                    strict=True):
        np.testing.assert_array_equal(a, b)
    # A model without a declaration keeps the hash it had before symmetry existed.
    assert "symmetry" not in load_model("five-link").to_dict()


def test_a_declaration_makes_a_model_with_feet_symmetric() -> None:
    data = _with_feet()
    with pytest.raises(SymmetryError, match="declare it in the model file"):
        model_symmetry(model_from_dict(data))
    data["symmetry"] = {"links": [["thigh_1", "thigh_2"], ["shank_1", "shank_2"]],
                        "contacts": [["heel_1", "heel_2"], ["toe_1", "toe_2"]]}
    model = model_from_dict(data)
    perm_q, _ = swap_permutations(model)
    np.testing.assert_array_equal(perm_q, [0, 1, 2, 5, 6, 3, 4])


@pytest.mark.parametrize(("symmetry", "message"), [
    ({"contacts": [["tip_1", "foot"]]}, r"symmetry.contacts\[0\]: got \['tip_1', 'foot'\]"),
    ({"links": [["thigh_1", "thigh_1"]], "contacts": []}, "two different links"),
    ({"links": [["thigh_1", "thigh_2"], ["thigh_2", "shank_1"]], "contacts": []},
     "'thigh_2' is already paired"),
    ({"links": [["thigh_1", "shank_2"]], "contacts": []},
     "pairs 'thigh_1' with 'shank_2', but their parents"),
    ({"links": [], "contacts": [["tip_1", "tip_2"]]},
     "pairs contacts 'tip_1' and 'tip_2', but their links are not a pair"),
])
def test_bad_declarations_are_refused_by_name(symmetry: dict[str, Any], message: str) -> None:
    data = _five_link()
    data["symmetry"] = symmetry
    with pytest.raises(ModelError, match=message):
        model_from_dict(data)


def test_model_show_says_what_it_inferred() -> None:
    out = CliRunner(env={"COLUMNS": "200"}).invoke(cli, ["model", "show", "five-link"])
    assert out.exit_code == 0
    assert "thigh_1 <-> thigh_2" in out.output and "inferred" in out.output
