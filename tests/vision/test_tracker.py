"""VisualTracker: ids, occlusion survival by prediction, CLE on rendered footage."""

from __future__ import annotations

import math
import threading
from pathlib import Path

import cv2
import numpy as np
import pytest

from seawatch.io.mot import read_mot
from seawatch.metrics import mot_metrics
from seawatch.metrics.cle import centre_location_error
from seawatch.scenarios.ship_video import detect_video, read_truth
from seawatch.synth import render_case
from seawatch.vision.detect import Detections
from seawatch.vision.tracker import TRACK_COLUMNS, VisualTracker, frames_lost, tracks_to_rows


def _crossing(T=80, gap=range(30, 38)):
    """Two boxes crossing at frame ~37; object 2 undetected during ``gap``."""
    rng = np.random.default_rng(1234)
    gt, dets = [], []
    for k in range(T):
        a = np.array([100.0 + 2 * k, 200.0, 40.0, 10.0])
        b = np.array([250.0 - 2 * k, 206.0, 30.0, 12.0])
        gt += [[k, 1, *a], [k, 2, *b]]
        d = [a + np.r_[rng.normal(0, 1.0, 2), 0, 0]]
        if k not in gap:
            d.append(b + np.r_[rng.normal(0, 1.0, 2), 0, 0])
        dets.append(np.array(d))
    return np.array(gt), dets


@pytest.mark.parametrize("name", ["afkf", "fkf", "kf"])
def test_one_id_per_ship_through_missed_detections(name):
    gt, dets = _crossing()
    vt = VisualTracker(detector=lambda *a, **k: None, filter=name, horizon=False)
    out = vt.track_detections(dets)
    assert all(t.shape[1] == len(TRACK_COLUMNS) for t in out)
    rows = tracks_to_rows(out)
    assert np.unique(rows[:, 1]).size == 2  # no id switch, no new id after the gap
    r = centre_location_error(rows, gt)
    assert sorted(r.matches.values()) == [1, 2]
    # confirmed after 3 detections (M-of-N 3/5): frames 2.. of each track are covered,
    # including the 8 frames without detections of object 2 (coasting)
    assert r.coverage == pytest.approx(78 / 80)
    coasting = [t[t[:, 7] > 0] for t in out[30:38]]
    assert all(c.shape[0] == 1 for c in coasting)
    assert r.mean_px < 3.0


@pytest.mark.parametrize("name", ["afkf", "kf"])
def test_coast_over_lost_frames_keeps_the_track(name):
    """A boat (10 × 4 px) moving 4 px a frame, seen in frames 0-29, then frames 30-34
    lost (a stream that dropped them) and seen again from frame 35. Told that 5 frames
    were lost (:meth:`VisualTracker.coast`), the track predicts over them: at frame 35
    its box centre is on the boat to 0.5 px, with the same id. Without it the filter
    steps one frame where six passed, the box is 20 px from its prediction (outside the
    gate, not overlapping) and a second track is born on it."""

    def box(k):
        return np.array([[100.0 + 4.0 * k, 200.0, 10.0, 4.0]])

    for told in (True, False):
        vt = VisualTracker(detector=lambda *a, **k: None, filter=name, horizon=False)
        for k in range(30):
            vt.update(box(k))
        if told:
            vt.coast(5)
        out = [vt.update(box(k)) for k in range(35, 40)]
        ids = {int(i) for t in out for i in t[:, 0]}
        if told:
            assert ids == {1}
            centre = out[0][0, 1:3] + 0.5 * out[0][0, 3:5]
            assert np.hypot(*(centre - [245.0, 202.0])) < 0.5
        else:
            assert 2 in ids
    with pytest.raises(ValueError, match="frames"):
        VisualTracker(horizon=False).coast(-1)


