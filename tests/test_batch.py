"""``seawatch batch``: many recordings, one task each — in process and on a Dask cluster."""

from __future__ import annotations

import csv
import json

import pytest
from typer.testing import CliRunner

from seawatch.batch import track_batch
from seawatch.cli import app
from seawatch.synth import render_case

runner = CliRunner()


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    base = tmp_path_factory.mktemp("clips")
    for name, seed in (("a", 1), ("b", 2)):
        render_case("medium", base / name, duration=1.2, width=640, height=360, seed=seed)
    return base


def _rows(path):
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_each_recording_gets_the_same_tracks_as_a_single_track_run(clips, tmp_path):
    from seawatch.io.camera_file import load_camera
    from seawatch.pipeline import track_video

    sources = [str(clips / "a" / "video.mp4"), str(clips / "b" / "video.mp4")]
    res = track_batch(sources, tmp_path / "batch", camera=clips / "a" / "camera.yaml",
                      workers=1, annotate=False, report=False)  # fmt: skip
    assert [it.ok for it in res.items] == [True, True]
    # both clips are named video.mp4: distinct folders
    assert [it.out_dir.name for it in res.items] == ["video", "video-2"]
    single = tmp_path / "single"
    track_video(sources[1], single, camera=load_camera(clips / "a" / "camera.yaml"),
                annotate=False, report=False)  # fmt: skip
    assert _rows(res.items[1].out_dir / "tracks.csv") == _rows(single / "tracks.csv")
    doc = json.loads((tmp_path / "batch" / "batch.json").read_text())
    assert doc["ok"] == 2 and doc["failed"] == 0


def test_on_a_local_dask_cluster_a_bad_recording_fails_alone(clips, tmp_path):
    junk = tmp_path / "junk.mp4"
    junk.write_bytes(b"\x00" * 2048)
    args = ["batch", str(clips / "a" / "video.mp4"), str(junk), "--camera",
            str(clips / "a" / "camera.yaml"), "--out", str(tmp_path / "out"), "--workers", "2",
            "--no-video", "--no-report", "--json"]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 1, res.output
    doc = json.loads(res.stdout)
    assert (doc["recordings"], doc["ok"], doc["failed"]) == (2, 1, 1)
    good, bad = doc["items"]
    assert good["ok"] and good["summary"]["rows"] > 5
    assert not bad["ok"] and "junk.mp4" in bad["error"]
    assert (tmp_path / "out" / "video" / "tracks.csv").is_file()


def test_step_and_fps_reach_each_recording(clips, tmp_path):
    """--step 2 tracks every other frame of each 30-frame recording; --fps times the frames
    of an image folder (the first recording's frames as PNG files, at 25 frames/s)."""
    import cv2

    from seawatch.io.video import VideoReader

    folder = tmp_path / "frames"
    folder.mkdir()
    with VideoReader(clips / "a" / "video.mp4") as reader:
        for fr in reader:
            cv2.imwrite(str(folder / f"f{fr.index:03d}.png"), fr.image)
    args = ["batch", str(clips / "b" / "video.mp4"), str(folder), "--step", "2", "--fps", "25",
            "--out", str(tmp_path / "out"), "--workers", "1", "--no-video", "--no-report",
            "--json"]  # fmt: skip
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert [it["summary"]["frames"] for it in doc["items"]] == [15, 15]
    rows = _rows(tmp_path / "out" / "frames" / "tracks.csv")
    assert rows and all(int(r["frame"]) % 2 == 0 for r in rows)
    assert all(abs(float(r["time"]) - int(r["frame"]) / 25.0) < 1e-6 for r in rows)


def test_bad_batch_inputs_exit_2(clips, tmp_path):
    video = str(clips / "a" / "video.mp4")
    res = runner.invoke(app, ["batch", video, "--camera", str(tmp_path / "none.yaml")])
    assert res.exit_code == 2 and "none.yaml" in res.output
    res = runner.invoke(app, ["batch", video, "--estimator", "magic"])
    assert res.exit_code == 2 and "--estimator" in res.output
    res = runner.invoke(app, ["batch", video, "--polarity", "grey", "--out", str(tmp_path / "p")])
    assert res.exit_code == 2 and "--polarity" in res.output
    assert not (tmp_path / "p").exists()  # before any work


def test_detector_options_reach_each_recordings_detector(clips, tmp_path):
    """With a detection threshold of 500 noise units the recording has no track rows; with
    the default (6) its ship is tracked: the options reach the worker's detector."""
    sources = [str(clips / "a" / "video.mp4")]
    rows = {}
    for threshold in (None, 500.0):
        res = track_batch(sources, tmp_path / str(threshold), workers=1, annotate=False,
                          report=False, detector_options={"threshold": threshold})  # fmt: skip
        assert res.items[0].ok
        rows[threshold] = res.items[0].summary["rows"]
    assert rows[None] > 5 and rows[500.0] == 0
