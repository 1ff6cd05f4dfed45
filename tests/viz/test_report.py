"""The HTML report: self-contained, complete, and rendered by a real browser."""

from __future__ import annotations

import base64
import io
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from gaitopt.study.summary import SummaryError
from gaitopt.viz.report import ReportInfo, write_report
from tests.viz.synthetic import synthetic_sweep

STEMS = ("fig3_energy", "fig4_step_length", "fig5_hip_motion", "fig6_heights",
         "fig7_torques_no_impulse", "fig8_torques_impulse", "stick_ankle-impulse",
         "stick_ankle", "stick_impulse", "stick_plain")


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> ReportInfo:
    root = tmp_path_factory.mktemp("report")
    synthetic_sweep(root / "sweep", speeds_m_min=(3, 6, 12, 24, 50), n_samples=31)
    return write_report(root / "sweep", root / "out")


def test_report_writes_every_figure_as_png_and_svg(report: ReportInfo) -> None:
    out = report.html.parent
    for stem in STEMS:
        assert (out / f"{stem}.png").stat().st_size > 5000, stem
        assert (out / f"{stem}.svg").read_text().lstrip().startswith("<?xml"), stem
    assert report.problems == ()


def test_report_html_is_self_contained(report: ReportInfo) -> None:
    page = report.html.read_text()
    assert "http://" not in page and "https://" not in page
    assert not re.search(r"<(link|script|iframe)\b", page)
    sources = re.findall(r"<img [^>]*src='([^']*)'", page)
    assert len(sources) == len(STEMS)
    for src in sources:
        assert src.startswith("data:image/png;base64,")
        with Image.open(io.BytesIO(base64.b64decode(src.split(",", 1)[1]))) as image:
            assert image.format == "PNG" and image.size[0] > 300


def test_report_sections_carry_our_numbers_beside_the_papers(report: ReportInfo) -> None:
    page = report.html.read_text()
    for heading in ("Energy-optimal walk of each variant", "Solver statistics",
                    "Orbital stability of the optimal gaits",
                    "Findings of the paper, checked", "All sweep points"):
        assert heading in page
    assert "<td>ankle+impulse</td><td>12.2</td>" in page  # speed-free optimum, m/min
    assert "paper (all variants)" in page
    for paper_number in ("568,635", "43,430", "249,928", "230,952", "8,497", "125,099",
                         "18 min", "12 min"):
        assert paper_number in page
    assert "1,234" in page and "ours: plain optimum (8+5 knots)" in page
    assert page.count(">holds<") == 8


def test_report_lists_unreadable_gait_files(tmp_path: Path) -> None:
    rows = synthetic_sweep(tmp_path / "sweep", speeds_m_min=(6, 12, 50), n_samples=21)
    broken = next(r for r in rows if r.variant == "plain" and r.speed_mode == "free")
    (tmp_path / "sweep" / broken.file).write_text("{not json")
    info = write_report(tmp_path / "sweep", tmp_path / "out", svg=False)
    assert not list((tmp_path / "out").glob("*.svg"))
    assert len(info.problems) == 1 and broken.file in info.problems[0]
    assert "not valid JSON" in info.html.read_text()
    with pytest.raises(SummaryError, match="summary.csv"):
        write_report(tmp_path / "nothing", tmp_path / "out2")


def _chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(_chromium() is None, reason="chromium is not installed")
def test_report_renders_in_headless_chromium(report: ReportInfo, tmp_path: Path) -> None:
    shot = tmp_path / "shot.png"
    subprocess.run([str(_chromium()), "--headless", "--no-sandbox", "--disable-gpu",
                    "--hide-scrollbars", "--window-size=1200,2000", f"--screenshot={shot}",
                    report.html.resolve().as_uri()],
                   check=True, capture_output=True, timeout=120)
    with Image.open(shot) as image:
        pixels = np.asarray(image.convert("L"), dtype=float)
    assert pixels.shape == (2000, 1200)
    dark = np.mean(pixels < 128)
    assert 0.01 < dark < 0.5  # text, tables and figures drawn; not blank, not black
    # the lower part of the window shows figures (many grey levels), not an empty page
    assert len(np.unique(pixels[1000:].astype(int))) > 50


def test_gait_figures_of_a_few_gaits(tmp_path: Path) -> None:
    from gaitopt.viz.report import write_gait_figures
    from tests.viz.synthetic import synthetic_gait

    curves = [("a", synthetic_gait(n_samples=21)), ("b", synthetic_gait(speed=0.3, n_samples=21))]
    paths = write_gait_figures(curves, tmp_path, svg=False)
    assert sorted(p.name for p in paths) == ["heights.png", "hip_motion.png", "stick_1.png",
                                             "stick_2.png", "torques.png"]
    assert all(p.stat().st_size > 5000 for p in paths)
    with pytest.raises(ValueError, match="no gaits"):
        write_gait_figures([], tmp_path)