@pytest.mark.parametrize("name", ["afkf", "kf"])
def test_a_repeated_box_is_no_new_measurement(name):
    """A boat (10 × 4 px) moving 0.5 px a frame whose box stays put for three frames (the
    same box exactly: whole-pixel edges that did not move) and then jumps to where the
    boat is. The frozen boxes are no measurements: the track goes on at the boat's speed
    through them (to 0.05 px); taken as measurements they pull it back (over 0.5 px
    behind the boat at the third). A box that stays the same for longer than
    ``STALE_LIMIT`` frames is a still scene, measured again: the track of a boat that
    stops coasts on through the first ``STALE_LIMIT`` repeats, then settles on it."""
    from seawatch.vision.tracker import STALE_LIMIT

    def box(x):
        return np.array([[x, 200.0, 10.0, 4.0]])

    vt = VisualTracker(detector=lambda *a, **k: None, filter=name, horizon=False)
    for k in range(40):
        vt.update(box(100.0 + 0.5 * k))
    frozen = [vt.update(box(100.0 + 0.5 * 39))[0] for _ in range(3)]
    truth = 100.0 + 0.5 * np.arange(40, 43)
    assert np.abs(np.array([t[1] for t in frozen]) - truth).max() < 0.05
    assert all(t[7] == 0 for t in frozen)  # a hit, not a miss
    ref = VisualTracker(detector=lambda *a, **k: None, filter=name, horizon=False)
    for k in range(40):  # the tracker without the flags: every box measured
        ref.mtt.step(box(100.0 + 0.5 * k)[:, :4])
    for _ in range(3):
        st = ref.mtt.step(box(100.0 + 0.5 * 39)[:, :4])
    assert truth[-1] - st.boxes[0, 0] > 0.5
    # the boat stops where it is: the same box for 4 × STALE_LIMIT frames
    out = [vt.update(box(truth[-1]))[0] for _ in range(4 * STALE_LIMIT)]
    assert abs(out[-1][1] - truth[-1]) < 0.1


def _numbered_frames(indices):
    """``Frame`` objects of the given source indices at 25 frames/s, each image holding
    its index in pixel (0, 0), for :func:`_boat_detector`."""
    from seawatch.io.video import Frame

    frames = []
    for k in indices:
        img = np.zeros((8, 8), np.uint8)
        img[0, 0] = k
        frames.append(Frame(index=k, time=k / 25.0, image=img))
    return frames


def _boat_detector(image, **_):
    """The box of a boat (10 × 4 px) moving 4 px a frame, at the frame's index."""
    k = int(image[0, 0])
    return np.array([[100.0 + 4.0 * k, 200.0, 10.0, 4.0]])


def test_track_frames_coasts_over_frames_whose_index_skips():
    """``track_frames`` on ``Frame`` objects whose indices skip 30-34 (lost from the
    source): the same boat as above keeps one id, one output per frame given, and
    :func:`frames_lost` rounds index gaps to whole decimation steps."""
    frames = _numbered_frames(k for k in range(40) if k not in range(30, 35))
    vt = VisualTracker(detector=_boat_detector, horizon=False, motion=False)
    out = vt.track_frames(frames, ahead=False)
    assert len(out) == len(frames)
    assert {int(i) for t in out for i in t[:, 0]} == {1}
    assert frames_lost(35, 29) == 5 and frames_lost(30, 29) == 0 and frames_lost(29, 30) == 0
    assert frames_lost(10, 5, step=5) == 0 and frames_lost(16, 5, step=5) == 1
    assert frames_lost(13, 5, step=5) == 1  # 8 frames: nearer two steps than one


def test_a_boat_seen_in_every_third_frame_is_tracked_from_its_third():
    """Keep-up on a source three times faster than the job: only every third frame
    (indices 0, 3, 6, …) reaches ``track_frames``. The frames between were never looked
    at, so they are no misses: the boat's track is confirmed at the third frame given
    (3-of-5 among the frames given), keeps one id, and its box is on the boat at every
    frame given after (to 1 px; 4 px a frame, 12 px between frames given). Counted as
    frames without the boat (session 25's code), 3 of 5 was never reached and the boat
    was never tracked."""
    frames = _numbered_frames(range(0, 90, 3))
    for name in ("afkf", "kf"):
        vt = VisualTracker(detector=_boat_detector, filter=name, horizon=False, motion=False)
        out = vt.track_frames(frames, ahead=False)
        assert [t.shape[0] for t in out[:4]] == [0, 0, 1, 1]
        assert {int(i) for t in out for i in t[:, 0]} == {1}
        for fr, t in zip(frames[2:], out[2:], strict=True):
            assert np.abs(t[0, 1:3] - [100.0 + 4.0 * fr.index, 200.0]).max() < 1.0


def test_waterline_defaults_to_box_bottom_centre():
    vt = VisualTracker(detector=lambda *a, **k: None, horizon=False, filter="kf")
    out = [vt.update(np.array([[10.0, 20.0, 8.0, 4.0]])) for _ in range(4)]
    t = out[-1][0]
    assert t[5] == pytest.approx(t[1] + 0.5 * t[3], abs=1e-6)
    assert t[6] == pytest.approx(t[2] + t[4], abs=1e-6)


