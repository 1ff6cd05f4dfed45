"""GaitOptions in groups: construction by group or by flat keyword, the read-only shorthands,
``replace``, the gait file's flat options (old files included), and the knots per phase by
name (the walk's two, the heel-toe walk's four, a name the step lacks refused; ``--knots``)."""

from __future__ import annotations

import dataclasses
import inspect
import re
import typing
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from gaitopt.cli import cli
from gaitopt.cli.base import UserError, grid_choice, parse_phase_knots
from gaitopt.gait.formulations.select import biped_for, contact_sequence, problem_for
from gaitopt.gait.options import gait_options
from gaitopt.gait.options.gait_options import (
    FIELD_GROUPS,
    GROUPS,
    CostOptions,
    Discretisation,
    FlatOptions,
    GaitOptions,
    GaitOptionsError,
    Limits,
    SequenceOptions,
    SolverOptions,
    Targets,
    field_path,
    validate_options,
)
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.record.file import Gait
from gaitopt.gait.sequence.contact_sequence import phase_knots
from gaitopt.gait.sequence.knots import BUILTIN_PHASES
from gaitopt.robot import load_model

DATA = Path(__file__).resolve().parents[1] / "analysis" / "data"
HEEL_TOE = {"foot_flat": 24, "heel_off": 10, "double_support": 16, "heel_rocker": 12}


def checked(model_name: str, options: GaitOptions) -> GaitOptions:
    """``options`` resolved for the model and validated (as a solve does first)."""
    model = load_model(model_name)
    resolved = options_for_model(model, options)
    validate_options(resolved, biped_for(model, resolved))
    return resolved


# -- groups ----------------------------------------------------------------------------------

def test_six_groups_hold_every_option_once() -> None:
    assert list(GROUPS) == ["targets", "sequence", "limits", "objective", "discretisation",
                            "solver"]
    assert [f.name for f in dataclasses.fields(GaitOptions)] == list(GROUPS)
    assert len(FIELD_GROUPS) == 41
    flat = typing.get_type_hints(FlatOptions)
    assert set(flat) == set(FIELD_GROUPS)
    for name, group in FIELD_GROUPS.items():
        assert typing.get_type_hints(GROUPS[group])[name] == flat[name], name  # same types
        assert getattr(GaitOptions, name).__doc__ is not None  # a documented shorthand


def test_each_shorthand_is_declared_with_its_fields_type() -> None:
    """The shorthands are typed by hand for mypy (``speed = _Alias[float | None](
    "targets.speed")``): each names its own field and that field's annotation."""
    source = inspect.getsource(gait_options)
    declared = {m[0]: (m[1], m[2]) for m in re.findall(
        r"^    (\w+) = _Alias\[(.+?)\]\(\s*\"(\w+\.\w+)\"\)", source, flags=re.M | re.S)}
    assert set(declared) == set(FIELD_GROUPS) - {"knots"}  # knots: the counts, a property
    for name, (annotation, path) in declared.items():
        group = GROUPS[FIELD_GROUPS[name]]
        assert path == field_path(name), name
        assert annotation == {f.name: f.type for f in dataclasses.fields(group)}[name], name


def test_grouped_and_flat_construction_agree() -> None:
    by_group = GaitOptions(targets=Targets(speed=0.3, step_time=0.5),
                           objective=CostOptions(cost="work"),
                           solver=SolverOptions(tol=1e-6))
    flat = GaitOptions(speed=0.3, step_time=0.5, cost="work", tol=1e-6)
    assert by_group == flat
    assert flat.targets.speed == flat.speed == 0.3
    assert flat.objective.cost == flat.cost == "work"
    assert flat.solver.tol == 1e-6 and flat.sequence == SequenceOptions()
    # a flat keyword changes the given group's field; the group's other fields stay
    both = GaitOptions(targets=Targets(speed=0.3, step_time=0.5), speed=0.4)
    assert (both.speed, both.step_time) == (0.4, 0.5)
    assert GaitOptions() == GaitOptions(targets=Targets(), sequence=SequenceOptions(),
                                        limits=Limits(), objective=CostOptions(),
                                        discretisation=Discretisation(), solver=SolverOptions())


def test_unknown_keywords_and_wrong_groups_are_refused() -> None:
    with pytest.raises(TypeError, match="unknown option 'sped'; known: "):
        GaitOptions(sped=0.3)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="targets = .*must be a Targets"):
        GaitOptions(targets=Limits())  # type: ignore[arg-type]


