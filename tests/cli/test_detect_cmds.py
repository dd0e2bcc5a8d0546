"""``seawatch detect`` (seawatch.cli.detect_cmds) through a tiny Typer app.

Truths: frames drawn here with known ship boxes (a grey sky over a noisy sea with a
straight horizon, dark and bright hulls), written as an image folder or an H.264 video;
the Detection JSON and BOXES.csv shapes of INTERFACES.md; the exit-code contract.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from seawatch.cli.detect_cmds import CSV_COLUMNS, detect

app = typer.Typer()
app.command()(detect)
runner = CliRunner()

BOX_KEYS = {"x", "y", "w", "h", "score", "u_wl", "v_wl"}
HORIZON = 100


def _msg(result: object) -> str:
    """The command's output with rich's line wrapping undone."""
    return " ".join(result.output.split())  # type: ignore[attr-defined]


def scene(seed: int, shift: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A 320×480 BGR frame: sky above row 100, sea below (darkening, horizontal wave
    streaks, noise σ = 2), a dark 24 × 6 px hull and a bright 10 × 4 px boat; returns
    the image and the boxes
    (x, y, w, h) [px, origin at the top-left pixel centre]."""
    rng = np.random.default_rng(seed)
    h, w = 320, 480
    rows = np.arange(h, dtype=np.float64)[:, None]
    img = np.where(rows < HORIZON, 170.0 - 0.2 * rows, 95.0 - 0.08 * (rows - HORIZON))
    img = np.broadcast_to(img, (h, w)).copy()
    streaks = cv2.GaussianBlur(rng.normal(0, 1, (h, w)), (0, 0), sigmaX=12, sigmaY=1.0) * 40
    img += np.where(rows >= HORIZON, streaks, 0.0)  # wave streaks (σ ≈ 3 grey levels)
    img += rng.normal(0, 2.0, (h, w))
    boxes = []
    for r0, c0, bh, bw, contrast in [(180, 100 + shift, 6, 24, -40), (240, 330 - shift, 4, 10, 40)]:
        img[r0 : r0 + bh, c0 : c0 + bw] += contrast
        boxes.append((c0 - 0.5, r0 - 0.5, bw, bh))
    grey = np.clip(np.round(img), 0, 255).astype(np.uint8)
    return cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR), np.array(boxes)


def _folder(tmp_path: Path, n: int = 3) -> tuple[Path, list[np.ndarray]]:
    folder = tmp_path / "frames"
    folder.mkdir()
    truths = []
    for k in range(n):
        img, boxes = scene(k, shift=4 * k)
        cv2.imwrite(str(folder / f"frame{k:02d}.png"), img)
        truths.append(boxes)
    return folder, truths


def _matches(boxes: list[dict], truth: np.ndarray) -> bool:
    centres = np.array([[b["x"] + b["w"] / 2, b["y"] + b["h"] / 2] for b in boxes]).reshape(-1, 2)
    if len(centres) != len(truth):
        return False
    tc = truth[:, :2] + truth[:, 2:] / 2
    return all((np.abs(centres - t).sum(axis=1) <= 12).any() for t in tc)