def test_bad_arguments_raise_naming_them():
    with pytest.raises(ValueError, match="filter"):
        VisualTracker(filter="ukf")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="memory"):
        VisualTracker(memory=0)
    with pytest.raises(ValueError, match="detections"):
        VisualTracker(horizon=False).update(np.zeros((2, 3)))


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    out = {}
    for name in ("large", "meeting"):
        res = render_case(name, tmp_path_factory.mktemp(name), duration=3.0, width=960, height=540)
        out[name] = (detect_video(res.video), read_truth(res.truth))
        out[f"{name}-video"] = res.video
    # the large ship with the camera panning ±4° in 3 s (peak 8.4°/s, 4.8 px a frame)
    res = render_case(
        "large", tmp_path_factory.mktemp("pan"), duration=3.0, width=960, height=540,
        pan=(math.radians(4.0), 3.0),
    )  # fmt: skip
    offsets: list[np.ndarray] = []
    out["large-pan"] = (detect_video(res.video, offsets=offsets), read_truth(res.truth))
    out["large-pan-offsets"] = offsets
    return out


def test_stream_ahead_gives_the_sequential_results(rendered):
    """Decoding, horizon and detection in background threads change nothing: the same
    horizons, detections and tracks, frame by frame, as the step-by-step loop."""
    from seawatch.io.video import VideoReader

    seq, ahead = VisualTracker(), VisualTracker()
    with VideoReader(rendered["meeting-video"]) as reader:
        frames = list(reader)
    assert len(frames) == 75
    got = list(ahead.stream(frames))
    assert [fr.index for fr, _, _ in got] == [fr.index for fr in frames]
    for fr, hz, det in got:
        want = seq.step(fr.image, fr.time)
        assert (hz.found, hz.rho, hz.theta) == (
            seq.last_horizon.found, seq.last_horizon.rho, seq.last_horizon.theta
        )  # fmt: skip
        np.testing.assert_array_equal(ahead.update(det), want)
    a = VisualTracker().track_frames(frames)
    b = VisualTracker().track_frames(frames, ahead=False)
    assert len(a) == len(b) == 75 and sum(r.shape[0] for r in a) > 75
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)


def test_stream_stops_its_threads_and_closes_the_source_when_left_early():
    import threading

    closed = []

    def frames():
        try:
            for k in range(1000):
                yield np.full((60, 80), 40 + k % 3, np.uint8)
        finally:
            closed.append(True)

    import cv2

    before, cv_threads = threading.active_count(), cv2.getNumThreads()
    stream = VisualTracker(horizon=False).stream(frames())
    for k, _ in enumerate(stream):
        assert cv2.getNumThreads() == 1  # OpenCV's pool off while the stream runs
        assert {"seawatch-read", "seawatch-detect"} <= {t.name for t in threading.enumerate()}
        if k == 3:
            break
    stream.close()
    assert cv2.getNumThreads() == cv_threads
    for t in threading.enumerate():
        if t.name in ("seawatch-read", "seawatch-detect"):
            t.join(timeout=5)
    assert closed == [True]
    assert threading.active_count() == before


class _Camera:
    """A source that sends frames in real time: they come whether or not they are read."""

    realtime = True

    def __init__(self, n: int):
        self.n = n
        self.sent = threading.Event()

    def __iter__(self):
        from seawatch.io.video import Frame

        for k in range(self.n):
            yield Frame(k, k / 25.0, np.full((60, 80), 40 + k % 3, np.uint8))
        self.sent.set()


def test_stream_keeps_up_with_a_realtime_source_by_dropping_frames():
    """A caller that falls behind a camera: the frames that come while three wait are
    dropped before their horizon and detection (counted in ``frames_dropped``, a warning
    names the first), the others come in order; without ``keep_up`` (the default for a
    source without ``realtime``) every frame comes."""
    camera = _Camera(40)
    vt = VisualTracker(horizon=False)
    with pytest.warns(UserWarning, match=r"frame \d+: processing is behind the source"):
        stream = vt.stream(camera)
        got = [next(stream)[0].index]
        assert camera.sent.wait(10.0)  # the whole clip sent while the caller was busy
        got += [fr.index for fr, _, _ in stream]
    assert got == sorted(got) and got[0] == 0
    assert vt.frames_dropped == 40 - len(got) >= 25  # at most 1 + 3 + 1 + 3 + 3 kept
    slow = _Camera(40)
    slow.realtime = False
    vt = VisualTracker(horizon=False)
    stream = vt.stream(slow)
    got = [next(stream)[0].index]
    assert not slow.sent.wait(0.3)
    got += [fr.index for fr, _, _ in stream]
    assert got == list(range(40)) and vt.frames_dropped == 0


