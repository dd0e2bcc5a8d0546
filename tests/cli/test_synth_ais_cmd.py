"""``seawatch synth ais`` (seawatch.cli.synth_cmds) through a tiny Typer app: the JSON
summary and clip.json of a short clip, the defaults (demo camera and clip, busiest
window), and exit code 2 naming the bad input.

Data: the packaged Solent AIS file (Stone Soup, MIT; seawatch/data/README.md).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from seawatch.camera import PinholeCamera
from seawatch.cli import synth_cmds
from seawatch.io import save_camera
from seawatch.scenarios.solent_ais import default_ais_path
from seawatch.synth import ais_scene
from seawatch.synth.ais_scene import DEMO, busiest_start, demo_camera

app = typer.Typer()
app.add_typer(synth_cmds.app, name="synth")
runner = CliRunner()
AIS = str(default_ais_path())


@pytest.fixture(scope="module")
def cam_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("cam") / "camera.yaml"
    save_camera(demo_camera(320, 180), path)
    return path


def _run(args: list[str]):
    res = runner.invoke(app, ["synth", "ais", *args])
    return res, " ".join(res.output.split())


def test_cli_renders_a_clip_and_prints_its_summary_and_alignment(
    tmp_path: Path, cam_file: Path
) -> None:
    out = tmp_path / "clip"
    args = [AIS, "--camera", str(cam_file), "--start", DEMO.start_utc, "--duration", "1"]
    res, msg = _run([*args, "--fps", "5", "--out", str(out), "--json"])
    assert res.exit_code == 0, msg
    doc = json.loads(res.stdout)
    assert doc["start_epoch"] == DEMO.start and doc["frames"] == 5
    assert (doc["width"], doc["height"]) == (320, 180)
    for key in ("video", "camera", "truth", "horizon", "clip"):
        assert Path(doc["outputs"][key]).is_file()
    clip = json.loads((out / "clip.json").read_text())
    assert clip["start_epoch"] == DEMO.start and clip["mmsi"] == doc["objects"]
    assert clip["mmsi"] and all(v["mmsi"] > 0 for v in doc["vessels"])


def test_cli_start_in_epoch_seconds_is_the_same_instant(tmp_path: Path, cam_file: Path) -> None:
    args = [AIS, "--camera", str(cam_file), "--start", f"{DEMO.start:.0f}", "--duration", "0.2"]
    res, msg = _run([*args, "--fps", "5", "--out", str(tmp_path), "--json"])
    assert res.exit_code == 0, msg
    assert json.loads(res.stdout)["start_utc"] == DEMO.start_utc


def test_cli_without_camera_renders_the_demo_clip(tmp_path: Path, monkeypatch) -> None:
    # the demo camera at a third of its size (its 1080p background alone takes seconds)
    monkeypatch.setattr(ais_scene, "demo_camera", lambda: demo_camera(640, 360))
    res, msg = _run(["--duration", "0.2", "--out", str(tmp_path), "--json"])
    assert res.exit_code == 0, msg
    doc = json.loads(res.stdout)
    assert doc["start_epoch"] == DEMO.start and doc["fps"] == DEMO.fps
    assert (doc["width"], doc["height"]) == (640, 360) and doc["frames"] == 2
    assert Path(doc["ais"]).resolve() == default_ais_path().resolve()
    assert "demo camera" in " ".join(res.stderr.split())


def test_cli_without_start_renders_the_busiest_window(tmp_path: Path, cam_file: Path) -> None:
    args = [AIS, "--camera", str(cam_file), "--duration", "10", "--fps", "0.5"]
    res, msg = _run([*args, "--out", str(tmp_path), "--json"])
    assert res.exit_code == 0, msg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = busiest_start(AIS, demo_camera(320, 180), 10.0)
    assert json.loads(res.stdout)["start_epoch"] == expected


def test_cli_missing_or_undecodable_ais_file_exits_2_naming_it(tmp_path: Path) -> None:
    res, msg = _run([str(tmp_path / "none.csv"), "--out", str(tmp_path)])
    assert res.exit_code == 2 and "none.csv" in msg
    junk = tmp_path / "junk.csv"
    junk.write_text("hello,world\n1,2\n")
    res, msg = _run([str(junk), "--out", str(tmp_path / "o")])
    assert res.exit_code == 2 and "junk.csv" in msg
    assert not (tmp_path / "o" / "video.mp4").exists()


def test_cli_camera_without_position_exits_2_naming_the_fields(tmp_path: Path) -> None:
    cam = tmp_path / "nogeo.yaml"
    save_camera(PinholeCamera.from_fov(320, 180, 50.0, height=10.0), cam)
    res, msg = _run([AIS, "--camera", str(cam), "--out", str(tmp_path)])
    assert res.exit_code == 2 and "nogeo.yaml" in msg and "lat_deg" in msg


@pytest.mark.parametrize(
    ("opt", "value", "needle"),
    [
        ("--start", "2020-01-01T00:00:00Z", "outside the time span"),
        ("--start", "yesterday", "ISO 8601"),
        ("--duration", "0", "--duration"),
        ("--fps", "-1", "--fps"),
        ("--lighting", "noon", "--lighting"),
    ],
)
def test_cli_bad_options_exit_2_naming_them(
    tmp_path: Path, cam_file: Path, opt: str, value: str, needle: str
) -> None:
    res, msg = _run([AIS, "--camera", str(cam_file), opt, value, "--out", str(tmp_path)])
    assert res.exit_code == 2 and opt in msg and needle in msg


def test_cli_no_vessel_in_view_exits_2(tmp_path: Path) -> None:
    cam = tmp_path / "inland.yaml"
    save_camera(PinholeCamera.from_fov(320, 180, 50.0, height=10.0, lat=51.5, lon=-1.09), cam)
    args = [AIS, "--camera", str(cam), "--start", DEMO.start_utc, "--out", str(tmp_path)]
    res, msg = _run(args)
    assert res.exit_code == 2 and "no vessel" in msg
