"""The sweep grid: points, continuation chains, file layout, settings (no solve)."""

from __future__ import annotations

import pytest

from gaitopt.gait.options.gait_options import GaitOptions
from gaitopt.robot import load_model
from gaitopt.study.driver import check_points
from gaitopt.study.plan import (
    SweepSpec,
    SweepSpecError,
    settings_differences,
    start_index,
    sweep_settings,
)
from gaitopt.study.summary import VARIANTS

MODEL = load_model("five-link")


def spec(**kw: object) -> SweepSpec:
    args: dict[str, object] = {"model": MODEL, "speeds": tuple(v / 60 for v in range(3, 61, 3))}
    args.update(kw)
    return SweepSpec(**args)  # type: ignore[arg-type]


def chain_from(s: SweepSpec, key: str) -> list[str]:
    """The keys from ``key`` back to its chain's cold start."""
    out = [key]
    while (parent := s.parents[out[-1]]) is not None:
        out.append(parent)
    return out


def test_chains_start_at_12_m_min_and_march_both_ways() -> None:
    s = spec(variants=("ankle",))
    speed = {p.key: p.speed for p in s.points}
    cold = [k for k, parent in s.parents.items() if parent is None]
    assert cold == ["gaits/ankle/speed-012.00m_min.gait.json"]
    # every fixed point's chain moves monotonically toward 12 m/min by one grid step
    for p in s.points:
        if p.speed is None:
            continue
        chain = [speed[k] for k in chain_from(s, p.key)]
        assert chain[-1] == pytest.approx(0.2)
        assert len(chain) == round(abs(p.speed - 0.2) * 60 / 3) + 1
        steps = [abs(a - b) * 60 for a, b in zip(chain, chain[1:], strict=False)]
        assert all(st == pytest.approx(3.0) for st in steps)
    free = "gaits/ankle/speed-free.gait.json"
    assert s.parents[free] == "gaits/ankle/speed-012.00m_min.gait.json"
    assert len(s.points) == 21


def test_impulse_chains_start_from_their_variant_without_the_impulse() -> None:
    """With ``impulse_from_no_impulse`` each impulse variant's start point continues from the
    same point of its variant without the impulse (the same ankle torques), which starts
    cold; every other parent is the chain's. Without chains (the check sweep) it does
    nothing, and only a sweep that uses it says so in its settings."""
    plain = spec()
    s = spec(impulse_from_no_impulse=True)
    start = "speed-012.00m_min.gait.json"
    cold = sorted(k for k, parent in s.parents.items() if parent is None)
    assert cold == [f"gaits/ankle/{start}", f"gaits/plain/{start}"]
    assert s.parents[f"gaits/ankle+impulse/{start}"] == f"gaits/ankle/{start}"
    assert s.parents[f"gaits/impulse/{start}"] == f"gaits/plain/{start}"
    changed = {k for k in s.parents if s.parents[k] != plain.parents[k]}
    assert changed == {f"gaits/ankle+impulse/{start}", f"gaits/impulse/{start}"}
    assert sweep_settings(s)["impulse_from_no_impulse"] is True
    assert "impulse_from_no_impulse" not in sweep_settings(plain)
    alone = spec(impulse_from_no_impulse=True, continuation=False)
    assert all(parent is None for parent in alone.parents.values())
    assert "impulse_from_no_impulse" not in sweep_settings(alone)
    only = spec(impulse_from_no_impulse=True, variants=("ankle+impulse", "impulse"))
    assert sum(parent is None for parent in only.parents.values()) == 2  # none to start from