def test_flat_attributes_are_read_only_shorthands() -> None:
    options = GaitOptions(speed=0.3, friction=0.8, knots=(12, 4))
    for name, group in FIELD_GROUPS.items():
        assert getattr(options, name) == getattr(getattr(options, group), name), name
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.speed = 0.5  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.targets.speed = 0.5  # type: ignore[misc]


def test_replace_takes_flat_keywords_and_groups() -> None:
    options = GaitOptions(speed=0.3, tol=1e-6)
    assert options.replace(speed=0.5).targets == Targets(speed=0.5)
    assert options.replace(speed=0.5).solver.tol == 1e-6
    assert dataclasses.replace(options, speed=0.5) == options.replace(speed=0.5)
    assert options.replace(limits=Limits(friction=0.7)).friction == 0.7
    assert options.replace(limits=Limits(friction=0.7)).speed == 0.3
    assert GaitOptions.paper(speed=0.1).knots == (8, 5)


def test_messages_name_the_grouped_path() -> None:
    model = load_model("five-link")
    for changes, path in (({"speed": -1.0}, "targets.speed = "),
                          ({"torso_bounds": (0.1, 0.5)}, "limits.torso_bounds = "),
                          ({"efficiency_positive": 0.0}, "objective.efficiency_positive = "),
                          ({"knots": (2, 5)}, "discretisation.knots = (2, 5)"),
                          ({"tol": 2.0}, "solver.tol = "),
                          ({"single_support_fraction": 1.2},
                           "sequence.single_support_fraction = ")):
        options = GaitOptions.paper(**changes)
        with pytest.raises(GaitOptionsError, match=path.replace("(", r"\(").replace(")", r"\)")):
            validate_options(options, biped_for(model, options))


# -- the gait file's options -----------------------------------------------------------------

def test_to_dict_is_flat_and_round_trips() -> None:
    options = GaitOptions(speed=0.3, friction=0.8,
                          knots={"single_support": 12, "double_support": 4})
    data = options.to_dict()
    assert list(data) == list(FIELD_GROUPS)
    assert data["knots"] == {"single_support": 12, "double_support": 4}
    assert GaitOptions.from_dict(data) == options
    assert GaitOptions.from_dict(GaitOptions().to_dict()).knots == (16, 6)


@pytest.mark.parametrize("name", ["five_link_12", "heel_toe_60", "seven_link_60"])
def test_gait_files_written_before_the_groups_still_load(name: str) -> None:
    gait = Gait.load(DATA / f"{name}.gait.json")
    saved = dict(gait.options)
    assert "targets" not in saved and isinstance(saved["knots"], list)  # the flat form
    options = GaitOptions.from_dict(saved)
    assert options.knots == tuple(saved["knots"])
    assert options.targets.speed == saved["speed"] and options.sequence.gait == saved["gait"]


def test_a_gait_file_with_knots_by_name_loads(tmp_path: Path) -> None:
    gait = Gait.load(DATA / "five_link_12.gait.json")
    named = dataclasses.replace(gait, options={**gait.options, "knots": {
        "single_support": 16, "double_support": 6}})
    named.save(tmp_path / "named.gait.json")
    again = Gait.load(tmp_path / "named.gait.json")
    assert again.options["knots"] == {"single_support": 16, "double_support": 6}
    assert GaitOptions.from_dict(dict(again.options)).knots == (16, 6)


# -- knots per phase by name ------------------------------------------------------------------

def test_knots_by_name_for_the_walk() -> None:
    named = GaitOptions(knots={"double_support": 6, "single_support": 16})
    assert named.knots == (16, 6)  # in phase order
    resolved = checked("five-link", named)
    assert resolved.knots == (16, 6)
    assert resolved.discretisation.knots == {"double_support": 6, "single_support": 16}
    counts = [ph.intervals + 1 for ph in problem_for(load_model("five-link"), resolved).phases]
    assert counts == [16, 6]
    # the tuple form keeps working
    assert checked("five-link", GaitOptions(knots=(16, 6))).knots == (16, 6)


def test_a_name_that_is_not_a_phase_is_refused_with_the_phase_names() -> None:
    options = GaitOptions(knots={"single": 16, "double": 6})
    message = "'single', 'double' are not phases of the step .*single_support, double_support"
    with pytest.raises(GaitOptionsError, match=message):
        checked("five-link", options)
    with pytest.raises(GaitOptionsError, match="missing: double_support"):
        checked("five-link", GaitOptions(knots={"single_support": 16}))
    # the single-support walk has one phase
    one = GaitOptions(single_support_fraction=1.0, knots={"single_support": 16})
    assert checked("five-link", one).knots == (16,)
    with pytest.raises(GaitOptionsError, match="'double_support' is not a phase"):
        checked("five-link", one.replace(knots={"single_support": 16, "double_support": 6}))


