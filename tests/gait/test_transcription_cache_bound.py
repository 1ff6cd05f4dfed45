"""The process-wide transcription cache keeps the process within its memory budget
(``$GAITOPT_MEMORY_MB``): a new transcription made while the process is over it drops the
least recently used others, and their memory goes back to the system; under it every
transcription is kept (sweeps reuse them)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from gaitopt import process_memory
from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.gait.solve import transcriptions as tc
from gaitopt.robot import load_model

PAPER = GaitOptions.paper()
#: Three structures of the compressed form (another NLP each), on the paper's small grid.
VARIANTS = [PAPER, PAPER.replace(ankle=False), PAPER.replace(impulse=False)]


@pytest.fixture
def fresh() -> Iterator[None]:
    tc.clear_cache()
    yield
    tc.clear_cache()


def _cached() -> list[object]:
    return list(tc._CACHE.values())


@pytest.mark.usefixtures("fresh")
def test_under_the_budget_every_transcription_is_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_MEMORY_MB", "1e9")
    model = load_model("five-link")
    made = [tc.transcription_for(model, o, o.knots) for o in VARIANTS]
    assert _cached() == made


@pytest.mark.usefixtures("fresh")
def test_over_the_budget_the_least_recently_used_go_first(
        monkeypatch: pytest.MonkeyPatch) -> None:
    model = load_model("five-link")
    monkeypatch.setenv("GAITOPT_MEMORY_MB", "1e9")
    a, b = (tc.transcription_for(model, o, o.knots) for o in VARIANTS[:2])
    assert tc.transcription_for(model, VARIANTS[0], PAPER.knots) is a  # a used again
    # A budget just above what the process holds with a and b minus one byte per entry: the
    # resident size is read, not estimated, so make it say "over" once, then "under".
    readings = iter([2, 0])
    monkeypatch.setattr(tc, "resident_bytes", lambda: next(readings))
    monkeypatch.setattr(tc, "memory_budget_bytes", lambda: 1)
    c = tc.transcription_for(model, VARIANTS[2], PAPER.knots)
    assert _cached() == [a, c]  # b, the least recently used, went first; then it was under
    # With the process always over its budget, only the newest is kept.
    monkeypatch.setattr(tc, "resident_bytes", lambda: 2)
    again = tc.transcription_for(model, VARIANTS[1], PAPER.knots)
    assert again is not b and again.layout.size == b.layout.size
    assert _cached() == [again]


@pytest.mark.usefixtures("fresh")
def test_a_dropped_transcription_gives_its_memory_back() -> None:
    """A compressed-form NLP of the full formulation, solved (its solver built), then dropped:
    the resident size falls back by most of what it grew."""
    model = load_model("five-link")
    process_memory.release_freed_memory()
    before = process_memory.resident_bytes()
    options = PAPER.replace(formulation="full")
    tr = tc.transcription_for(model, options, options.knots)
    tr.solve()  # building the solver takes the memory; the outcome does not matter here
    grown = process_memory.resident_bytes() - before
    assert grown > 20 * 2**20, grown  # tens of megabytes at least, or the test says nothing
    del tr
    tc.clear_cache()
    released = process_memory.resident_bytes() - before
    assert released < 0.5 * grown, (grown, released)


def test_the_budget_comes_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GAITOPT_MEMORY_MB", "100")
    assert process_memory.memory_budget_bytes() == 100 * 2**20
    for bad in ("-1", "lots", "inf", "0"):
        monkeypatch.setenv("GAITOPT_MEMORY_MB", bad)
        with pytest.warns(RuntimeWarning, match="GAITOPT_MEMORY_MB"):
            budget = process_memory.memory_budget_bytes()
        assert budget == process_memory.DEFAULT_BUDGET_MB * 2**20
