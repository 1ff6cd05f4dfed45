"""Figures build, render, and show the data they claim to show."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

from gaitopt.gait.record.file import Gait
from gaitopt.study.summary import SummaryRow, failed_row, variant_name
from gaitopt.viz.gait_figures import heights_figure, hip_motion_figure, torques_figure
from gaitopt.viz.stick import stick_strip_figure
from gaitopt.viz.style import png_bytes
from gaitopt.viz.sweep_figures import energy_figure, human_energy, step_length_figure
from tests.viz.synthetic import synthetic_cost, synthetic_gait, synthetic_step_length

SPEEDS = (3.0, 6.0, 12.0, 24.0, 48.0)


def _rows() -> list[SummaryRow]:
    rows = []
    for ankle in (True, False):
        for impulse in (True, False):
            for v in SPEEDS:
                rows.append(SummaryRow(
                    variant=variant_name(ankle=ankle, impulse=impulse), ankle=ankle,
                    impulse=impulse, speed_mode="fixed", speed_m_s=v / 60, speed_m_min=v,
                    step_length=synthetic_step_length(v), step_time=1.0,
                    cost=synthetic_cost(v, ankle=ankle, impulse=impulse), status="ok",
                    success=True, iterations=1, wall_time_s=0.1, file=""))
    rows.append(SummaryRow(variant="plain", ankle=False, impulse=False, speed_mode="free",
                           speed_m_s=0.2, speed_m_min=12.0, step_length=0.1, step_time=0.5,
                           cost=55.0, status="ok", success=True, iterations=1, wall_time_s=0.1,
                           file=""))
    rows.append(failed_row(ankle=True, impulse=False, speed_mode="fixed", status="failed",
                           speed_m_s=1.0))
    return rows


def _renders(fig: Figure) -> None:
    image = Image.open(io.BytesIO(png_bytes(fig, dpi=40)))
    pixels = np.asarray(image.convert("L"), dtype=float)
    assert pixels.std() > 10  # not a blank canvas


def _line(ax: object, gid: str) -> object:
    lines = [ln for ln in ax.get_lines() if ln.get_gid() == gid]  # type: ignore[attr-defined]
    assert len(lines) == 1, gid
    return lines[0]


def test_human_curve_has_its_minimum_at_80_m_min() -> None:
    v = np.linspace(20, 200, 1801)
    assert v[np.argmin(human_energy(v))] == pytest.approx(80.0, abs=0.1)
    assert human_energy(80.0) == pytest.approx(0.8)


def test_energy_figure_plots_each_variant_and_the_human_curve() -> None:
    rows = _rows()
    fig = energy_figure(rows)
    ax, human = fig.axes
    for ankle in (True, False):
        for impulse in (True, False):
            name = variant_name(ankle=ankle, impulse=impulse)
            line = _line(ax, f"variant:{name}")
            np.testing.assert_allclose(line.get_xdata(), SPEEDS)  # type: ignore[attr-defined]
            np.testing.assert_allclose(line.get_ydata(),  # type: ignore[attr-defined]
                                       [synthetic_cost(v, ankle=ankle, impulse=impulse)
                                        for v in SPEEDS])
    star = _line(ax, "optimum:plain")
    assert list(star.get_xdata()) == [12.0] and list(star.get_ydata()) == [55.0]  # type: ignore[attr-defined]
    (curve,) = human.get_lines()
    np.testing.assert_allclose(curve.get_ydata(), human_energy(curve.get_xdata()))
    assert curve.get_xdata()[0] == pytest.approx(3.0)
    assert "m/min" in ax.get_xlabel() and "cost" in ax.get_ylabel()
    assert "cal/kg/m" in human.get_ylabel()
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "ankle torques, no impulse (1 failed)" in legend  # failures are counted, not drawn
    assert any("human" in t for t in legend)
    _renders(fig)


def test_step_length_figure() -> None:
    fig = step_length_figure(_rows())
    (ax,) = fig.axes
    line = _line(ax, "variant:impulse")
    np.testing.assert_allclose(line.get_ydata(),  # type: ignore[attr-defined]
                               [synthetic_step_length(v) for v in SPEEDS])
    assert ax.get_ylabel() == "optimal step length  [m]"
    _renders(fig)


@pytest.fixture(scope="module")
def curves() -> list[tuple[str, Gait]]:
    return [("slow", synthetic_gait(speed=0.2, step_length=0.1, n_samples=41)),
            ("fast", synthetic_gait(speed=0.8, step_length=0.45, single_support_fraction=0.8,
                                    torque_amplitude=200.0, ankle=False, n_samples=41))]


def test_hip_motion_figure_shows_a_double_step(curves: list[tuple[str, Gait]]) -> None:
    fig = hip_motion_figure(curves)
    ax_s, ax_x, ax_v = fig.axes
    assert ax_s.get_gid() == "sticks"
    assert len([ln for ln in ax_s.get_lines() if ln.get_gid() == "leg_1"]) == 9  # t/T=0..2
    data = [ln for ln in ax_x.get_lines() if ln.get_label() in ("slow", "fast")]
    assert [ln.get_label() for ln in data] == ["slow", "fast"]
    for line, (_, gait) in zip(data, curves, strict=True):
        tau, dx = line.get_xdata(), line.get_ydata()
        assert tau[0] == 0.0 and tau[-1] == pytest.approx(2.0)
        # the hip advances two step lengths over the double step
        assert dx[-1] == pytest.approx(2 * gait.step_length)
    speeds = [ln.get_ydata() for ln in ax_v.get_lines() if ln.get_label() in ("slow", "fast")]
    np.testing.assert_allclose(speeds[0], 0.2, atol=1e-6)
    np.testing.assert_allclose(speeds[1], 0.8, atol=1e-6)
    events = sorted({ln.get_xdata()[0] for ln in ax_x.get_lines()
                     if ln.get_label().startswith("_child")
                     and len(set(ln.get_xdata())) == 1})
    np.testing.assert_allclose(events, [0.8, 0.85, 1.0, 1.8, 1.85])
    assert "normalized time" in ax_v.get_xlabel()
    _renders(fig)


def test_heights_figure_plots_hip_and_knees(curves: list[tuple[str, Gait]]) -> None:
    fig = heights_figure(curves)
    assert len(fig.axes) == 3
    _, gait = curves[0]
    stride = gait.stride_samples(2)
    for ax, name in zip(fig.axes, ("hip", "knee_1", "knee_2"), strict=True):
        (slow,) = [ln for ln in ax.get_lines() if ln.get_label() == "slow"]
        np.testing.assert_allclose(slow.get_ydata(), stride.points[name][:, 1])
    _renders(fig)


def test_torques_figure_has_one_panel_per_actuator_with_bounds(
        curves: list[tuple[str, Gait]]) -> None:
    fig = torques_figure(curves, title="Fig. 7")
    axes = [ax for ax in fig.axes if ax.get_visible()]
    names = [a.name for a in curves[0][1].model.actuators]
    assert [ax.get_title().split()[0] for ax in axes] == names
    for j, ax in enumerate(axes):
        lo, hi = curves[0][1].model.actuators[j].limits
        horizontal = {ln.get_ydata()[0] for ln in ax.get_lines()
                      if len(set(ln.get_ydata())) == 1 and len(ln.get_xdata()) == 2}
        assert {lo, hi} <= horizontal
        (fast,) = [ln for ln in ax.get_lines() if ln.get_label() == "fast"]
        np.testing.assert_allclose(fast.get_ydata(), curves[1][1].samples.u[:, j])
    hip = axes[0]
    # the fast gait saturates: its curve touches the bound, and the bound is in view
    assert hip.get_ylim()[1] >= curves[0][1].model.actuators[0].limits[1]
    _renders(fig)
    with pytest.raises(ValueError, match="styles"):
        torques_figure(curves, styles=[{}])
    with pytest.raises(ValueError, match="no gaits"):
        torques_figure([])


def test_stick_strip_draws_links_of_the_right_length(curves: list[tuple[str, Gait]]) -> None:
    _, gait = curves[1]
    fig = stick_strip_figure(gait, frames=5)
    (ax,) = fig.axes
    legs = [ln for ln in ax.get_lines() if ln.get_gid() in ("leg_1", "leg_2")]
    torsos = [ln for ln in ax.get_lines() if ln.get_gid() == "torso"]
    assert len(legs) == 10 and len(torsos) == 5
    for line in legs:
        xy = np.stack([line.get_xdata(), line.get_ydata()], axis=1)
        np.testing.assert_allclose(np.linalg.norm(np.diff(xy, axis=0), axis=1), [0.5, 0.5],
                                   atol=1e-2)  # thigh and shank (linear between samples)
    for line in torsos:
        assert np.hypot(np.diff(line.get_xdata()), np.diff(line.get_ydata()))[0] == \
            pytest.approx(0.72, abs=1e-2)
    _renders(fig)
    with pytest.raises(ValueError, match="frames"):
        stick_strip_figure(gait, frames=1)


def test_torques_figure_takes_gaits_with_fewer_actuators() -> None:
    """A gait whose model lacks actuators (the feet study's passive ankles) has no curve in
    their panels; every actuator of any gait has its panel."""
    import dataclasses

    from tests.viz.synthetic import synthetic_gait

    full = synthetic_gait(speed=0.4)
    model = full.model
    keep = [i for i, a in enumerate(model.actuators) if not a.name.startswith("ankle")]
    data = dict(full.model_data)
    data["actuators"] = [a for a in data["actuators"] if not a["name"].startswith("ankle")]
    data["name"] = "no-ankles"
    other = synthetic_gait(speed=0.5, ankle=False)
    passive = dataclasses.replace(
        other, model_data=data,
        samples=dataclasses.replace(other.samples, u=other.samples.u[:, keep]),
        phases=tuple(dataclasses.replace(ph, u=ph.u[:, keep]) for ph in other.phases))
    fig = torques_figure([("passive", passive), ("actuated", full)])
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title().split()[0] for ax in axes] == [a.name for a in model.actuators]
    for ax in axes:
        labels = {ln.get_label() for ln in ax.get_lines()}
        assert "actuated" in labels
        assert ("passive" in labels) == (not ax.get_title().startswith("ankle"))
    _renders(fig)
