"""Camera motion (``seawatch.vision.motion``): the sideways shift of a panning camera and
the scale of a zooming one, measured above the horizon, against shifts and zooms applied
to a textured frame."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from seawatch.vision.horizon import HorizonEstimate
from seawatch.vision.motion import CameraMotion

W, H, ROW = 640, 360, 150  # frame size, horizon row [px]


def _scene(seed: int = 0) -> np.ndarray:
    """A wide grey panorama: smooth cloud texture above row ROW, sea texture below."""
    rng = np.random.default_rng(seed)
    noise = rng.normal(size=(H, 3 * W)).astype(np.float32)
    clouds = cv2.GaussianBlur(noise, (0, 0), 3.0)
    clouds = 140.0 + 40.0 * clouds / clouds.std()
    return np.clip(clouds, 0, 255).astype(np.float32)


def _view(pano: np.ndarray, x: float, sea_x: float = 0.0, seed: int = 1) -> np.ndarray:
    """The camera's frame looking at pano column ``x`` (sub-pixel), the sea below ROW
    drifting by ``sea_x`` on its own (travelling waves), with 1-level noise."""
    m = np.float32([[1, 0, -x - W], [0, 1, 0]])
    img = cv2.warpAffine(pano, m, (W, H), flags=cv2.INTER_LINEAR)
    sea = cv2.warpAffine(pano[::-1].copy(), np.float32([[1, 0, -sea_x - W], [0, 1, 0]]), (W, H))
    img[ROW:] = 0.5 * sea[ROW:]  # a darker, different texture below the horizon
    noise = np.random.default_rng(seed).normal(0.0, 1.0, img.shape)
    return np.clip(img + noise, 0, 255).astype(np.uint8)


HORIZON = HorizonEstimate.from_endpoints(ROW, ROW, W, H, confidence=1.0)


def test_a_pan_is_measured_frame_by_frame_and_accumulated():
    """A pan speeding up from 0.5 to 4 px a frame (content moving left): each frame's
    shift to 0.2 px, the total within 3 %, the vertical left alone."""
    pano = _scene()
    cm = CameraMotion()
    steps = np.linspace(0.5, 4.0, 30)
    xs = np.cumsum(np.r_[0.0, steps])
    shifts, offsets = [], []
    for k, x in enumerate(xs):
        offsets.append(cm.update(_view(pano, x, seed=k), HORIZON))
        shifts.append(cm.shift[0])
    assert np.max(np.abs(np.array(shifts[1:]) + steps)) < 0.2
    # the pan starts once over half the window (5 shifts) has a median of 0.5 px or
    # more: the 5th here; from there on every shift is added up
    assert not np.any(offsets[:5]) and offsets[5][0] < 0.0
    assert offsets[-1][0] == pytest.approx(-(xs[-1] - xs[4]), rel=0.03)
    assert cm.moving and offsets[-1][1] == 0.0


def test_a_fixed_camera_accumulates_nothing_even_when_the_sea_drifts():
    """Travelling waves move the sea by 1 px a frame (the rendered demo's whole frame
    correlates at that): measured above the horizon, the fixed camera stays at 0."""
    pano = _scene()
    cm = CameraMotion()
    for k in range(30):
        offset = cm.update(_view(pano, 0.0, sea_x=1.0 * k, seed=k), HORIZON)
    assert np.array_equal(offset, [0.0, 0.0]) and not cm.moving
    assert cm.scale == 1.0 and not cm.zooming


def _zoomed(pano: np.ndarray, scale: float, across: float | None = None, seed: int = 0):
    """The camera's frame (W × H) of the middle of a larger panorama magnified by
    ``scale`` about the frame's centre (``across``: the columns alone by it, the rows
    not), with 1-level noise, and its horizon (row ROW of the unmagnified frame)."""
    sx = scale if across is None else across
    sy = scale if across is None else 1.0
    cx, cy = (W - 1) / 2, (H - 1) / 2
    px, py = (pano.shape[1] - 1) / 2, (pano.shape[0] - 1) / 2  # the view's centre there
    m = np.float32([[sx, 0, cx - sx * px], [0, sy, cy - sy * py]])
    img = cv2.warpAffine(pano, m, (W, H), flags=cv2.INTER_LINEAR)
    img = img + np.random.default_rng(seed).normal(0.0, 1.0, img.shape)
    row = cy + sy * (ROW - cy)
    horizon = HorizonEstimate.from_endpoints(row, row, W, H, confidence=1.0)
    return np.clip(img, 0, 255).astype(np.uint8), horizon


def _panorama(seed: int = 0) -> np.ndarray:
    """Cloud texture three frames wide and high (room for a zoom out)."""
    noise = np.random.default_rng(seed).normal(size=(3 * H, 3 * W)).astype(np.float32)
    clouds = cv2.GaussianBlur(noise, (0, 0), 3.0)
    return np.clip(140.0 + 40.0 * clouds / clouds.std(), 0, 255).astype(np.float32)


def test_a_zoom_is_measured_frame_by_frame_and_accumulated():
    """A zoom out by 4 % a frame for 12 frames, then none (MarDCT ir-3 zooms out by
    5–8 % a frame for 13): each frame's scale change to 0.3 %, the accumulated scale to
    1 % of 0.96¹², the first frame's change too (a zoom starts on two in a row), no
    pan made of it, and the scale held once the zoom stops."""
    pano = _panorama()
    cm = CameraMotion()
    steps = [1.0] * 5 + [0.96] * 12 + [1.0] * 10
    truth = np.cumprod(steps)
    scales, zooms = [], []
    for k, s in enumerate(truth):
        cm.update(*_zoomed(pano, s, seed=k))
        scales.append(cm.scale)
        zooms.append(cm.zoom)
    assert scales[:6] == [1.0] * 6  # the zoom's first frame: not yet known to be one
    assert np.max(np.abs(np.log(np.array(zooms[7:17]) / 0.96))) < 0.003
    assert scales[16] == pytest.approx(truth[16], rel=0.01)
    assert scales[-1] == scales[20]  # stopped: nothing more added
    assert np.max(np.abs(cm.offset)) < 1.0


def test_a_stretch_across_alone_is_no_zoom():
    """The sky's columns spread by 1 % a frame and its rows not (a boat's camera yawing
    as it pitches, the rendered uav-sea clip: 0.4–0.8 % a frame across for 60 frames):
    the halves' shifts say zoom, the rows say no, and the scale stays 1."""
    pano = _panorama()
    cm = CameraMotion()
    for k in range(20):
        cm.update(*_zoomed(pano, 1.0, across=1.01**k, seed=k))
        assert not cm.zooming
    assert cm.scale == 1.0


