"""seawatch.io.video: one frame iterator over files, streams and image folders, and the
writer. Round trips through our own writer, byte-level corruption and truncation with
known effects, and every bad-input path of issue 6 ("Video in", "Bad input")."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path

import av
import cv2
import numpy as np
import pytest

from seawatch.io.video import (
    Frame,
    VideoError,
    VideoReader,
    VideoWarning,
    VideoWriter,
    read_image,
)

W, H, FPS, N = 96, 64, 25.0, 40


def _pattern(i: int, w: int = W, h: int = H) -> np.ndarray:
    """A smooth BGR frame that changes with i (survives lossy coding well)."""
    y, x = np.mgrid[0:h, 0:w]
    img = np.empty((h, w, 3), np.uint8)
    img[:, :, 0] = (x * 255 // (w - 1)).astype(np.uint8)
    img[:, :, 1] = (y * 255 // (h - 1)).astype(np.uint8)
    img[:, :, 2] = np.uint8((i * 6) % 256)
    x0 = (i * 2) % (w - 16)
    img[20:36, x0 : x0 + 16] = 255
    return img


def _gray(img: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY).astype(np.float64)


@pytest.fixture(scope="module")
def clip(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("video") / "clip.mp4"
    with VideoWriter(path, FPS, gop=10, crf=12) as writer:
        for i in range(N):
            writer.write(_pattern(i))
    assert writer.codec == "libx264"
    return path


def _frames(reader: VideoReader) -> list[Frame]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", VideoWarning)
        return list(reader)


# ----------------------------------------------------------------------------- round trip
def test_written_video_reads_back_every_frame_with_pts_times_and_similar_content(clip: Path):
    reader = VideoReader(clip)
    assert reader.kind == "file" and not reader.live
    assert reader.size == (W, H) and reader.fps == pytest.approx(FPS)
    assert reader.frame_count == N
    frames = list(reader)
    assert [f.index for f in frames] == list(range(N))
    np.testing.assert_allclose([f.time for f in frames], np.arange(N) / FPS, atol=1e-9)
    assert reader.skipped == 0
    for f in frames:
        assert f.image.shape == (H, W, 3) and f.image.dtype == np.uint8 and f.file is None
        assert np.mean(np.abs(_gray(f.image) - _gray(_pattern(f.index)))) < 3.0
    # iterating again starts from the beginning
    assert len(list(reader)) == N


def test_gray_option_gives_the_luma_plane(clip: Path):
    frames = list(VideoReader(clip, gray=True, max_frames=3))
    assert all(f.image.shape == (H, W) and f.image.dtype == np.uint8 for f in frames)
    assert np.mean(np.abs(frames[2].image - _gray(_pattern(2)))) < 4.0


def test_step_start_end_and_max_frames_select_the_right_frames(clip: Path):
    # times are k / 25: start 0.2 s is frame 5; end 1.0 s (exclusive) is frame 25
    frames = list(VideoReader(clip, step=3, start=0.2, end=1.0))
    assert [f.index for f in frames] == list(range(5, 25, 3))
    assert all(0.2 <= f.time < 1.0 for f in frames)
    assert [f.index for f in VideoReader(clip, step=4, max_frames=3)] == [0, 4, 8]
    assert [f.index for f in VideoReader(clip, start=1.5)] == list(range(38, N))
    assert list(VideoReader(clip, start=100.0)) == []  # frames exist, none in the window


@pytest.mark.parametrize(
    "kwargs",
    [{}, {"step": 3, "start": 0.2, "end": 1.0}, {"step": 4, "max_frames": 3}, {"start": 1.5},
     {"start": 100.0}, {"end": 0.5, "step": 2}, {"start": 0.21, "end": 0.99}],
)  # fmt: skip
def test_expected_frames_is_what_the_iteration_delivers(clip: Path, kwargs: dict):
    reader = VideoReader(clip, **kwargs)
    assert reader.expected_frames == len(list(reader))


def test_opencv_backend_reads_the_same_frames_and_times(clip: Path):
    frames = list(VideoReader(clip, backend="opencv"))
    assert [f.index for f in frames] == list(range(N))
    np.testing.assert_allclose([f.time for f in frames], np.arange(N) / FPS, atol=1e-3)
    ref = list(VideoReader(clip))
    assert np.mean(np.abs(_gray(frames[7].image) - _gray(ref[7].image))) < 1.0
    picked = list(VideoReader(clip, backend="opencv", step=2, start=0.5, max_frames=3))
    assert [f.index for f in picked] == [13, 15, 17]


def test_mpeg4_is_the_fallback_when_the_codec_is_missing(tmp_path: Path):
    path = tmp_path / "fallback.avi"
    with VideoWriter(path, 10.0, codec="no-such-encoder") as writer:
        for i in range(5):
            writer.write(_pattern(i))
    assert writer.codec == "mpeg4"
    frames = list(VideoReader(path))
    assert len(frames) == 5
    assert np.mean(np.abs(_gray(frames[4].image) - _gray(_pattern(4)))) < 6.0


def test_sixteen_bit_gray_video_round_trips_exactly_with_ffv1(tmp_path: Path):
    rng = np.random.default_rng(1234)
    data = [rng.integers(0, 65536, (H, W), dtype=np.uint16) for _ in range(4)]
    path = tmp_path / "thermal.mkv"
    with VideoWriter(path, 30.0, codec="ffv1") as writer:
        for img in data:
            writer.write(img)
    frames = list(VideoReader(path))
    assert len(frames) == 4
    for f, img in zip(frames, data, strict=True):
        assert f.image.dtype == np.uint16
        np.testing.assert_array_equal(f.image, img)
    with pytest.raises(ValueError, match="image: 16-bit"):
        VideoWriter(tmp_path / "thermal.mp4").write(data[0])


def test_odd_frame_size_is_padded_without_moving_pixels(tmp_path: Path):
    path = tmp_path / "odd.mp4"
    img = _pattern(0, 95, 63)
    with pytest.warns(VideoWarning, match="padded"), VideoWriter(path) as writer:
        writer.write(img)
    (frame,) = list(VideoReader(path))
    assert frame.image.shape == (64, 96, 3)
    assert np.mean(np.abs(_gray(frame.image[:63, :95]) - _gray(img))) < 3.0


def test_writer_rejects_bad_frames_and_writes_no_file_without_frames(tmp_path: Path):
    with pytest.raises(ValueError, match="fps"):
        VideoWriter(tmp_path / "a.mp4", fps=0)
    with pytest.raises(ValueError, match="path"):
        VideoWriter(tmp_path / "missing-folder" / "a.mp4")
    writer = VideoWriter(tmp_path / "a.mp4")
    with pytest.raises(ValueError, match="image"):
        writer.write(np.zeros((10, 10, 2), np.uint8))
    with pytest.raises(ValueError, match="image"):
        writer.write(np.zeros((10, 10, 3), np.float32))
    writer.write(_pattern(0))
    with pytest.raises(ValueError, match="image: frame 1"):
        writer.write(_pattern(0, 32, 32))
    writer.close()
    writer.close()  # idempotent
    with pytest.raises(ValueError, match="closed"):
        writer.write(_pattern(1))
    empty = tmp_path / "empty.mp4"
    with pytest.warns(VideoWarning, match="no frames"):
        VideoWriter(empty).close()
    assert not empty.exists()


def test_frames_written_at_their_pts_keep_their_times_across_gaps(tmp_path: Path):
    """Frames given presentation times with gaps (frames dropped upstream) are read back
    at those times, with the source's indices and pixels, the gaps reported as missing
    frames (the stream's base rate, 25/s, is kept: a sixth of its frames are gone); a
    pts not after the last one is refused."""
    path = tmp_path / "gaps.mp4"
    pts = [0, 1, 2, 3, 5, 6, 7, 9, 10]  # 4 and 8 dropped
    with VideoWriter(path, fps=25.0, crf=0) as writer:
        for k in pts:
            writer.write(_pattern(k), pts=k)
        for bad in (10, 4, 11.5, True):
            with pytest.raises(ValueError, match="pts"):
                writer.write(_pattern(0), pts=bad)
        writer.write(_pattern(11))  # the default: the frame after the last
    with pytest.warns(VideoWarning, match="1 frame\\(s\\) missing between 0.280"):
        frames = list(VideoReader(path))
    assert [f.index for f in frames] == [*pts, 11]
    assert [f.time for f in frames] == pytest.approx([k / 25.0 for k in [*pts, 11]])
    for f in frames:
        assert np.mean(np.abs(_gray(f.image) - _gray(_pattern(f.index)))) < 3.0


@pytest.mark.parametrize("fragmented", [False, True])
def test_frames_written_at_every_third_pts_keep_the_source_indices(tmp_path: Path, fragmented):
    """Every third frame written (a job that kept up with a camera three times faster
    than itself, as the track job's annotated.mp4, whose MP4 is fragmented): the
    stream's own rates are the gaps' — average 375/44, and FFmpeg's guess from the
    timestamps 25/3 — so without the writer's rate tag (:data:`RATE_TAG`) the frames
    were read back as indices 0, 1, 2 … With it: the source indices 0, 3, 6 … at their
    times, and the frames between reported missing."""
    from seawatch.io.video import RATE_TAG, _tagged_rate
    from seawatch.report.annotate import FRAGMENTED_MP4

    path = tmp_path / "every3.mp4"
    opts = FRAGMENTED_MP4 if fragmented else None
    with VideoWriter(path, fps=25.0, crf=0, container_options=opts) as writer:
        for k in range(0, 90, 3):
            writer.write(_pattern(k), pts=k)
    with av.open(str(path)) as container:
        assert container.metadata[RATE_TAG] == "25"
        assert container.streams.video[0].guessed_rate == Fraction(25, 3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frames = list(VideoReader(path))
    notes = [str(w.message) for w in caught if issubclass(w.category, VideoWarning)]
    assert "2 frame(s) missing between 0.000 s and 0.120 s" in notes[0]
    assert [f.index for f in frames] == list(range(0, 90, 3))
    assert [f.time for f in frames] == pytest.approx([k / 25.0 for k in range(0, 90, 3)])
    for f in frames:
        assert np.mean(np.abs(_gray(f.image) - _gray(_pattern(f.index)))) < 3.0
    assert _tagged_rate({RATE_TAG: "30000/1001"}) == pytest.approx(29.97003)
    for bad in ("", "abc", "1/0", "0", "-25", "5000"):
        assert _tagged_rate({RATE_TAG: bad}) is None
    assert _tagged_rate({}) is None


# ----------------------------------------------------------------------------- corruption
def test_bytes_overwritten_mid_file_skip_and_count_frames_without_failing(
    clip: Path, tmp_path: Path
):
    clean = list(VideoReader(clip))
    data = bytearray(clip.read_bytes())
    mid = len(data) // 2
    rng = np.random.default_rng(1234)
    data[mid : mid + 300] = rng.integers(0, 256, 300, dtype=np.uint8).tobytes()
    bad = tmp_path / "corrupt.mp4"
    bad.write_bytes(bytes(data))
    reader = VideoReader(bad)
    with pytest.warns(VideoWarning):
        frames = list(reader)
    assert reader.skipped >= 1
    assert len(frames) < N and len(frames) + reader.skipped >= N - 1
    idx = [f.index for f in frames]
    times = [f.time for f in frames]
    assert idx == sorted(set(idx)) and times == sorted(set(times))  # strictly increasing
    # lost frames keep their indices: each delivered frame sits at its own time
    np.testing.assert_allclose(times, np.array(idx) / FPS, atol=1e-9)
    # frames well before the damage (B-frames next to it may reference broken data)
    # are the clean ones; every frame still looks like its original
    first_gap = next(i for i, k in enumerate(idx) if k != i)
    assert first_gap >= 4
    for f in frames[: first_gap - 3]:
        np.testing.assert_array_equal(f.image, clean[f.index].image)


def test_frames_lost_before_encoding_keep_the_stream_rate_and_their_indices(
    tmp_path: Path, write_at
):
    """A 25 frames/s recording from which 12 of 40 frames were lost before it was written
    (a camera or recorder that dropped them: their timestamps are absent). Its average
    rate is 28 frames over 1.6 s, 17.5 frames/s; the reader takes the stream's base
    rate, 25, so each lost frame is counted and every frame keeps its index and time
    (before session 15 it took the average rate: the fps was wrong, lost frames went
    uncounted and the indices drifted from the timestamps)."""
    path = tmp_path / "dropped.mp4"
    lost = {5, 6, 7, 11, 17, 18, 23, 27, 28, 29, 30, 35}
    write_at(path, ((i, _pattern(i)) for i in range(40) if i not in lost))
    with av.open(str(path)) as c:  # the premise: the average rate is the kept frames'
        assert float(c.streams.video[0].average_rate) < 20.0
    reader = VideoReader(path)
    with pytest.warns(VideoWarning, match="missing"):
        frames = list(reader)
    assert reader.fps == pytest.approx(25.0)
    kept = [i for i in range(40) if i not in lost]
    assert [f.index for f in frames] == kept
    np.testing.assert_allclose([f.time for f in frames], np.array(kept) / 25.0, atol=1e-9)
    assert reader.skipped == len(lost)


def test_truncated_file_keeps_the_frames_before_the_cut_with_a_warning(clip: Path, tmp_path: Path):
    data = clip.read_bytes()  # the writer puts the index first (+faststart)
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(data[: int(len(data) * 0.6)])
    reader = VideoReader(cut)
    with pytest.warns(VideoWarning, match="ended after|corrupt"):
        frames = list(reader)
    assert 5 <= len(frames) < N
    assert [f.index for f in frames[:5]] == list(range(5))


def test_truncated_file_without_index_is_a_clear_error(tmp_path: Path, write_at):
    path = tmp_path / "late_index.mp4"  # PyAV's default: moov atom at the end
    write_at(path, ((i, _pattern(i)) for i in range(10)))
    cut = tmp_path / "late_cut.mp4"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    with pytest.raises(VideoError, match=r"late_cut\.mp4"):
        VideoReader(cut)


def test_video_without_frames_is_a_clear_error(tmp_path: Path):
    path = tmp_path / "zero.mp4"
    container = av.open(str(path), "w")
    stream = container.add_stream("libx264", rate=Fraction(25))
    stream.width, stream.height, stream.pix_fmt = W, H, "yuv420p"
    container.start_encoding()
    container.close()
    with pytest.raises(VideoError, match=r"zero\.mp4"):
        list(VideoReader(path))
    # a transport stream cut right after its headers: a video stream, no frames
    ts = tmp_path / "headers.ts"
    with VideoWriter(ts, 25.0) as writer:
        for i in range(5):
            writer.write(_pattern(i))
    head = tmp_path / "head_only.ts"
    head.write_bytes(ts.read_bytes()[: 188 * 3])
    with pytest.raises(VideoError, match=r"head_only\.ts"):
        list(VideoReader(head))


def test_size_change_and_timestamp_restart_mid_stream_warn_and_keep_all_frames(tmp_path: Path):
    # two transport streams back to back: the second has another size and restarts at 0 s
    parts = []
    for name, (w, h) in (("a.ts", (96, 64)), ("b.ts", (128, 96))):
        with VideoWriter(tmp_path / name, FPS, gop=5) as writer:
            for i in range(10):
                writer.write(_pattern(i, w, h))
        parts.append((tmp_path / name).read_bytes())
    joined = tmp_path / "joined.ts"
    joined.write_bytes(parts[0] + parts[1])
    with pytest.warns(VideoWarning) as record:
        frames = list(VideoReader(joined))
    text = " ".join(str(w.message) for w in record)
    assert "size changed from 96x64 BGR to 128x96 BGR" in text and "jump back" in text
    assert [f.image.shape for f in frames] == [(64, 96, 3)] * 10 + [(96, 128, 3)] * 10
    assert [f.index for f in frames] == list(range(20))
    np.testing.assert_allclose([f.time for f in frames], np.arange(20) / FPS, atol=1e-6)


@pytest.mark.parametrize(("rotation", "k"), [(-90, -1), (90, 1), (180, 2)])
def test_a_display_rotation_is_applied_as_players_do(tmp_path: Path, rotation: int, k: int):
    """A phone stores a portrait video as landscape pixels plus a display matrix (FFmpeg's
    rotation, degrees counter-clockwise); players turn the frames, decoders do not. The
    reader turns them the same way (np.rot90 by rotation / 90), once reported, and the
    size it announces is then the upright one; the pixels are the stored frame's."""
    path = tmp_path / f"r{rotation}.mp4"
    stored = np.zeros((64, 96, 3), np.uint8)
    stored[:20] = 255  # a bright band along the stored top edge
    stored[:, :12] = 128  # a grey one along the stored left edge
    with av.open(str(path), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height, s.pix_fmt = 96, 64, "yuv420p"
        s.options = {"crf": "0"}
        s.set_display_rotation(rotation)
        for _ in range(3):
            for p in s.encode(av.VideoFrame.from_ndarray(stored, format="bgr24")):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    reader = VideoReader(path)
    with pytest.warns(VideoWarning, match="turned upright") as record:
        frames = list(reader)
    assert len(frames) == 3 and len([w for w in record if "upright" in str(w.message)]) == 1
    want = np.rot90(stored, k=k)
    for f in frames:
        assert f.image.shape == want.shape
        assert np.abs(f.image.astype(int) - want).mean() < 3.0  # lossless but for YUV
    assert reader.size == (want.shape[1], want.shape[0])


@pytest.mark.parametrize("content", [b"", b"not a video at all " * 50])
def test_undecodable_file_is_a_video_error_naming_it(tmp_path: Path, content: bytes):
    path = tmp_path / "junk.mp4"
    path.write_bytes(content)
    with pytest.raises(VideoError, match=r"junk\.mp4"):
        VideoReader(path)


def test_missing_file_is_a_value_error_naming_it():
    with pytest.raises(VideoError, match=r"no-such-clip\.mp4") as info:
        VideoReader("no-such-clip.mp4")
    assert isinstance(info.value, ValueError)


def test_missing_camera_device_is_a_video_error():
    with pytest.raises(VideoError, match="camera"):
        VideoReader("/dev/video97")
    with pytest.raises(VideoError, match="camera 97"):
        VideoReader(97)


def test_unreachable_stream_url_is_a_video_error():
    with pytest.raises(VideoError, match=r"127\.0\.0\.1:9"):
        VideoReader("rtsp://127.0.0.1:9/none", timeout=2.0)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"step": 0}, "step"),
        ({"start": -1.0}, "start"),
        ({"start": 2.0, "end": 1.0}, "end"),
        ({"max_frames": 0}, "max_frames"),
        ({"fps": 0.0}, "fps"),
        ({"backend": "gstreamer"}, "backend"),
        ({"reconnect": -1}, "reconnect"),
        ({"reconnect_wait": -1.0}, "reconnect_wait"),
    ],
)
def test_bad_reader_options_are_value_errors_naming_them(clip: Path, kwargs: dict, name: str):
    with pytest.raises(ValueError, match=name):
        VideoReader(clip, **kwargs)