def test_ankle_impulse_points_start_from_the_ankle_points_of_their_speed() -> None:
    """With ``ankle_impulse_from_ankle`` every point with ankle torques and the impulse (the
    speed-free one too) starts from the same point with ankle torques only, in a sweep with
    chains or without (the check and refinement sweeps); the other variants keep their
    parents, a point whose twin is not in the sweep too, and the settings say so."""
    def twin(key: str) -> str:
        return key.replace("gaits/ankle+impulse/", "gaits/ankle/")

    for chains in (True, False):
        before = spec(continuation=chains, impulse_from_no_impulse=True)
        s = spec(continuation=chains, impulse_from_no_impulse=True,
                 ankle_impulse_from_ankle=True)
        for p in s.points:
            expected = twin(p.key) if p.variant == "ankle+impulse" else before.parents[p.key]
            assert s.parents[p.key] == expected
        assert sweep_settings(s)["ankle_impulse_from_ankle"] is True
        assert "ankle_impulse_from_ankle" not in sweep_settings(before)
        # every chain still ends in a cold start
        assert all(chain_from(s, p.key) for p in s.points)
    alone = spec(ankle_impulse_from_ankle=True, variants=("ankle+impulse", "impulse"))
    assert alone.parents == spec(variants=("ankle+impulse", "impulse")).parents


def test_start_is_the_speed_nearest_12_m_min() -> None:
    assert start_index([0.05, 0.1, 0.15]) == 2
    assert start_index([0.3, 0.5]) == 0
    assert start_index([0.15, 0.25]) == 0  # a tie goes to the lower speed
    s = spec(speeds=(0.1, 0.35, 0.5), variants=("plain",))
    cold = [k for k, parent in s.parents.items() if parent is None]
    assert cold == ["gaits/plain/speed-006.00m_min.gait.json"]


def test_one_chain_set_per_variant_and_axis_combination_in_subfolders() -> None:
    s = spec(speeds=(0.1, 0.2), step_lengths=(None, 0.1), single_support=(0.85, 1.0),
             free_speed=False)
    assert s.nested and len(s.points) == 4 * 2 * 2 * 2
    keys = {p.key for p in s.points}
    assert len(keys) == len(s.points)
    assert "single-support-1_step-0.1m/gaits/plain/speed-006.00m_min.gait.json" in keys
    assert "single-support-0.85_step-free/gaits/ankle+impulse/speed-012.00m_min.gait.json" \
        in keys
    # a chain never crosses a group: parent and child share variant and axes
    by_key = {p.key: p for p in s.points}
    for key, parent in s.parents.items():
        if parent is not None:
            assert by_key[key].group == by_key[parent].group
    assert sum(parent is None for parent in s.parents.values()) == 16
    opts = s.options(by_key["single-support-1_step-0.1m/gaits/plain/speed-006.00m_min.gait.json"])
    assert (opts.speed, opts.step_length, opts.single_support_fraction, opts.ankle,
            opts.impulse) == (0.1, 0.1, 1.0, False, False)


def test_a_step_time_axis_fixes_the_step_length_through_the_speed() -> None:
    s = spec(speeds=(0.15, 0.2), step_times=(0.5, 0.7), variants=("plain",))
    assert s.nested and len(s.points) == 2 * 3
    by_key = {p.key: p for p in s.points}
    point = by_key["single-support-0.85_step-time-0.7s/gaits/plain/speed-012.00m_min.gait.json"]
    opts = s.options(point)
    assert (opts.speed, opts.step_time, opts.step_length) == (0.2, 0.7, None)
    free = by_key["single-support-0.85_step-time-0.5s/gaits/plain/speed-free.gait.json"]
    assert s.options(free).speed is None and s.options(free).step_time == 0.5
    assert sweep_settings(s)["step_times"] == [0.5, 0.7]
    # A sweep without step times writes the settings it always wrote (old sweeps resume).
    assert "step_times" not in sweep_settings(spec(speeds=(0.2,)))
    # A step time whose step length at some speed leaves the bounds is refused up front.
    with pytest.raises(SweepSpecError, match="step_time = 5 s: with the speed"):
        check_points(spec(speeds=(0.2,), step_times=(5.0,)))


def test_plain_layout_matches_the_report_layout() -> None:
    s = spec(speeds=(0.2,))
    assert not s.nested
    assert [p.key for p in s.points if p.variant == "ankle+impulse"] == [
        "gaits/ankle+impulse/speed-012.00m_min.gait.json",
        "gaits/ankle+impulse/speed-free.gait.json"]
    assert tuple(dict.fromkeys(p.variant for p in s.points)) == VARIANTS