def test_knots_by_name_for_the_heel_toe_walk() -> None:
    assert BUILTIN_PHASES["heel-toe"] == tuple(HEEL_TOE)
    model = load_model("seven-link")
    options = checked("seven-link", GaitOptions(knots=HEEL_TOE))  # the gait from the names
    assert options.gait == "heel-toe" and options.knots == (24, 10, 16, 12)
    seq = contact_sequence(model, options)
    assert [ph.name for ph in seq.phases] == list(HEEL_TOE)
    assert phase_knots(seq, options.discretisation.knots) == (24, 10, 16, 12)
    assert phase_knots(seq, (24, 10, 16, 12)) == (24, 10, 16, 12)  # one count per phase
    assert phase_knots(seq, (24, 16))[0] == 24  # (first, others) as before
    counts = [ph.intervals + 1 for ph in problem_for(model, options).phases]
    assert counts == [24, 10, 16, 12]
    with pytest.raises(GaitOptionsError, match=r"'heel_strike' is not a phase of the step "
                                               r"\(its phases: foot_flat, heel_off, "
                                               r"double_support, heel_rocker\)"):
        checked("seven-link", GaitOptions(gait="heel-toe", knots={**HEEL_TOE,
                                                                  "heel_strike": 4}))
    with pytest.raises(GaitOptionsError, match="need >= 3 knots in the first phase"):
        checked("seven-link", GaitOptions(knots={**HEEL_TOE, "foot_flat": 2}))
    with pytest.raises(GaitOptionsError, match=r"must be two integers .*one per phase"):
        checked("seven-link", GaitOptions(gait="heel-toe", knots=(24, 16, 8)))


def test_stride_steps_take_the_knots_of_one_step() -> None:
    model = load_model("five-link")
    options = checked("five-link", GaitOptions(
        formulation="full", stride=True, knots={"single_support": 12, "double_support": 4}))
    assert phase_knots(contact_sequence(model, options), options.discretisation.knots) == (
        12, 4, 12, 4)


# -- the command line ------------------------------------------------------------------------

def test_knots_option_forms() -> None:
    assert parse_phase_knots("16,6") == (16, 6)
    assert parse_phase_knots("24,10,16,12") == (24, 10, 16, 12)
    assert parse_phase_knots("single_support=16, double_support=6") == {
        "single_support": 16, "double_support": 6}
    for bad in ("16", "16,x", "single_support=16,6", "=3,b=4", "a=1.5,b=2"):
        with pytest.raises(UserError, match="--knots"):
            parse_phase_knots(bad)
    assert grid_choice("single_support=16,double_support=6", None, False, by_phase=True) == {
        "knots": {"single_support": 16, "double_support": 6}}
    with pytest.raises(UserError, match="must be two integers 'single,double'"):
        grid_choice("single_support=16,double_support=6", None, False)  # a study's sweeps


def test_solve_refuses_a_knots_name_that_is_not_a_phase(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("a solve was started for a request that should be refused")

    monkeypatch.setattr("gaitopt.gait.solve.staged.transcription_for", refuse)
    result = CliRunner().invoke(cli, ["solve", "--knots", "single=16,double=6"])
    assert result.exit_code == 2, result.output
    assert "not phases of the step (its phases: single_support, double_support)" in " ".join(
        result.output.split())


@pytest.mark.slow
def test_a_heel_toe_walk_solves_on_knots_given_by_name() -> None:
    """About 2 minutes: every stage past the coarse ones on the named counts, the check grid
    1.5 times each, the file keeping the mapping (measured 2026-12-03: converged, 2381.5)."""
    from gaitopt import solve_gait

    knots = {"foot_flat": 12, "heel_off": 6, "double_support": 8, "heel_rocker": 5}
    gait = solve_gait("seven-link", GaitOptions(knots=knots, knot_spacing="uniform",
                                                accuracy=None))
    assert gait.success
    assert [(p.name, len(p.t)) for p in gait.phases] == list(knots.items())
    stages = {s["name"]: s["knots"] for s in gait.solver["stages"]}
    assert stages["target grid, all free"] == [12, 6, 8, 5]
    assert stages["check grid"] == [18, 9, 12, 8]
    assert gait.options["knots"] == knots
