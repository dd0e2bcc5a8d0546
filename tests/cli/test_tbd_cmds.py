"""``seawatch tbd`` (the function in seawatch.cli.tbd_cmds on a tiny Typer app): marks CSV
in, confirmed detections out; JSON summary; exit codes 0 / 2 (INTERFACES.md)."""

from __future__ import annotations

import csv
import io
import json
import sys

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from seawatch.cli.tbd_cmds import tbd

app = typer.Typer()
app.command("tbd")(tbd)


@app.callback()
def _root() -> None:
    """Test app."""


runner = CliRunner()


def said(result):
    """stderr with rich's line wrapping undone."""
    return " ".join(result.stderr.split())


def write_marks(path, rows, header="frame,row,col"):
    lines = ([header] if header else []) + [",".join(str(v) for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def target_rows(frames=8, p0=(100, 200), v=(4, -3)):
    return [(k, p0[0] + v[0] * k, p0[1] + v[1] * k) for k in range(frames)]


def test_marks_csv_to_tracks_csv(tmp_path):
    clutter = [(k, 900, 100 + 400 * k) for k in range(8)]  # far away, never linear in gate
    rows = sorted(target_rows() + clutter)
    marks = write_marks(tmp_path / "marks.csv", rows, header="frame,row,col,intensity")
    out = tmp_path / "tracks.csv"
    result = runner.invoke(
        app,
        ["tbd", str(marks), "--frame-size", "1080x1920", "--large-gate", "161",
         "--small-gate", "23", "-N", "4", "-o", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert f"wrote {out}" in result.stdout
    got = list(csv.DictReader(out.open()))
    assert [int(r["frame"]) for r in got] == [3, 4, 5, 6, 7]  # delay N − 1
    assert {r["track_id"] for r in got} == {"1"}
    for r in got:
        k = int(r["frame"])
        assert (float(r["row"]), float(r["col"])) == (100 + 4 * k, 200 - 3 * k)
        assert (float(r["v_row"]), float(r["v_col"])) == pytest.approx((4.0, -3.0))


def test_json_is_one_document_with_the_track_summary(tmp_path):
    marks = write_marks(tmp_path / "m.csv", target_rows(6))
    result = runner.invoke(app, ["tbd", str(marks), "-N", "3", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["frames"] == 6 and doc["marks"] == 6 and doc["detections"] == 4
    assert doc["tracks"] == [{"track_id": 1, "first_frame": 2, "last_frame": 5, "detections": 4}]
    assert doc["parameters"]["n_frames"] == 3 and doc["frame_size"] == [1080, 1920]


def test_without_output_the_csv_goes_to_stdout_and_header_less_files_work(tmp_path):
    marks = write_marks(tmp_path / "m.csv", target_rows(5), header=None)
    result = runner.invoke(app, ["tbd", str(marks), "-N", "3"])
    assert result.exit_code == 0, result.output
    rows = list(csv.reader(io.StringIO(result.stdout)))
    assert rows[0] == ["frame", "track_id", "row", "col", "v_row", "v_col"]
    assert [r[0] for r in rows[1:]] == ["2", "3", "4"]


def test_skipped_frame_numbers_are_empty_frames(tmp_path):
    rows = [(k if k < 4 else k + 5, 100 + 4 * k, 200) for k in range(8)]
    marks = write_marks(tmp_path / "m.csv", rows)
    result = runner.invoke(app, ["tbd", str(marks), "-N", "3", "--json"])
    doc = json.loads(result.stdout)
    # frames 2, 3 confirmed; the gap of 5 frames deletes the track; 11, 12 confirm anew
    assert [t["track_id"] for t in doc["tracks"]] == [1, 2]
    assert doc["detections"] == 4


def test_marks_outside_the_frame_are_dropped_with_a_warning(tmp_path):
    rows = sorted([*target_rows(5), (1, 5000, 5), (2, -3, 7)])
    marks = write_marks(tmp_path / "m.csv", rows)
    result = runner.invoke(app, ["tbd", str(marks), "-N", "3", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["dropped"] == 2 and doc["detections"] == 3
    assert "dropped 2 mark" in said(result)


def test_decreasing_frame_numbers_are_bad_input_naming_the_frame(tmp_path):
    marks = write_marks(tmp_path / "m.csv", [(0, 1, 1), (2, 5, 5), (1, 3, 3)])
    result = runner.invoke(app, ["tbd", str(marks)])
    assert result.exit_code == 2
    assert "frame 1" in said(result) and "follows frame 2" in said(result)


@pytest.mark.parametrize(
    ("content", "args", "message"),
    [
        ("frame,row,col\n0,1,1\n", ["--frame-size", "1080by1920"], "--frame-size"),
        ("frame,row\n0,1\n", [], "no column col"),
        ("frame,row,col\n0,a,1\n", [], "line 2"),
        ("frame,row,col\n0,1,1\n", ["--large-gate", "160"], "large_gate"),
        ("frame,row,col\n0.5,1,1\n", [], "not an integer"),
    ],
)
def test_bad_input_exits_2_with_a_message(tmp_path, content, args, message):
    path = tmp_path / "m.csv"
    path.write_text(content)
    result = runner.invoke(app, ["tbd", str(path), *args])
    assert result.exit_code == 2
    assert message in said(result)


def test_missing_file_exits_2(tmp_path):
    result = runner.invoke(app, ["tbd", str(tmp_path / "nope.csv")])
    assert result.exit_code == 2 and "no such file" in said(result)


def test_video_without_mark_extraction_exits_2_saying_so(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "seawatch.vision.marks", None)  # import fails
    video = tmp_path / "clip.mp4"
    video.write_bytes(b"\x00" * 16)
    result = runner.invoke(app, ["tbd", str(video)])
    assert result.exit_code == 2
    assert "mark extraction" in said(result) and "seawatch.vision.marks" in said(result)


def test_video_with_mark_extraction_tracks_the_extracted_marks(tmp_path, monkeypatch):
    cv2 = pytest.importorskip("cv2")
    import types

    path = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 25, (320, 240))
    if not writer.isOpened():
        pytest.skip("no video writer")
    for k in range(6):
        img = np.zeros((240, 320, 3), np.uint8)
        img[50 + 5 * k - 1 : 50 + 5 * k + 2, 60 + 7 * k - 1 : 60 + 7 * k + 2] = 255
        writer.write(img)
    writer.release()

    def extract_marks(frame):  # a stand-in for the vision helper: brightest blob centroid
        gray = frame.max(axis=2)
        r, c = np.nonzero(gray > 128)
        return np.array([[r.mean(), c.mean(), 255.0, r.size]])

    fake = types.ModuleType("seawatch.vision.marks")
    fake.extract_marks = extract_marks
    monkeypatch.setitem(sys.modules, "seawatch.vision.marks", fake)
    result = runner.invoke(app, ["tbd", str(path), "-N", "3", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["frame_size"] == [240, 320] and doc["frames"] == 6
    assert [t["track_id"] for t in doc["tracks"]] == [1]


def test_help_shows_an_example():
    result = runner.invoke(app, ["tbd", "--help"])
    assert result.exit_code == 0
    assert "Example" in result.stdout and "seawatch tbd" in result.stdout
