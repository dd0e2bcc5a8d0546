"""``seawatch horizon`` (seawatch.cli.horizon_cmds) through a tiny Typer app: the Horizon
JSON of INTERFACES.md, the CSV written as frames are processed, and the exit codes."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from seawatch.cli.horizon_cmds import CSV_COLUMNS, horizon
from seawatch.io import video as video_module
from seawatch.io.video import Frame, VideoError, VideoWriter

app = typer.Typer()
app.command()(horizon)


@app.callback()
def _root() -> None:
    """Test app (a callback keeps `horizon` a named sub-command)."""


runner = CliRunner()
KEYS = {"index", "time", "found", "x0", "y0", "x1", "y1", "confidence"}


def scene(y_left: float, y_right: float, w: int = 320, h: int = 240, seed: int = 0):
    """Bright sky over a darker textured sea, the line anti-aliased at its exact row."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    line = y_left + (y_right - y_left) * xx / (w - 1)
    below = np.clip(yy + 0.5 - line, 0.0, 1.0)
    tex = cv2.GaussianBlur(rng.standard_normal((h, w)), (0, 0), sigmaX=4, sigmaY=1)
    img = 200.0 * (1 - below) + (100.0 + 25.0 * tex / tex.std()) * below
    img = np.clip(img + rng.normal(0, 3, img.shape), 0, 255).astype(np.uint8)
    return cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)


def _msg(result) -> str:
    return " ".join(result.output.split())


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("frames")
    for k, (a, b) in enumerate([(100.0, 120.0), (140.0, 110.0), (90.0, 90.0)]):
        cv2.imwrite(str(path / f"img{k + 1}.png"), scene(a, b, seed=k))
    cv2.imwrite(str(path / "img10.png"), np.zeros((240, 320, 3), np.uint8))  # all black
    return path


def test_help_shows_an_example_and_the_options():
    result = runner.invoke(app, ["horizon", "--help"])
    assert result.exit_code == 0
    assert "Example" in result.stdout and "seawatch horizon" in result.stdout
    for option in ("--json", "--output", "--step", "--fps"):
        assert option in result.stdout