def test_frames_dropped_to_keep_up_are_coasted_over_by_index():
    """The tracks coast over the frames dropped as over frames the source lost: a ship
    seen at frames 0-9 and 20-29 (10-19 dropped) keeps its track and id."""

    def box(k):
        return np.array([[100.0 + 2 * k, 200.0, 40.0, 12.0]])

    vt = VisualTracker(detector=lambda *a, **k: None, horizon=False)
    ids = set()
    for k in [*range(10), *range(20, 30)]:
        vt.coast_to(k)
        rows = vt.update(box(k))
        ids |= set(rows[:, 0].astype(int))
        if k == 20:
            assert abs(rows[0, 1] + rows[0, 3] / 2 - (120.0 + 2 * k)) < 2.0
    assert len(ids) == 1


def test_stream_raises_a_detector_error_at_its_frame_after_the_frames_before():
    def detector(image, **_):
        if image[0, 0] == 3:
            raise RuntimeError("detector failed on frame 3")
        return np.zeros((0, 4))

    images = [np.full((60, 80), k, np.uint8) for k in range(6)]
    seen = []
    with pytest.raises(RuntimeError, match="frame 3"):
        for fr, _, _ in VisualTracker(detector=detector, horizon=False).stream(images):
            seen.append(int(fr[0, 0]))
    assert seen == [0, 1, 2]


def test_rendered_large_ship_cle_below_2_percent_of_diagonal(rendered):
    dets, truth = rendered["large"]
    vt = VisualTracker(detector=lambda *a, **k: None, horizon=False)
    rows = tracks_to_rows(vt.track_detections(dets))
    r = centre_location_error(rows, truth)
    assert np.unique(rows[:, 1]).size == 1
    assert r.coverage > 0.9
    assert r.mean_percent < 2.0  # issue 6 target (measured ~0.4 %)


@pytest.mark.parametrize("name", ["afkf", "kf"])
def test_rendered_large_ship_through_a_panning_camera_keeps_its_id(name, rendered):
    """The camera pans ±4° about its heading in 3 s (the ship sweeps ±58 px across the
    frame, up to 4.8 px a frame, with 0.4 px/frame² of acceleration): one track id, the
    same coverage as the fixed camera, CLE under the 2 % target. Without camera-motion
    compensation the constant-velocity model lags the pan's acceleration (measured:
    1.64 % afkf, 1.15 % kf, against 0.27 % with the camera fixed); with it (the offsets
    the stream measured above the horizon) 0.69 % and 0.59 % (session 29): the clip
    starts mid-pan at 4.8 px a frame, and the first 5 frames are needed to tell a pan
    from noise."""
    dets, truth = rendered["large-pan"]
    errors = {}
    for compensated in (False, True):
        offsets = rendered["large-pan-offsets"] if compensated else None
        vt = VisualTracker(detector=lambda *a, **k: None, horizon=False, filter=name)
        rows = tracks_to_rows(vt.track_detections(dets, offsets))
        r = centre_location_error(rows, truth)
        assert np.unique(rows[:, 1]).size == 1
        assert r.coverage > 0.95
        assert r.mean_percent < 2.0
        errors[compensated] = r.mean_percent
    assert errors[True] < 0.6 * errors[False]


def _zooming_ship(seed: int = 0):
    """A 40 × 12 px ship crossing 0.3 px a frame at column 120 of a 640 × 360 frame,
    seen by a camera that zooms out by 4 % a frame in frames 15–29 about the frame's
    centre: its detections (the zoomed true box, ±0.3 px), the zooms (scale, cx, cy)
    and the true boxes in the frame's pixels (rows frame, id, x, y, w, h)."""
    rng = np.random.default_rng(seed)
    centre = np.array([319.5, 179.5])
    scale, dets, zooms, truth = 1.0, [], [], []
    for k in range(60):
        scale *= 0.96 if 15 <= k < 30 else 1.0
        box = np.array([120.0 + 0.3 * k, 200.0, 40.0, 12.0])  # first frame's pixels
        seen = np.r_[centre + scale * (box[:2] - centre), scale * box[2:]]
        truth.append([k, 1, *seen])
        dets.append((seen + rng.normal(0.0, 0.3, 4))[None, :])
        zooms.append(np.r_[scale, centre])
    return dets, zooms, np.array(truth)