# ----------------------------------------------------------------------------- streams
@pytest.fixture(scope="module")
def transport_stream(tmp_path_factory: pytest.TempPathFactory) -> Iterator[bytes]:
    path = tmp_path_factory.mktemp("ts") / "stream.ts"
    with VideoWriter(path, FPS, gop=5) as writer:
        for i in range(N):
            writer.write(_pattern(i))
    yield path.read_bytes()


def test_http_stream_is_read_live_with_times_from_zero(
    transport_stream: bytes, stream_server: type
):
    with stream_server(transport_stream) as server:
        reader = VideoReader(f"http://127.0.0.1:{server.port}/live.ts", timeout=5.0)
        assert reader.kind == "url" and reader.live
        frames = _frames(reader)
    assert len(frames) == N
    np.testing.assert_allclose([f.time for f in frames], np.arange(N) / FPS, atol=1e-6)


def test_a_stream_that_drops_ends_with_a_warning_and_keeps_the_frames(
    transport_stream: bytes, stream_server: type
):
    with stream_server(transport_stream) as server:
        reader = VideoReader(f"http://127.0.0.1:{server.port}/drop.ts", timeout=5.0)
        with pytest.warns(VideoWarning, match="stream ended"):
            frames = list(reader)
    assert 5 <= len(frames) < N
    # indices count the frames of the source: they start at 0 and only increase; a frame
    # lost in the cut (decoder reordering) leaves a gap, never a repeat
    idx = [f.index for f in frames]
    assert idx[0] == 0 and bool(np.all(np.diff(idx) > 0))
    assert idx[-1] < N


