"""annotated.mp4: what the Annotator draws (and where it does not), labels and units, the
encoded video (frame count, size, colours), and what a killed writer leaves behind."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
from types import SimpleNamespace

import numpy as np
import pytest

from seawatch.io.video import VideoReader
from seawatch.report.annotate import AnnotatedVideo, Annotator, format_range, track_colour

W, H = 1280, 720
BG = (90, 70, 50)  # BGR, a dull sea
ROW = {"track_id": 7, "x": 600.0, "y": 420.0, "w": 120.0, "h": 40.0, "u_wl": 660.0,
       "v_wl": 460.0, "range_m": 2413.2, "speed_mps": 5.1, "mmsi": "235000001"}  # fmt: skip
HORIZON = SimpleNamespace(found=True, x0=0.0, y0=300.0, x1=W - 1.0, y1=280.0)


def _frame() -> np.ndarray:
    return np.full((H, W, 3), BG, np.uint8)


def _changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.any(a != b, axis=-1)


def _horizon_distance(horizon) -> np.ndarray:
    """Distance [px] of every pixel centre from the horizon line (closed form)."""
    yy, xx = np.mgrid[0:H, 0:W]
    dx, dy = horizon.x1 - horizon.x0, horizon.y1 - horizon.y0
    return np.abs(dy * (xx - horizon.x0) - dx * (yy - horizon.y0)) / math.hypot(dx, dy)


def test_box_outline_and_horizon_are_drawn_and_nothing_far_from_them():
    img = _frame()
    out = Annotator(show_time=False).draw(img, [ROW], HORIZON)
    changed = _changed(out, img)
    t = 1 + 1  # thickness at 720p is 1; allow antialiasing one pixel out
    x0, y0, x1, y1 = 600, 420, 720, 460
    # the outline: every pixel of the four sides changed
    assert changed[y0, x0:x1 + 1].all() and changed[y1, x0:x1 + 1].all()  # fmt: skip
    assert changed[y0:y1 + 1, x0].all() and changed[y0:y1 + 1, x1].all()  # fmt: skip
    # the box interior is untouched, except the ring on the water-line point (660, 460)
    inner = np.zeros_like(changed)
    inner[y0 + t + 1 : y1 - t, x0 + t + 1 : x1 - t] = True
    yy, xx = np.mgrid[0:H, 0:W]
    inner &= np.hypot(xx - 660, yy - 460) > 6
    assert not changed[inner].any()
    # the horizon: changed pixels within 1 px of the line at every column
    dist = _horizon_distance(HORIZON)
    near_line = dist <= 1.0
    assert all(changed[:, x][near_line[:, x]].any() for x in range(0, W, 7))
    # nothing changed far away: outside the box (+2 px), its label block below it
    # (text of two lines: at most 60 px down, 250 px right) and a 2-px band around the horizon
    allowed = dist <= 2.0
    allowed[y0 - 2 : y1 + 3, x0 - 2 : x1 + 3] = True
    allowed[y1 : y1 + 60, x0 - 2 : x0 + 250] = True
    allowed |= np.hypot(xx - 660, yy - 460) <= 6  # the water-line ring
    assert not changed[~allowed].any()
    assert changed[y1 + 2 : y1 + 60, x0 : x0 + 250].sum() > 1000  # the label is there
    # at the bottom of the image the label goes above the box
    low = dict(ROW, y=H - 45.0, v_wl=H - 5.0)
    changed = _changed(Annotator(show_time=False).draw(img, [low]), img)
    assert changed[H - 45 - 60 : H - 47, x0 : x0 + 250].sum() > 1000


def test_label_holds_id_mmsi_range_and_speed_in_knots():
    lines = Annotator().label(ROW)
    knots = 5.1 * 3600.0 / 1852.0  # 9.914 kn
    assert lines == ["#7 235000001", f"2.41 km  {knots:.1f} kn"]
    assert Annotator().label({"track_id": "3", "mmsi": "", "range_m": "", "speed_mps": ""}) == [
        "#3"
    ]
    assert Annotator().label({"track_id": 3, "mmsi": 235000001.0, "range_m": 850.2}) == [
        "#3 235000001",
        "850 m",
    ]


def test_range_format_switches_from_metres_to_kilometres_at_one_km():
    assert format_range(850.2) == "850 m"
    assert format_range(999.4) == "999 m"
    assert format_range(999.6) == "1.00 km"
    assert format_range(2413.2) == "2.41 km"
    assert format_range(float("nan")) == "" and format_range(float("inf")) == ""


def test_horizon_not_found_and_no_tracks_leave_the_frame_unchanged_and_input_untouched():
    img = _frame()
    lost = SimpleNamespace(found=False, x0=0.0, y0=300.0, x1=W - 1.0, y1=280.0)
    out = Annotator().draw(img, [], lost)
    assert np.array_equal(out, img) and out is not img
    before = img.copy()
    Annotator().draw(img, [ROW], HORIZON, time=1.0)
    assert np.array_equal(img, before)  # drawing never modifies the caller's frame


def test_rows_without_a_box_are_skipped_and_time_stamp_goes_top_left():
    img = _frame()
    out = Annotator().draw(img, [dict(ROW, x="", w=None)], None, time=12.5, frame=312)
    changed = _changed(out, img)
    assert changed.any()
    ys, xs = np.nonzero(changed)
    assert ys.max() < 40 and xs.max() < 300


def test_gray_and_16_bit_frames_become_8_bit_bgr():
    gray16 = np.full((H, W), 257 * 100, np.uint16)
    out = Annotator().draw(gray16, [ROW])
    assert out.dtype == np.uint8 and out.shape == (H, W, 3)
    assert tuple(out[5, W - 5]) == (100, 100, 100)


def test_track_colours_are_stable_bright_and_distinct_for_neighbouring_ids():
    assert track_colour(5) == track_colour(5)
    cols = np.array([track_colour(k) for k in range(1, 9)], float)
    assert cols.max(axis=1).min() >= 250  # full value
    d = np.linalg.norm(cols[:, None] - cols[None], axis=-1)
    assert d[~np.eye(8, dtype=bool)].min() > 40


def test_annotated_video_decodes_with_right_frame_count_size_and_box_colour(tmp_path):
    path = tmp_path / "annotated.mp4"
    n = 30
    with AnnotatedVideo(path, 25.0, (320, 240), annotator=Annotator(thickness=3)) as video:
        for k in range(n):
            row = {"track_id": 2, "x": 100.0 + k, "y": 120.0, "w": 60.0, "h": 24.0}
            video.write(np.full((240, 320, 3), BG, np.uint8), [row], time=k / 25.0, frame=k)
        assert video.frames_written == n
    frames = list(VideoReader(path))
    assert len(frames) == n
    assert all(f.size == (320, 240) for f in frames)
    assert [f.time for f in frames] == pytest.approx([k / 25.0 for k in range(n)], abs=1e-3)
    # the box's left side (3 px wide, centred at x = 100 + k) is in the track's colour
    # (after lossy coding with 2×2 chroma subsampling)
    want = np.array(track_colour(2), float)
    for k in (0, 15, 29):
        side = frames[k].image[126:140, 100 + k].astype(float).mean(axis=0)
        assert np.linalg.norm(side - want) < np.linalg.norm(side - np.array(BG, float)) / 2


def test_a_frame_of_another_size_is_drawn_at_its_size_and_fitted_to_the_video(tmp_path):
    """fit=True (a stream whose resolution changed): a 160×120 frame with a box at its own
    pixels comes out 320×240 with the box at twice them."""
    path = tmp_path / "fit.mp4"
    row = {"track_id": 2, "x": 40.0, "y": 60.0, "w": 30.0, "h": 12.0}
    with AnnotatedVideo(path, 25.0, (320, 240), annotator=Annotator(thickness=2)) as video:
        video.write(np.full((120, 160, 3), BG, np.uint8), [row], fit=True)
    (frame,) = list(VideoReader(path))
    assert frame.size == (320, 240)
    want = np.array(track_colour(2), float)
    side = frame.image[126:140, 80].astype(float)  # the left side at x = 2 × 40
    away = frame.image[126:140, 70].astype(float)
    assert np.linalg.norm(side.mean(0) - want) < np.linalg.norm(away.mean(0) - want) / 2


def test_killed_writer_leaves_a_playable_file_missing_at_most_one_second(tmp_path):
    path = tmp_path / "annotated.mp4"
    n, fps = 100, 25
    script = textwrap.dedent(
        f"""
        import os, signal, numpy as np
        from seawatch.report.annotate import AnnotatedVideo
        v = AnnotatedVideo({str(path)!r}, {fps}, (320, 240))
        rng = np.random.default_rng(1234)
        for k in range({n}):
            img = rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)
            v.write(img, [{{"track_id": 1, "x": k, "y": 100, "w": 40, "h": 20}}])
        os.kill(os.getpid(), signal.SIGKILL)
        """
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()[-2000:]
    frames = list(VideoReader(path))
    assert n - fps <= len(frames) <= n
    assert frames[0].size == (320, 240)


def test_bad_sizes_raise_value_error_naming_the_argument(tmp_path):
    with pytest.raises(ValueError, match="size"):
        AnnotatedVideo(tmp_path / "a.mp4", 25.0, (320,))
    with pytest.raises(ValueError, match="size"):
        AnnotatedVideo(tmp_path / "a.mp4", 25.0, (1, 240))
    with pytest.raises(ValueError, match="fps"):
        AnnotatedVideo(tmp_path / "a.mp4", 0.0, (320, 240))
    with pytest.raises(ValueError, match="path"):
        AnnotatedVideo(tmp_path / "no" / "a.mp4", 25.0, (320, 240))
    video = AnnotatedVideo(tmp_path / "a.mp4", 25.0, (320, 240))
    with pytest.raises(ValueError, match=r"image: frame 0 is 240x320, the video is 320x240"):
        video.write(np.zeros((320, 240, 3), np.uint8))
    video.write(np.zeros((240, 320, 3), np.uint8))
    video.close()
    assert os.path.getsize(tmp_path / "a.mp4") > 0
    with pytest.raises(ValueError, match="thickness"):
        Annotator(thickness=0)
    with pytest.raises(ValueError, match="font_scale"):
        Annotator(font_scale=float("nan"))