@pytest.mark.parametrize(("kw", "message"), [
    ({"speeds": ()}, "at least one speed"),
    ({"speeds": (0.2, 0.1)}, "ascending"),
    ({"speeds": (-0.1, 0.2)}, "not a positive speed"),
    ({"speeds": (0.2, 0.2 + 1e-5)}, "same file name"),
    ({"variants": ("ankle", "walking")}, "unknown variant 'walking'"),
    ({"variants": ()}, "at least one of"),
    ({"single_support": (0.85, 0.85)}, "each at most once"),
    ({"step_times": (0.5, 0.5)}, "step times: at least one, each at most once"),
    ({"step_times": (-0.5,)}, "not a positive time"),
    ({"step_times": (0.5,), "step_lengths": (0.1,)}, "give one of them"),
])
def test_bad_grids_are_refused_with_the_setting_named(kw: dict[str, object],
                                                      message: str) -> None:
    with pytest.raises(SweepSpecError, match=message):
        spec(**kw)


def test_every_point_is_validated_before_any_solve() -> None:
    # (a given speed is not checked against speed_bounds; a step it cannot reach is)
    with pytest.raises(SweepSpecError, match=r"plain .*120.00 m/min: targets.step_time = 1 s"):
        check_points(spec(speeds=(0.2, 2.0), step_times=(1.0,), variants=("plain",)))
    with pytest.raises(SweepSpecError, match="step_length = 3 m: longer than the legs"):
        check_points(spec(speeds=(0.2,), step_lengths=(3.0,)))


def test_settings_differences_name_each_changed_field() -> None:
    a = sweep_settings(spec())
    assert settings_differences(a, sweep_settings(spec())) == []
    b = sweep_settings(spec(speeds=(0.2,), base=GaitOptions(tol=1e-6)))
    diffs = settings_differences(a, b)
    assert any(d.startswith("speeds_m_min:") for d in diffs)
    assert any(d.startswith("options.tol:") for d in diffs)
    assert len(diffs) == 2
    assert a["model"]["content_hash"] == MODEL.content_hash()


def test_secant_steps_reach_two_points_back_along_their_own_chain() -> None:
    """With ``secant`` a fixed-speed point two or more steps from its chain's start names the
    point before its parent and the step ratio; the chain's first step, the speed-free points,
    a start from another variant and a sweep without it name none."""
    s = spec(speeds=tuple(v / 60 for v in (6, 12, 24, 30, 36)), impulse_from_no_impulse=True,
             secant=True)
    key = {(p.variant, None if p.speed is None else round(p.speed * 60)): p.key
           for p in s.points}
    # chains start at 12 m/min: 24 -> 30 -> 36 upward, 6 downward
    assert s.secant_step(key["ankle", 30]) == (key["ankle", 12], pytest.approx(0.5))
    assert s.secant_step(key["ankle", 36]) == (key["ankle", 24], pytest.approx(1.0))
    assert s.secant_step(key["impulse", 36]) == (key["impulse", 24], pytest.approx(1.0))
    for k in (key["ankle", 24], key["ankle", 6], key["ankle", 12], key["ankle", None],
              key["impulse", 24]):  # impulse 24 m/min: its chain's start came from plain
        assert s.secant_step(k) is None
    assert spec(speeds=s.speeds).secant_step(key["ankle", 36]) is None
    assert sweep_settings(s)["secant"] is True
    assert "secant" not in sweep_settings(spec(speeds=s.speeds))


def test_check_cold_is_a_setting_of_the_sweep_only_when_off() -> None:
    # sweep.json of a sweep whose cold starts skip their check grid says so; a sweep with
    # the default (every folder written before the field existed) does not change.
    assert "check_cold" not in sweep_settings(spec())
    assert sweep_settings(spec(check_cold=False))["check_cold"] is False