def test_a_dropped_live_stream_is_reconnected_and_time_and_indices_go_on(
    transport_stream: bytes, stream_server: type
):
    with stream_server(transport_stream, plan=("half", "whole")) as server:
        reader = VideoReader(
            f"http://127.0.0.1:{server.port}/plan.ts",
            timeout=5.0,
            reconnect=2,
            reconnect_wait=0.0,
            backend="pyav",  # one request per attempt ("auto" tries OpenCV after PyAV)
        )
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            frames = list(reader)
        requests = server.requests
    said = " | ".join(str(w.message) for w in caught)
    # the first connection cut off, the second whole, then two refused attempts
    assert requests == 4
    assert reader.reconnects == 1 and reader.lost_seconds >= 0.0
    assert "reconnecting in 0 s (attempt 1 of 2)" in said
    assert "reconnected after" in said and "not back after 2 attempt(s)" in said
    times = np.array([f.time for f in frames])
    idx = np.array([f.index for f in frames])
    assert bool(np.all(np.diff(times) > 0)) and bool(np.all(np.diff(idx) > 0))
    # the second connection's frames: all N, one frame interval apart, after the first's
    first_n = len(frames) - N
    assert 5 <= first_n < N
    np.testing.assert_allclose(np.diff(times[first_n:]), 1.0 / FPS, atol=1e-6)
    assert times[first_n] >= times[first_n - 1] and idx[first_n] > idx[first_n - 1]
    # the pictures of the second connection are the file's frames from the start
    assert np.abs(frames[first_n].image.astype(int) - _pattern(0).astype(int)).mean() < 8


