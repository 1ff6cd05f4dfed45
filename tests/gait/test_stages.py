"""The staged solve as data: which stages run for which options, what each holds, and the
structure key of the transcription cache (derived from the option fields, none listed by hand
except those that only enter bounds). Fast: nothing is solved."""

from __future__ import annotations

import dataclasses

import pytest

from gaitopt.gait.formulations.step_parameters import FRACTION, IMPULSE, SPEED, parameter_bounds
from gaitopt.gait.options.gait_options import FIELD_GROUPS, GaitOptions
from gaitopt.gait.solve.stages import (
    ANKLES,
    COARSE_COMPLETION,
    COLD_CONTROL_MODEL,
    CONTROL_MODEL_STAGE,
    RELEASES,
    held_bounds,
)
from gaitopt.gait.solve.transcriptions import BOUNDS_ONLY_OPTIONS, NlpStructure
from gaitopt.robot import load_model

FIELDS = set(FIELD_GROUPS)


def _released(options: GaitOptions) -> list[str]:
    return [spec.name for spec in RELEASES if spec.runs(options)]


@pytest.mark.parametrize(("options", "names"), [
    (GaitOptions(), ["ankle torques free", "liftoff impulse free"]),
    (GaitOptions(speed=None), ["ankle torques free", "liftoff impulse free", "speed free"]),
    (GaitOptions(speed=None, ankle=False, impulse=False), ["speed free"]),
    (GaitOptions(ankle=False, impulse=False), []),
    (GaitOptions(formulation="full", single_support_fraction_bounds=(0.6, 0.95)),
     ["ankle torques free", "liftoff impulse free", "phase fractions free"]),
    (GaitOptions(formulation="full", free_phase_fractions=True, speed=None),
     ["ankle torques free", "liftoff impulse free", "phase fractions free", "speed free"]),
])
def test_the_release_stages_that_run_for_each_variant(options: GaitOptions,
                                                      names: list[str]) -> None:
    assert _released(options) == names


def test_each_release_frees_a_different_quantity() -> None:
    frees = [spec.frees for spec in RELEASES]
    assert None not in frees and len(set(frees)) == len(frees)
    assert set(frees) == {ANKLES, IMPULSE, FRACTION, SPEED}


def test_held_bounds_hold_exactly_what_is_asked() -> None:
    o = GaitOptions(speed=None, single_support_fraction_bounds=(0.6, 0.95))
    free = parameter_bounds(o)
    assert held_bounds(o, set(), 0.3) == free
    fractions = {"fraction_single_support": o.single_support_fraction}
    assert held_bounds(o, set(), 0.3, fractions=fractions) == free
    held = held_bounds(o, {SPEED, IMPULSE, FRACTION}, 0.3, fractions=fractions)
    assert held[SPEED] == (0.3, 0.3) and held[IMPULSE] == (0.0, 0.0)
    assert held["fraction_single_support"] == (o.single_support_fraction,) * 2
    assert held["step_length"] == free["step_length"]


def test_bounds_only_options_are_option_fields() -> None:
    assert BOUNDS_ONLY_OPTIONS <= FIELDS


def test_the_structure_key_changes_with_every_field_but_the_bounds_only_ones() -> None:
    """Changing any option field (to a sentinel: the key only reads values) changes the
    structure unless the field only enters bounds; so a new field shapes the NLP until it is
    listed in BOUNDS_ONLY_OPTIONS, never silently shares a transcription."""
    model = load_model("five-link")
    base = GaitOptions(cost="metabolic")  # a cost with kinks: its smoothing shapes the NLP
    key = NlpStructure.of(model, base, (8, 5), None)
    assert NlpStructure.of(model, GaitOptions(cost="metabolic"), (8, 5), None) == key
    for name in sorted(FIELDS):
        changed = NlpStructure.of(model, dataclasses.replace(base, **{name: object()}),
                                  (8, 5), None)
        if name in BOUNDS_ONLY_OPTIONS and name != "step_time":
            assert changed == key, name
        else:
            assert changed != key, name
    assert NlpStructure.of(model, base, (16, 6), None) != key
    assert NlpStructure.of(model, base, (8, 5), "codegen") != key
    # A smooth cost has nothing to smooth: the same NLP at any smoothing.
    paper = GaitOptions()
    assert NlpStructure.of(model, paper.replace(cost_smoothing=1.0), (8, 5), None) == \
        NlpStructure.of(model, paper, (8, 5), None)


@pytest.mark.parametrize(("options", "names"), [
    (GaitOptions(), ["control model jumps", "ankle torques free", "liftoff impulse free"]),
    (GaitOptions.paper(), ["ankle torques free", "liftoff impulse free"]),
    (GaitOptions(speed=None, ankle=False, impulse=False), ["control model jumps", "speed free"]),
])
def test_the_coarse_completion_switches_control_model_first(options: GaitOptions,
                                                            names: list[str]) -> None:
    """After the contact stages (always the paper's control model) the coarse solution is
    solved again in the requested control model, from its values only, before anything is
    freed; that stage frees nothing, so it holds what every release frees."""
    stages = [spec for spec in COARSE_COMPLETION if spec.runs(options)]
    assert [spec.title(options) for spec in stages] == names
    assert (CONTROL_MODEL_STAGE, *RELEASES) == COARSE_COMPLETION
    assert CONTROL_MODEL_STAGE.frees is None and CONTROL_MODEL_STAGE.values_only
    assert not any(spec.values_only for spec in RELEASES)
    assert CONTROL_MODEL_STAGE.runs(options) == (options.control_model != COLD_CONTROL_MODEL)