def test_folder_json_has_one_record_per_image_in_sorted_order_with_file(folder: Path):
    result = runner.invoke(app, ["horizon", str(folder), "--json", "--fps", "2"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert list(doc) == ["frames"]
    frames = doc["frames"]
    assert [Path(f["file"]).name for f in frames] == [
        "img1.png",
        "img2.png",
        "img3.png",
        "img10.png",
    ]
    assert [f["index"] for f in frames] == [0, 1, 2, 3]
    assert [f["time"] for f in frames] == [0.0, 0.5, 1.0, 1.5]
    for f, (a, b) in zip(frames[:3], [(100.0, 120.0), (140.0, 110.0), (90.0, 90.0)], strict=True):
        assert set(f) == KEYS | {"file"}
        assert f["found"] is True and f["x0"] == 0 and f["x1"] == 319
        assert abs(f["y0"] - a) < 1.5 and abs(f["y1"] - b) < 1.5
        assert 0.0 <= f["confidence"] <= 1.0
    black = frames[3]
    assert black["found"] is False and black["y0"] is None and black["y1"] is None


def test_video_json_and_csv_agree_and_follow_the_frame_times(tmp_path: Path):
    path = tmp_path / "clip.mp4"
    truth = [(100.0 + k, 120.0 - k) for k in range(8)]
    with VideoWriter(path, 10.0) as writer:
        for k, (a, b) in enumerate(truth):
            writer.write(scene(a, b, seed=k))
    out = tmp_path / "horizon.csv"
    result = runner.invoke(app, ["horizon", str(path), "--json", "-o", str(out), "--step", "2"])
    assert result.exit_code == 0, result.output
    frames = json.loads(result.stdout)["frames"]
    assert [f["index"] for f in frames] == [0, 2, 4, 6]
    assert [f["time"] for f in frames] == pytest.approx([0.0, 0.2, 0.4, 0.6])
    assert all(set(f) == KEYS for f in frames)  # no "file" for video
    for f in frames:
        a, b = truth[f["index"]]
        assert f["found"] and abs(f["y0"] - a) < 2.0 and abs(f["y1"] - b) < 2.0
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    assert tuple(rows[0]) == CSV_COLUMNS
    assert len(rows) == len(frames)
    for row, f in zip(rows, frames, strict=True):
        assert int(row["index"]) == f["index"] and row["file"] == ""
        assert float(row["y0"]) == pytest.approx(f["y0"]) and row["found"] == "true"


def test_missing_source_is_exit_2_naming_it(tmp_path: Path):
    result = runner.invoke(app, ["horizon", str(tmp_path / "nope.mp4"), "--json"])
    assert result.exit_code == 2
    assert "nope.mp4" in _msg(result) and result.stdout.strip() == ""


def test_undecodable_file_and_empty_folder_are_exit_2(tmp_path: Path):
    junk = tmp_path / "junk.avi"
    junk.write_bytes(b"\x00" * 1000)
    result = runner.invoke(app, ["horizon", str(junk)])
    assert result.exit_code == 2 and "junk.avi" in _msg(result)
    empty = tmp_path / "empty"
    empty.mkdir()
    result = runner.invoke(app, ["horizon", str(empty)])
    assert result.exit_code == 2 and "no image files" in _msg(result)


def test_bad_options_are_exit_2(folder: Path):
    assert runner.invoke(app, ["horizon", str(folder), "--step", "0"]).exit_code == 2
    result = runner.invoke(app, ["horizon", str(folder), "--start", "2", "--end", "1"])
    assert result.exit_code == 2 and "--end" in _msg(result)


def test_frames_before_a_failure_are_kept_in_the_csv_and_the_json(
    folder: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
):
    real = video_module.VideoReader

    class FailingReader(real):  # type: ignore[misc, valid-type]
        def __iter__(self):
            for k, frame in enumerate(super().__iter__()):
                if k == 2:
                    raise VideoError(f"{self.source}: stream broke")
                yield frame

    monkeypatch.setattr(video_module, "VideoReader", FailingReader)
    out = tmp_path / "partial.csv"
    result = runner.invoke(app, ["horizon", str(folder), "--json", "-o", str(out)])
    assert result.exit_code == 2
    assert "stream broke" in _msg(result)
    doc = json.loads(result.stdout)
    assert [f["index"] for f in doc["frames"]] == [0, 1] and "stream broke" in doc["error"]
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    assert [int(r["index"]) for r in rows] == [0, 1]


def test_warnings_go_to_stderr_and_do_not_stop_the_run(folder: Path, tmp_path: Path):
    mixed = tmp_path / "mixed"
    mixed.mkdir()
    for name in ("img1.png", "img2.png"):
        (mixed / name).write_bytes((folder / name).read_bytes())
    (mixed / "notes.txt").write_text("not an image")
    result = runner.invoke(app, ["horizon", str(mixed), "--json"])
    assert result.exit_code == 0
    assert "notes.txt" in _msg(result)
    assert len(json.loads(result.stdout)["frames"]) == 2


def test_plain_output_lists_every_frame(folder: Path):
    result = runner.invoke(app, ["horizon", str(folder), "--max-frames", "2"])
    assert result.exit_code == 0
    lines = [ln for ln in result.stdout.splitlines() if ln.strip()]
    assert len(lines) == 2 and "img1.png" in lines[0] and "y0=" in lines[0]


def test_record_uses_frame_file_and_nulls_for_not_found():
    from seawatch.cli.horizon_cmds import _record
    from seawatch.vision.horizon import HorizonEstimate

    frame = Frame(index=3, time=0.12, image=np.zeros((4, 4), np.uint8), file=Path("a.png"))
    est = HorizonEstimate.from_endpoints(1.0, 2.0, 640, 480, found=False, confidence=0.1)
    rec = _record(frame, est)
    assert rec == {
        "index": 3,
        "time": 0.12,
        "file": "a.png",
        "found": False,
        "x0": 0,
        "y0": None,
        "x1": 639,
        "y1": None,
        "confidence": 0.1,
    }


def test_keep_up_loses_no_frame_it_does_not_count(tmp_path: Path):
    """``--keep-up`` on a file (read faster than it is processed): every frame is either
    in the records, in source order, or counted in ``frames_dropped``; the lines found
    are the drawn ones."""
    path = tmp_path / "clip.mp4"
    with VideoWriter(path, 25.0) as writer:
        for k in range(40):
            writer.write(scene(100.0 + k / 4, 120.0 - k / 4, seed=k))
    result = runner.invoke(app, ["horizon", str(path), "--json", "--keep-up"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    index = [f["index"] for f in doc["frames"]]
    assert len(index) + doc["frames_dropped"] == 40 and np.all(np.diff(index) > 0)
    for f in doc["frames"]:
        k = f["index"]
        assert f["found"] and abs(f["y0"] - (100.0 + k / 4)) < 2.0
        assert abs(f["y1"] - (120.0 - k / 4)) < 2.0