def test_reconnecting_stops_at_max_frames_and_files_never_reconnect(
    transport_stream: bytes, stream_server: type, tmp_path: Path
):
    with stream_server(transport_stream, plan=("whole",)) as server:
        reader = VideoReader(
            f"http://127.0.0.1:{server.port}/plan.ts", reconnect=3, reconnect_wait=0.0, max_frames=4
        )
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no reconnection warning
            frames = list(reader)
        assert len(frames) == 4 and server.requests == 1
    cut = tmp_path / "cut.ts"
    cut.write_bytes(transport_stream[: len(transport_stream) // 2])
    reader = VideoReader(cut, reconnect=3, reconnect_wait=0.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frames = list(reader)
    assert 0 < len(frames) < N and reader.reconnects == 0
    # this reader's warnings (the record is process-wide: an earlier test's stream
    # thread may still be saying that it reconnects)
    assert not any("reconnect" in str(w.message) and str(cut) in str(w.message) for w in caught)


def test_a_live_source_that_never_comes_back_keeps_its_frames(
    transport_stream: bytes, stream_server: type
):
    with stream_server(transport_stream, plan=("half",)) as server:
        reader = VideoReader(
            f"http://127.0.0.1:{server.port}/plan.ts",
            timeout=5.0,
            reconnect=3,
            reconnect_wait=0.0,
            backend="pyav",
        )
        with pytest.warns(VideoWarning, match=r"not back after 3 attempt\(s\); \d+ frames kept"):
            frames = list(reader)
        assert server.requests == 4
    assert 5 <= len(frames) < N and reader.reconnects == 0


# ----------------------------------------------------------------------------- images
def _write_png(path: Path, img: np.ndarray) -> None:
    assert cv2.imwrite(str(path), img)


def test_image_folder_in_natural_order_with_fps_times_and_all_pixel_kinds(tmp_path: Path):
    g8 = np.arange(W * H, dtype=np.uint64).reshape(H, W).astype(np.uint8)
    g16 = (np.arange(W * H, dtype=np.uint32).reshape(H, W) * 9).astype(np.uint16)
    bgr = _pattern(3)
    bgra = np.dstack([bgr, np.full((H, W), 77, np.uint8)])
    _write_png(tmp_path / "frame1.png", g8)
    _write_png(tmp_path / "frame2.png", g16)
    assert cv2.imwrite(str(tmp_path / "frame3.tiff"), g16)
    _write_png(tmp_path / "frame10.png", bgra)
    _write_png(tmp_path / "frame9.png", bgr)
    (tmp_path / ".hidden.png").write_bytes(b"ignored silently")
    reader = VideoReader(tmp_path, fps=4.0)
    assert reader.kind == "folder" and reader.frame_count == 5 and reader.size == (W, H)
    with pytest.warns(VideoWarning, match="96x64 gray to 96x64 BGR"):
        frames = list(reader)
    names = [f.file.name for f in frames]
    assert names == ["frame1.png", "frame2.png", "frame3.tiff", "frame9.png", "frame10.png"]
    assert [f.index for f in frames] == [0, 1, 2, 3, 4]
    assert [f.time for f in frames] == [0.0, 0.25, 0.5, 0.75, 1.0]
    np.testing.assert_array_equal(frames[0].image, g8)
    assert frames[1].image.dtype == np.uint16 and frames[2].image.dtype == np.uint16
    np.testing.assert_array_equal(frames[1].image, g16)
    np.testing.assert_array_equal(frames[2].image, g16)
    np.testing.assert_array_equal(frames[3].image, bgr)
    np.testing.assert_array_equal(frames[4].image, bgr)  # alpha dropped, BGR kept
    gray = list(VideoReader(tmp_path, gray=True, max_frames=4))
    assert all(f.image.ndim == 2 for f in gray)
    with pytest.warns(VideoWarning, match="size changed"):
        selected = list(VideoReader(tmp_path, step=2, start=0.4, fps=4.0))
    assert [f.file.name for f in selected] == ["frame3.tiff", "frame10.png"]


def test_non_image_and_broken_files_in_a_folder_are_skipped_with_warnings(tmp_path: Path):
    _write_png(tmp_path / "a.png", _pattern(0))
    (tmp_path / "notes.txt").write_text("not an image")
    (tmp_path / "b.jpg").write_bytes(b"broken jpeg")
    _write_png(tmp_path / "c.png", _pattern(1, 48, 32))  # another size
    with pytest.warns(VideoWarning) as record:
        reader = VideoReader(tmp_path)
        frames = list(reader)
    text = " ".join(str(w.message) for w in record)
    assert "notes.txt" in text and "b.jpg" in text and "size changed" in text
    assert [f.file.name for f in frames] == ["a.png", "c.png"]
    assert [f.index for f in frames] == [0, 2]  # b.jpg keeps its place
    assert reader.skipped == 1
    assert frames[1].image.shape == (32, 48, 3)  # delivered despite the size change


def test_nan_pixels_of_float_images_are_filled_and_an_all_nan_image_is_skipped(tmp_path: Path):
    """A radiometric thermal camera's float TIFFs with dead (NaN) or saturated (inf)
    pixels: each such pixel gets the median of the image's finite pixels (the first image
    is reported, all are counted in ``filled``), the other pixels are untouched; an
    image without a finite pixel is skipped and counted in ``skipped``."""
    rng = np.random.default_rng(7)
    images = []
    for k in range(3):
        img = (280.0 + rng.normal(0.0, 2.0, (32, 48))).astype(np.float32)
        if k > 0:
            img[3, 5], img[20, 40], img[31, 0] = np.nan, np.inf, -np.inf
        images.append(img)
        cv2.imwrite(str(tmp_path / f"t{k}.tiff"), img)
    cv2.imwrite(str(tmp_path / "t3.tiff"), np.full((32, 48), np.nan, np.float32))
    reader = VideoReader(tmp_path)
    with pytest.warns(VideoWarning) as record:
        frames = list(reader)
    text = " ".join(str(w.message) for w in record)
    assert "t1.tiff: 3 NaN or inf pixel(s)" in text and "t2.tiff: 3" not in text
    assert "t3.tiff: no finite pixel" in text
    assert (reader.filled, reader.skipped) == (2, 1)
    assert [f.file.name for f in frames] == ["t0.tiff", "t1.tiff", "t2.tiff"]
    np.testing.assert_array_equal(frames[0].image, images[0])
    for f, img in zip(frames[1:], images[1:], strict=True):
        ok = np.isfinite(img)
        np.testing.assert_array_equal(f.image[ok], img[ok])
        assert np.all(f.image[~ok] == np.median(img[ok]))


def test_empty_folder_and_folder_without_images_are_clear_errors(tmp_path: Path):
    with pytest.raises(VideoError, match="no image files"):
        VideoReader(tmp_path)
    (tmp_path / "readme.md").write_text("x")
    with pytest.raises(VideoError, match=r"readme\.md"):
        VideoReader(tmp_path)


def test_folder_of_only_broken_images_raises_after_warnings(tmp_path: Path):
    (tmp_path / "a.png").write_bytes(b"nope")
    reader = VideoReader(tmp_path)
    with pytest.warns(VideoWarning), pytest.raises(VideoError, match="none of the 1"):
        list(reader)


def test_single_image_file_is_one_frame(tmp_path: Path):
    path = tmp_path / "one.png"
    _write_png(path, _pattern(5))
    (frame,) = list(VideoReader(path))
    assert frame.index == 0 and frame.time == 0.0 and frame.file == path
    np.testing.assert_array_equal(read_image(path), _pattern(5))
    with pytest.raises(VideoError, match=r"missing\.png"):
        read_image(tmp_path / "missing.png")


@pytest.mark.parametrize(
    ("source", "realtime"),
    [("rtsp://mast/stream", True), ("RTSP://mast/stream", True), ("udp://239.0.0.1:5000", True),
     ("srt://cam:9000", True), ("rtmp://host/live", True), (0, True), ("/dev/video0", True),
     ("http://host/clip.mp4", False), ("https://host/live.m3u8", False)],
)  # fmt: skip
def test_realtime_sources_are_cameras_and_streaming_protocols_not_http_or_files(source, realtime):
    """Sources that send frames whether or not they are read (the track job drops frames
    to keep up with them by default): camera devices and the streaming protocols; an
    HTTP URL may be a file served as fast as it is read, and files and folders wait."""
    from seawatch.io.video import _classify, _realtime

    assert _realtime(_classify(source)[0], source) == realtime


def test_an_http_stream_and_a_file_are_not_realtime(
    transport_stream: bytes, stream_server: type, tmp_path
):
    with stream_server(transport_stream) as server:
        reader = VideoReader(f"http://127.0.0.1:{server.port}/clip.ts", timeout=5.0)
        assert reader.live and not reader.realtime
        reader.close()
    path = tmp_path / "clip.ts"
    path.write_bytes(transport_stream)
    with VideoReader(path) as reader:
        assert not reader.live and not reader.realtime
