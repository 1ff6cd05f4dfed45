"""Each formulation is one object behind one protocol, picked in one place
(:func:`gaitopt.gait.formulation.formulation_of`): no other module compares
``formulation`` with a formulation's name (docs/architecture.md, "The formulations")."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from gaitopt.gait.formulation import FORMULATIONS, FULL, REDUCED, formulation_of
from gaitopt.gait.formulation_traits import FORMULATION_TRAITS
from gaitopt.gait.options import FORMULATIONS as OPTION_FORMULATIONS
from gaitopt.gait.options import GaitOptions

SRC = Path(__file__).resolve().parents[2] / "src" / "gaitopt"
#: The modules that may name a formulation: the selection and the traits table.
SELECTION = {SRC / "gait" / "formulation.py", SRC / "gait" / "formulation_traits.py"}


def names_formulation(node: ast.expr) -> bool:
    return (isinstance(node, ast.Attribute) and node.attr == "formulation") or (
        isinstance(node, ast.Name) and node.id == "formulation")


def formulation_names(node: ast.expr) -> set[str]:
    """The formulation names a literal holds (a string, or a tuple/list/set of them)."""
    items = node.elts if isinstance(node, ast.Tuple | ast.List | ast.Set) else [node]
    return {e.value for e in items
            if isinstance(e, ast.Constant) and e.value in FORMULATION_TRAITS}


def test_nothing_outside_the_selection_branches_on_the_name() -> None:
    offences = []
    for path in sorted(SRC.rglob("*.py")):
        if path in SELECTION:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Compare):
                continue
            sides = [node.left, *node.comparators]
            if any(names_formulation(s) for s in sides) and any(
                    formulation_names(s) for s in sides):
                offences.append(f"{path.relative_to(SRC.parent)}:{node.lineno}")
    assert not offences, ("formulation compared with a name (ask formulation_of(options) "
                          "instead): " + ", ".join(offences))


def test_one_object_and_one_traits_entry_per_formulation() -> None:
    assert tuple(FORMULATIONS) == tuple(FORMULATION_TRAITS) == OPTION_FORMULATIONS
    for name, formulation in FORMULATIONS.items():
        assert formulation.traits is FORMULATION_TRAITS[name]


@pytest.mark.parametrize(("name", "expected"), [("reduced", REDUCED), ("full", FULL)])
def test_formulation_of_picks_the_named_object(name: str, expected: object) -> None:
    assert formulation_of(GaitOptions(formulation=name)) is expected  # type: ignore[arg-type]
