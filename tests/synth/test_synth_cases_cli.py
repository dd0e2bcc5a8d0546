"""The ship-video cases (seawatch.synth.cases) and ``seawatch synth ship-video``
(seawatch.cli.synth_cmds) through a tiny Typer app: JSON summary and exit codes."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from seawatch.cli import synth_cmds
from seawatch.synth import CASES, Renderer, ship_video_case

app = typer.Typer()
app.add_typer(synth_cmds.app, name="synth")
runner = CliRunner()


def _truth_over_clip(name: str, frames: int = 26, fps: float = 2.5):
    """Truth (no drawing) at a 1920×1080 camera over a 10 s clip."""
    case = ship_video_case(name)
    r = Renderer(case.camera, case.ships, fps, sway=case.sway, seed=case.seed)
    return case, [r.truth(i)[1] for i in range(frames)]


@pytest.mark.parametrize("name", CASES)
def test_every_case_keeps_all_its_ships_in_view(name: str) -> None:
    case, truths = _truth_over_clip(name)
    ids = {s.object_id for s in case.ships}
    mid = truths[len(truths) // 2]
    assert {o.object_id for o in mid} == ids
    for objs in truths:
        for o in objs:
            assert 0.0 <= o.x and o.x + o.w <= 1919.5 and o.y >= -0.5 and o.y + o.h <= 1079.5
    assert case.camera.image_size == (1920, 1080) and case.camera.height == 15.0


def test_small_case_ship_is_a_few_pixels_high() -> None:
    _, truths = _truth_over_clip("small")
    heights = [o.h for objs in truths for o in objs]
    # 2.5 m of boat at 1.6 km seen with fy = 960 / tan(30°) = 1663 px: about 2.6 px
    assert 1.5 < min(heights) and max(heights) < 4.0


def test_large_case_ship_is_large() -> None:
    _, truths = _truth_over_clip("large")
    assert min(o.w for objs in truths for o in objs) > 120.0  # 150 m at 1.5 km: ~166 px


def test_meeting_case_occludes_the_farther_ship_at_the_meeting() -> None:
    _, truths = _truth_over_clip("meeting")
    vis = [min((o.visible for o in objs), default=1.0) for objs in truths]
    assert min(vis) < 0.8 and vis[0] == 1.0 and vis[-1] == 1.0  # apart, overlapping, apart


@pytest.mark.parametrize("name", ["overtaking", "crossing"])
def test_ships_swap_order_across_the_image(name: str) -> None:
    _, truths = _truth_over_clip(name)

    def centres(objs):
        return {o.object_id: o.x + o.w / 2 for o in objs}

    first, last = centres(truths[0]), centres(truths[-1])
    assert (first[1] < first[2]) != (last[1] < last[2])


def test_lighting_and_night_cases_use_their_lighting() -> None:
    lit = ship_video_case("lighting").lighting
    assert lit.glint == 1.0 and lit.sun_elevation > 0 and lit.cloud_shadows > 0
    assert ship_video_case("night").lighting.thermal


def test_cli_renders_a_case_and_prints_a_json_summary(tmp_path: Path) -> None:
    out = tmp_path / "small"
    args = ["synth", "ship-video", "--case", "small", "--out", str(out), "--json"]
    args += ["--duration", "0.4", "--fps", "10", "--width", "320", "--height", "180"]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["case"] == "small" and doc["frames"] == 4 and doc["objects"] == [1]
    assert (doc["width"], doc["height"]) == (320, 180)
    for key in ("video", "camera", "truth", "horizon"):
        assert Path(doc["outputs"][key]).is_file()
    assert doc["truth_rows"] == 4 and math.isfinite(doc["render_fps"]) and doc["crf"] == 20
    lines = Path(doc["outputs"]["horizon"]).read_text().splitlines()
    assert len(lines) == 5


def test_cli_bad_case_exits_2_naming_the_option(tmp_path: Path) -> None:
    res = runner.invoke(app, ["synth", "ship-video", "--case", "huge", "--out", str(tmp_path)])
    assert res.exit_code == 2
    msg = " ".join(res.output.split())
    assert "--case" in msg and "huge" in msg
    assert not (tmp_path / "video.mp4").exists()


@pytest.mark.parametrize(
    ("opt", "value"),
    [
        ("--width", "321"),
        ("--duration", "0"),
        ("--fps", "-5"),
        ("--crf", "52"),
        ("--pan-deg", "50"),
        ("--pan-period", "0"),
    ],
)
def test_cli_bad_numbers_exit_2(tmp_path: Path, opt: str, value: str) -> None:
    args = ["synth", "ship-video", "--case", "small", "--out", str(tmp_path), opt, value]
    res = runner.invoke(app, args)
    assert res.exit_code == 2
    assert opt in " ".join(res.output.split())


def test_unknown_case_raises_value_error() -> None:
    with pytest.raises(ValueError, match="case"):
        ship_video_case("tiny")
    with pytest.raises(ValueError, match="duration"):
        ship_video_case("small", duration=float("nan"))
    assert np.isfinite(ship_video_case("small", duration=30.0).ships[0].trajectory.end)
