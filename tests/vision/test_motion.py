"""Camera motion (``seawatch.vision.motion``): the sideways shift of a panning camera,
measured above the horizon, against shifts applied to a textured frame."""

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
    monkeypatch.setattr(cm, "_register", lambda a, b, hann: next(shifts))
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