def test_folder_json_has_the_interfaces_shape_and_the_drawn_ships(tmp_path):
    folder, truths = _folder(tmp_path)
    res = runner.invoke(app, [str(folder), "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    frames = doc["frames"]
    assert [f["index"] for f in frames] == [0, 1, 2]
    assert [Path(f["file"]).name for f in frames] == ["frame00.png", "frame01.png", "frame02.png"]
    assert [f["time"] for f in frames] == [0.0, 1.0, 2.0]  # folder default: 1 frame/s
    for f, truth in zip(frames, truths, strict=True):
        assert all(set(b) == BOX_KEYS for b in f["boxes"])
        assert _matches(f["boxes"], truth), f["boxes"]
        for b in f["boxes"]:
            assert 0 <= b["score"] <= 1
            assert b["y"] < b["v_wl"] <= b["y"] + b["h"] + 0.01


def test_csv_rows_equal_the_json_boxes(tmp_path):
    folder, _ = _folder(tmp_path)
    out = tmp_path / "boxes.csv"
    res = runner.invoke(app, [str(folder), "--json", "-o", str(out), "--fps", "5"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == CSV_COLUMNS
    expected = [(f["index"], f["file"], f["time"], b) for f in doc["frames"] for b in f["boxes"]]
    assert len(rows) == len(expected) > 0
    for row, (index, file, time, b) in zip(rows, expected, strict=True):
        assert int(row["index"]) == index and row["file"] == file
        assert float(row["time"]) == pytest.approx(time)
        for k in BOX_KEYS:
            assert float(row[k]) == pytest.approx(b[k])
    assert [f["time"] for f in doc["frames"]] == [0.0, 0.2, 0.4]


def test_video_source_gives_increasing_times_and_no_file_key(tmp_path):
    from seawatch.io.video import VideoWriter

    path = tmp_path / "clip.mp4"
    truths = []
    with VideoWriter(path, fps=10.0, crf=10) as writer:
        for k in range(4):
            img, boxes = scene(10 + k, shift=2 * k)
            writer.write(img)
            truths.append(boxes)
    res = runner.invoke(app, [str(path), "--json"])
    assert res.exit_code == 0, res.output
    frames = json.loads(res.stdout)["frames"]
    assert [f["index"] for f in frames] == [0, 1, 2, 3]
    assert [f["time"] for f in frames] == pytest.approx([0.0, 0.1, 0.2, 0.3])
    assert all("file" not in f for f in frames)
    assert all(_matches(f["boxes"], t) for f, t in zip(frames, truths, strict=True))


def test_no_horizon_searches_the_sky_too(tmp_path):
    img, _ = scene(3)
    img[40:44, 200:212] = 40  # a dark object in the sky, above the horizon
    path = tmp_path / "sky.png"
    cv2.imwrite(str(path), img)
    with_h = json.loads(runner.invoke(app, [str(path), "--json"]).stdout)["frames"][0]["boxes"]
    without = runner.invoke(app, [str(path), "--json", "--no-horizon"])
    everywhere = json.loads(without.stdout)["frames"][0]["boxes"]
    assert all(b["v_wl"] > HORIZON - 5 for b in with_h)
    assert any(b["v_wl"] < HORIZON for b in everywhere)


@pytest.mark.parametrize(("polarity", "kept"), [("both", [0, 1]), ("dark", [0]), ("bright", [1])])
def test_polarity_keeps_the_dark_hull_or_the_bright_boat(tmp_path, polarity, kept):
    folder, truths = _folder(tmp_path, n=2)
    res = runner.invoke(app, [str(folder), "--json", "--polarity", polarity])
    assert res.exit_code == 0, res.output
    for f, truth in zip(json.loads(res.stdout)["frames"], truths, strict=True):
        assert _matches(f["boxes"], truth[kept]), (polarity, f["boxes"])


def test_float_thermal_images_with_dead_pixels_are_detected_not_refused(tmp_path):
    """Radiometric float TIFFs (kelvin) with NaN dead pixels: the reader fills them, the
    ships are found and the summary counts the filled images (before: exit 2, "image:
    contains NaN or inf pixels", on the first frame)."""
    folder = tmp_path / "thermal"
    folder.mkdir()
    truths = []
    for k in range(2):
        img, boxes = scene(k, shift=4 * k)
        kelvin = 270.0 + cv2.cvtColor(img, cv2.COLOR_BGR2GRAY).astype(np.float32) / 10.0
        kelvin[[5, 150, 300], [7, 200, 470]] = np.nan
        cv2.imwrite(str(folder / f"t{k}.tiff"), kelvin)
        truths.append(boxes)
    res = runner.invoke(app, [str(folder), "--json"])
    assert res.exit_code == 0, res.output
    assert "2 with NaN/inf pixels filled" in _msg(res)
    for f, truth in zip(json.loads(res.stdout)["frames"], truths, strict=True):
        assert _matches(f["boxes"], truth), f["boxes"]


def _with_overlay(tmp_path: Path) -> tuple[Path, list[np.ndarray]]:
    """Two frames of :func:`scene` with a camera's text overlay burnt into the sea
    (bright glyph strokes in rows 290–299, columns 20–139, as a time stamp)."""
    folder = tmp_path / "osd"
    folder.mkdir()
    truths = []
    for k in range(2):
        img, boxes = scene(k, shift=4 * k)
        for c in range(20, 140, 8):  # glyphs: 5 px strokes, 3 px gaps
            img[290:300, c : c + 5] = 235
        cv2.imwrite(str(folder / f"f{k}.png"), img)
        truths.append(boxes)
    return folder, truths


def test_mask_keeps_the_ships_and_drops_the_text_overlay(tmp_path):
    folder, truths = _with_overlay(tmp_path)
    res = runner.invoke(app, [str(folder), "--json"])
    assert res.exit_code == 0, res.output
    for f in json.loads(res.stdout)["frames"]:  # the overlay is boxed without a mask
        assert any(b["y"] > 280 and b["x"] < 140 for b in f["boxes"]), f["boxes"]
    mask = np.full((320, 480), 255, np.uint8)
    mask[285:305, 15:145] = 0
    cv2.imwrite(str(tmp_path / "mask.png"), mask)
    res = runner.invoke(app, [str(folder), "--json", "--mask", str(tmp_path / "mask.png")])
    assert res.exit_code == 0, res.output
    for f, truth in zip(json.loads(res.stdout)["frames"], truths, strict=True):
        assert _matches(f["boxes"], truth), f["boxes"]
    # a mask of half the frame's size is scaled; one of another aspect ratio is refused
    cv2.imwrite(str(tmp_path / "half.png"), mask[::2, ::2])
    res = runner.invoke(app, [str(folder), "--json", "--mask", str(tmp_path / "half.png")])
    assert res.exit_code == 0, res.output
    for f, truth in zip(json.loads(res.stdout)["frames"], truths, strict=True):
        assert _matches(f["boxes"], truth), f["boxes"]
    cv2.imwrite(str(tmp_path / "square.png"), mask[:, :320])
    res = runner.invoke(app, [str(folder), "--mask", str(tmp_path / "square.png")])
    assert res.exit_code == 2 and "--mask: 320x320, the frames are 480x320" in _msg(res)
    res = runner.invoke(app, [str(folder), "--mask", str(tmp_path / "none.png")])
    assert res.exit_code == 2 and "none.png" in _msg(res)


def test_human_readable_output_has_one_line_per_frame(tmp_path):
    folder, _ = _folder(tmp_path, n=2)
    res = runner.invoke(app, [str(folder)])
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.stdout.splitlines() if "box(es)" in ln and "frame(s)" not in ln]
    assert len(lines) == 2 and "frame00.png" in lines[0]


def test_all_black_frames_give_empty_box_lists(tmp_path):
    folder = tmp_path / "black"
    folder.mkdir()
    for k in range(2):
        cv2.imwrite(str(folder / f"b{k}.png"), np.zeros((120, 160, 3), np.uint8))
    res = runner.invoke(app, [str(folder), "--json"])
    assert res.exit_code == 0, res.output
    assert [f["boxes"] for f in json.loads(res.stdout)["frames"]] == [[], []]


def test_a_non_image_file_in_the_folder_is_skipped_with_a_warning(tmp_path):
    folder, _ = _folder(tmp_path, n=2)
    (folder / "notes.txt").write_text("not an image")
    res = runner.invoke(app, [str(folder), "--json"])
    assert res.exit_code == 0, res.output
    assert len(json.loads(res.stdout)["frames"]) == 2
    assert "notes.txt" in res.stderr


def test_bad_inputs_exit_2_naming_the_input(tmp_path):
    missing = tmp_path / "nope.mp4"
    res = runner.invoke(app, [str(missing)])
    assert res.exit_code == 2 and "nope.mp4" in _msg(res)
    empty = tmp_path / "empty"
    empty.mkdir()
    res = runner.invoke(app, [str(empty)])
    assert res.exit_code == 2 and "empty" in _msg(res)
    folder, _ = _folder(tmp_path, n=1)
    res = runner.invoke(app, [str(folder), "--model", str(tmp_path / "m.onnx")])
    assert res.exit_code == 2 and "--model" in _msg(res)
    res = runner.invoke(app, [str(folder), "--polarity", "grey"])
    assert res.exit_code == 2 and "--polarity" in _msg(res)
    res = runner.invoke(app, [str(folder), "--start", "2", "--end", "1"])
    assert res.exit_code == 2 and "--end" in _msg(res)
    garbage = tmp_path / "garbage.mp4"
    garbage.write_bytes(b"\x00" * 1000)
    res = runner.invoke(app, [str(garbage)])
    assert res.exit_code == 2 and "garbage.mp4" in _msg(res)


def test_help_has_an_example():
    res = runner.invoke(app, ["--help"])
    assert res.exit_code == 0 and "Example" in res.output


def test_keep_up_drops_the_frames_it_is_behind_on_and_counts_them(tmp_path):
    """``--keep-up`` on a file, decoded far faster than ships are looked for in it (as a
    camera sending frames faster than the command keeps up with): frames are dropped
    unprocessed, counted in ``frames_dropped`` and warned about, and those processed
    are the source's own frames in order. A file without the option loses none (the
    default off a real-time source) and its JSON keeps the INTERFACES shape."""
    from seawatch.io.video import VideoWriter

    path = tmp_path / "clip.mp4"
    with VideoWriter(path, fps=25.0, crf=10) as writer:
        for k in range(60):
            writer.write(scene(20 + k % 5, shift=k % 8)[0])
    res = runner.invoke(app, [str(path), "--json", "--keep-up"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    index = [f["index"] for f in doc["frames"]]
    assert doc["frames_dropped"] > 0 and len(index) + doc["frames_dropped"] == 60
    assert index[:2] == [0, 1] and np.all(np.diff(index) > 0)
    assert "dropped to keep up" in _msg(res)
    plain = json.loads(runner.invoke(app, [str(path), "--json"]).stdout)
    assert set(plain) == {"frames"} and len(plain["frames"]) == 60