def test_the_registration_leaves_its_bands_as_they_were():
    """OpenCV's phase correlation multiplies its inputs by the window in place; the
    band kept for the next frame must stay the frame's own."""
    from seawatch.vision.motion import _correlate

    rng = np.random.default_rng(3)
    a = rng.random((40, 80)).astype(np.float32)
    b = np.roll(a, 2, axis=1)
    a0, b0 = a.copy(), b.copy()
    (dx, _), _ = _correlate(a[:20], b[:20], cv2.createHanningWindow((80, 20), cv2.CV_32F))
    assert dx == pytest.approx(2.0, abs=0.2)
    assert np.array_equal(a, a0) and np.array_equal(b, b0)


def test_a_rendered_night_sky_gives_no_motion(tmp_path):
    """A thermal night sky is grain without structure: its correlation peaks are weak
    (0.16 median on the rendered night case, about 0.9 on a day sky) and fall anywhere.
    Under ``min_response`` they are not used: with 0.1 this fixed camera wandered
    (175 px in 8 s, night CLE 1.19 → 12.8 %)."""
    from seawatch.io.video import VideoReader
    from seawatch.synth import render_case
    from seawatch.vision.horizon import HorizonTracker

    res = render_case("night", tmp_path, duration=2.0, width=960, height=540)
    cm, horizons = CameraMotion(), HorizonTracker()
    with VideoReader(res.video) as reader:
        for fr in reader:
            offset = cm.update(fr.image, horizons.update(fr.image, fr.time))
    assert np.array_equal(offset, [0.0, 0.0])


def test_odd_peaks_neither_start_a_pan_nor_join_one(monkeypatch):
    """The registration's shifts given as a sequence: lone peaks of ±10 px on a fixed
    camera (lossless footage's sensor noise gave such peaks, and one of them, counted as
    motion, moved a fixed camera's tracks 2.6 px) start nothing; amid a steady 3 px pan a
    peak is replaced by the pan's shift; the pan's abrupt start is taken from its fifth
    frame on (the window's median)."""
    cm = CameraMotion()
    shifts = iter([0.0] * 10 + [11.0] + [0.0] * 5 + [-9.8, 10.0] + [0.0] * 5
                  + [3.0] * 10 + [-8.0] + [3.0] * 10)  # fmt: skip
    monkeypatch.setattr(cm, "_register", lambda a, b, hann: (next(shifts), 0.0))
    frame = _view(_scene(), 0.0)
    offsets = [cm.update(frame, HORIZON)[0] for _ in range(1 + 10 + 1 + 5 + 2 + 5 + 21)]
    assert offsets[23] == 0.0  # the fixed camera's peaks
    # the pan: its first 4 frames are missed, then 17 steps of 3 px, the peak one of them
    assert offsets[-1] == pytest.approx(17 * 3.0)


def test_without_a_horizon_or_sky_nothing_is_measured():
    pano = _scene()
    low = HorizonEstimate.from_endpoints(10.0, 10.0, W, H, confidence=1.0)  # no sky
    for horizon in (None, low):
        cm = CameraMotion()
        for k in range(20):
            offset = cm.update(_view(pano, 3.0 * k, seed=k), horizon)
        assert np.array_equal(offset, [0.0, 0.0])


def test_a_size_change_restarts_the_measurement_and_keeps_the_offset():
    pano = _scene()
    cm = CameraMotion()
    for k in range(20):
        cm.update(_view(pano, 3.0 * k, seed=k), HORIZON)
    before = cm.offset.copy()
    assert before[0] < -20.0
    small = cv2.resize(_view(pano, 60.0), (320, 180))
    half = HorizonEstimate.from_endpoints(ROW / 2, ROW / 2, 320, 180, confidence=1.0)
    assert np.array_equal(cm.update(small, half), before) and not cm.moving


def test_bad_arguments_raise_naming_them():
    with pytest.raises(ValueError, match="width"):
        CameraMotion(width=4)
    with pytest.raises(ValueError, match="window"):
        CameraMotion(window=0)
    with pytest.raises(ValueError, match="gate_px"):
        CameraMotion(gate_px=-1.0)
    with pytest.raises(ValueError, match="gate_zoom"):
        CameraMotion(gate_zoom=-0.1)
