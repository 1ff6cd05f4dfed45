"""summary.csv: writing, reading back, and errors naming line and column."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from gaitopt.study.summary import (
    SUMMARY_COLUMNS,
    VARIANTS,
    SummaryError,
    SummaryRow,
    failed_row,
    gait_relpath,
    read_summary,
    summary_row,
    variant_flags,
    variant_name,
    write_summary,
)
from tests.viz.synthetic import synthetic_gait


def test_variant_names_cover_the_four_combinations() -> None:
    names = {variant_name(ankle=a, impulse=i) for a in (True, False) for i in (True, False)}
    assert names == set(VARIANTS)
    for name in VARIANTS:
        ankle, impulse = variant_flags(name)
        assert variant_name(ankle=ankle, impulse=impulse) == name
    with pytest.raises(ValueError, match="unknown variant"):
        variant_flags("feet")


def test_gait_paths() -> None:
    assert gait_relpath(ankle=True, impulse=True, speed_mode="fixed", speed_m_s=0.2) == \
        "gaits/ankle+impulse/speed-012.00m_min.gait.json"
    assert gait_relpath(ankle=False, impulse=False, speed_mode="free") == \
        "gaits/plain/speed-free.gait.json"
    with pytest.raises(ValueError, match="speed_m_s"):
        gait_relpath(ankle=False, impulse=False, speed_mode="fixed")


def test_rows_round_trip_through_csv(tmp_path: Path) -> None:
    gait = synthetic_gait(speed=0.25, step_length=0.2)
    rows = [summary_row(gait, ankle=True, impulse=False, speed_mode="fixed", file="gaits/a.json"),
            failed_row(ankle=False, impulse=True, speed_mode="free", status="Infeasible",
                       iterations=300)]
    path = write_summary(tmp_path / "summary.csv", rows)
    header = path.read_text().splitlines()[0]
    assert header == ",".join(SUMMARY_COLUMNS)
    back = read_summary(path)
    assert back[0] == rows[0]
    assert back[0].speed_m_min == pytest.approx(15.0)
    assert back[0].cost == gait.cost_value  # repr round trip is exact
    failed = back[1]
    assert not failed.success and failed.status == "Infeasible" and failed.iterations == 300
    assert math.isnan(failed.cost) and math.isnan(failed.speed_m_s) and failed.file == ""


@pytest.mark.parametrize(("change", "words"), [
    (lambda t: t.replace("variant,", "name,", 1), "missing columns variant"),
    (lambda t: t.replace(",true,", ",maybe,", 1), "line 2: column ankle: expected true or false"),
    (lambda t: t.replace(",fixed,", ",sometimes,", 1), "line 2: speed_mode"),
    (lambda t: t.replace("ankle,true,false", "plain,true,false", 1), "line 2: variant 'plain'"),
])
def test_bad_tables_name_the_line_and_column(tmp_path: Path, change: object,
                                              words: str) -> None:
    row = SummaryRow(variant="ankle", ankle=True, impulse=False, speed_mode="fixed",
                     speed_m_s=0.2, speed_m_min=12.0, step_length=0.1, step_time=0.5, cost=3.0,
                     status="ok", success=True, iterations=4, wall_time_s=0.1, file="x")
    path = write_summary(tmp_path / "summary.csv", [row])
    path.write_text(change(path.read_text()))  # type: ignore[operator]
    with pytest.raises(SummaryError, match=words.replace("(", r"\(")) as info:
        read_summary(path)
    assert str(path) in str(info.value)


def test_bad_number_and_missing_file(tmp_path: Path) -> None:
    row = failed_row(ankle=True, impulse=True, speed_mode="fixed", status="x", speed_m_s=0.1)
    path = write_summary(tmp_path / "s.csv", [row])
    path.write_text(path.read_text().replace(",0.1,", ",fast,"))
    with pytest.raises(SummaryError, match="column speed_m_s: expected a number, got 'fast'"):
        read_summary(path)
    with pytest.raises(SummaryError, match="cannot read"):
        read_summary(tmp_path / "none.csv")