@pytest.mark.parametrize("name", ["afkf", "kf"])
def test_a_zooming_camera_is_tracked_at_the_first_frames_focal_length(name):
    """A zoom out moves the ship towards the frame's centre and shrinks it (here 93 px
    in 15 frames, 8 px a frame at first): in the frame's pixels the constant-velocity
    model lags it and overshoots when the zoom stops. Given the camera's zoom (what
    :class:`CameraMotion` measures) the track filters the ship where the first frame
    saw it, moving steadily, and reports it in each frame's pixels: one id, the error
    under half, the box's size the zoomed one (measured: 0.86 → 0.24 px afkf, 0.77 →
    0.25 px kf)."""
    dets, zooms, truth = _zooming_ship()
    errors = {}
    for given in (False, True):
        vt = VisualTracker(detector=lambda *a, **k: None, horizon=False, filter=name)
        per_frame = vt.track_detections(dets, zooms=zooms if given else None)
        rows = tracks_to_rows(per_frame)
        r = centre_location_error(rows, truth)
        errors[given] = r.mean_px
        if given:
            assert np.unique(rows[:, 1]).size == 1 and r.coverage > 0.95
            last = rows[rows[:, 0] == 59][0]
            assert last[4:6] == pytest.approx(truth[59, 4:6], rel=0.05)
            # the water line: the box's bottom centre (no detection gave another), and
            # no missed frames
            tracks = np.concatenate(per_frame)
            bottom = tracks[:, 1:3] + tracks[:, 3:5] * [0.5, 1.0]
            np.testing.assert_allclose(tracks[:, 5:7], bottom, atol=0.5)
            assert np.all(tracks[:, 7] == 0)
            # zoomed out, a detector's pixel is 1 / 0.96¹⁵ of the first frame's: so is
            # its noise floor there; a new video starts at the first frame's again
            assert vt.mtt.sigma_z == pytest.approx(2.0 / 0.96**15)
            vt.reset()
            assert vt.mtt.sigma_z == 2.0
    assert errors[True] < errors[False] / 2, errors


def test_rendered_meeting_occlusion_handling_halves_the_centre_error(rendered):
    """The 3 s meeting clip, whose two ships are one box in most frames: with the
    tracker's occlusion handling (each ship measured by its own free box edge) the
    centre location error is under 0.6 × that of the same tracker without it, on the
    same detections, and more truth frames have an estimate (measured: 11.1 against
    20.2 %, coverage 0.95 against 0.87)."""
    dets, truth = rendered["meeting"]
    runs = {}
    for occlusion in (True, False):
        vt = VisualTracker(detector=lambda *a, **k: None, horizon=False, occlusion=occlusion)
        runs[occlusion] = centre_location_error(tracks_to_rows(vt.track_detections(dets)), truth)
    assert runs[True].mean_percent < 0.6 * runs[False].mean_percent
    assert runs[True].coverage > runs[False].coverage


@pytest.mark.xfail(
    strict=True,
    reason="the two ships' water lines are 1.1-1.3 px apart at 960x540, at the detector's "
    "1-px split threshold: split in 34 of 75 frames, merged in the rest; the 3 s "
    "meeting clip gives 3 tracks and both ships are matched to the merged box's track "
    "(coverage 49 %)",
)
def test_rendered_meeting_keeps_one_id_per_ship(rendered):
    dets, truth = rendered["meeting"]
    vt = VisualTracker(detector=lambda *a, **k: None, horizon=False)
    rows = tracks_to_rows(vt.track_detections(dets))
    r = centre_location_error(rows, truth)
    assert sorted(set(r.matches.values())) == [1, 2]
    assert np.unique(rows[:, 1]).size == 2


# ------------------------------------------------------------------ real detections

FVESSEL = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "fvessel"


@pytest.mark.skipif(
    not (FVESSEL / "Video-01_re_detection.txt").is_file(),
    reason=f"FVessel sample not found at {FVESSEL} (shared data folder absent)",
)
def test_fvessel_real_detections_keep_every_ship_with_few_ids():
    """FVessel Video-01 (MIT): the dataset authors' 1,822 detections of 5 ships at 1
    frame/s, tracked with VisualTracker's defaults and scored by TrackEval (IoU >= 0.5)
    against the ground truth (docs/results/fvessel/). Measured (session 12, with the
    size-relative box noise sigma_z_rel = 3 %): HOTA 0.672, MOTA 0.847, IDF1 0.907, 1 ID
    switch, 6 track ids (session 11, σ_z alone: 0.594, 0.802, 0.773, 3, 11; the authors'
    tracker: 0.652, 0.867, 0.847, 2, 9). The bounds are those numbers with a margin, a
    regression guard on real data, and every ship must be covered by a track for most
    of its frames."""
    gt = read_mot(FVESSEL / "Video-01_gt_tracking.txt")
    det = read_mot(FVESSEL / "Video-01_re_detection.txt")
    scans = [
        Detections.from_boxes(det[det[:, 0] == f, 2:6]) for f in range(int(gt[:, 0].max()) + 1)
    ]
    vt = VisualTracker(detector=lambda *a, **k: None, horizon=False, fps=1.0)
    rows = tracks_to_rows(vt.track_detections(scans))
    m = mot_metrics(gt, rows, "iou", 0.5)
    assert m.hota.hota > 0.65 and m.clear.mota > 0.82 and m.identity.idf1 > 0.88
    assert m.clear.id_switches <= 2 and np.unique(rows[:, 1]).size <= 9
    assert m.clear.fn <= 70  # of 1,709 truth boxes


MARDCT = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "mardct_ir3"


@pytest.mark.skipif(
    not (MARDCT / "boxes.csv").is_file(),
    reason=f"MarDCT ir-3 frames not found at {MARDCT} (shared data folder absent)",
)
def test_mardct_real_thermal_boat_is_tracked_through_the_zoom():
    """The 88 real thermal MarDCT ir-3 frames (a small boat near a coastline, TIRSD's
    box per frame; read in place), from pixels to tracks with VisualTracker's defaults:
    the boat has a track in at least 95 % of the frames, one track through the camera's
    zoom out (5–8 % a frame in frames 1–13, the boat crossing 150 px of the frame and
    stopping dead with it), and the centre location error (§1.6) is under 1.2 px. The
    zoom measured frame by frame adds up to the scale of frame 17 against frame 0 that
    one registration of the two frames finds (a search over the scale). Measured
    (session 29): coverage 97.7 % (the first two frames, before confirmation), 1.02 px
    (afkf); without the zoom 1.29 px, with 11 and 17 px in frames 14–15 where the
    track coasted on at the zoom's speed and a new one took over."""
    from seawatch.io.video import VideoReader

    boxes = np.genfromtxt(MARDCT / "boxes.csv", delimiter=",", names=True, dtype=None)
    order = np.argsort(boxes["frame"])
    truth = np.column_stack([np.arange(order.size), np.ones(order.size)]
                            + [boxes[k][order] for k in ("x", "y", "w", "h")])  # fmt: skip
    vt = VisualTracker()
    scales = []
    with VideoReader(MARDCT / "images", fps=25.0) as reader:
        per_frame = []
        for _, _, det in vt.stream(reader):
            per_frame.append(vt.update(det))
            scales.append(vt.camera_zoom[0])
    rows = tracks_to_rows(per_frame)
    c = centre_location_error(rows, truth)
    assert c.coverage >= 0.95, c.coverage
    assert c.mean_px < 1.2, c.mean_px
    centres = truth[:, 2:4] + truth[:, 4:6] / 2
    near = np.hypot(*(rows[:, 2:4] + rows[:, 4:6] / 2 - centres[rows[:, 0].astype(int)]).T)
    boat = rows[(near < 12.0) & (rows[:, 0] <= 30)]
    assert np.unique(boat[:, 1]).size == 1
    # the scale of frame 17 against frame 0, by one registration: frame 0 magnified
    # about the centre by each scale, the best phase-correlation peak over the coast
    first, later = (
        cv2.imread(str(MARDCT / "images" / f"ir-3_{n}.png"), cv2.IMREAD_GRAYSCALE).astype(
            np.float32
        )
        for n in (133, 150)
    )
    h, w = first.shape
    cx, cy = (w - 1) / 2, (h - 1) / 2
    hann = cv2.createHanningWindow((280, 85), cv2.CV_32F)
    peaks = []
    for s in np.arange(0.40, 0.52, 0.0025):
        m = np.float32([[s, 0, (1 - s) * cx], [0, s, (1 - s) * cy]])
        warped = cv2.warpAffine(first, m, (w, h))[150:235, 180:460].copy()
        peaks.append((cv2.phaseCorrelate(warped, later[150:235, 180:460].copy(), hann)[1], s))
    assert scales[17] == pytest.approx(max(peaks)[1], abs=0.01)
