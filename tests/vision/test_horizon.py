"""seawatch.vision.horizon: horizon line, sea mask and temporal tracker.

Truths: synthetic scenes drawn here with a known line (anti-aliased at the exact row
y(x), with clouds, a dark coastline band just above the horizon, a sun-glint blob, boats
on the line, fog, 16-bit thermal-like images); sky/sea steps integrated over each pixel
at known fractional rows, under a Gaussian lens blur, with and without a haze ramp below
the line (sub-pixel location); the camera geometry of seawatch.camera (a horizon drawn
for a known pitch/roll must give that pitch/roll back); rendered footage from
seawatch.synth with its exact horizon.csv; and six real boat-camera images with
IMU-derived horizon masks (WaSR repository, ``examples/``, Apache-2.0;
../shared/data/horizon/).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from seawatch.camera import PinholeCamera, attitude_from_horizon, horizon_line
from seawatch.vision.horizon import HorizonEstimate, HorizonTracker, detect_horizon, sea_mask

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "horizon"
needs_data = pytest.mark.skipif(
    not (DATA / "images" / "example_01.jpg").is_file(),
    reason=f"horizon images not found at {DATA} (shared data folder absent)",
)


def scene(
    h: int = 384,
    w: int = 512,
    y_left: float = 200.0,
    y_right: float = 220.0,
    *,
    seed: int = 0,
    coast: bool = False,
    glint: bool = False,
    clouds: bool = False,
    boats: bool = False,
    fog: bool = False,
    noise: float = 4.0,
) -> tuple[np.ndarray, np.ndarray]:
    """A BGR sky/sea image with the horizon through (0, y_left) and (w − 1, y_right).

    Sky brightening towards the horizon, optional clouds; sea with streaky wave texture
    growing towards the bottom; a pixel is sea in proportion to its area below the line.
    Returns the image and the true row of the line at every column.
    """
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    yl = y_left + (y_right - y_left) * xx / (w - 1)
    below = np.clip(yy + 0.5 - yl, 0.0, 1.0)
    sky = np.array([205.0, 190.0, 170.0])
    sea = sky * 0.9 if fog else np.array([120.0, 110.0, 80.0])
    dist = np.clip((yl - yy) / h, 0.0, 1.0)[..., None]
    sky_img = sky * (1.0 - 0.25 * dist)
    if clouds:
        n = cv2.GaussianBlur(rng.standard_normal((h, w)), (0, 0), 12)
        fade = np.clip((np.minimum(yl - 20, 0.6 * yl) - yy) / (0.15 * h), 0.0, 1.0)
        cloud = np.clip(n / n.std() - 0.6, 0.0, None) * fade
        sky_img = np.minimum(sky_img + 90.0 * cloud[..., None], 255.0)
    tex = cv2.GaussianBlur(rng.standard_normal((h, w)), (0, 0), sigmaX=6, sigmaY=1.2)
    tex /= tex.std()
    depth = np.clip((yy - yl) / max(1.0, h - yl.min()), 0.0, 1.0)
    sea_img = sea * (1.0 - 0.3 * depth[..., None]) + ((4 + 14 * depth) * tex)[..., None]
    if glint:
        cx, cy = 0.6 * w, y_left + 0.6 * (y_right - y_left) + 0.08 * h
        blob = np.exp(-(((xx - cx) / (0.08 * w)) ** 2 + ((yy - cy) / (0.04 * h)) ** 2))
        blob *= yy > yl + 2
        sea_img += (255.0 - sea_img) * np.clip(1.6 * blob, 0.0, 1.0)[..., None]
    img = sky_img * (1.0 - below[..., None]) + sea_img * below[..., None]
    if coast:
        hill = cv2.GaussianBlur(rng.standard_normal((1, w)), (0, 0), 25)[0]
        hill = (hill - hill.min()) / (np.ptp(hill) + 1e-9)
        top = yl - (0.015 * h + 0.06 * h * hill[None, :])
        # land covers the sky between its top and the horizon: per pixel, the area
        # fractions sky (1 − land − below), land, sea (below)
        band = np.clip(yy + 0.5 - top, 0.0, 1.0) - below
        land = (
            np.array([70.0, 85.0, 75.0])
            + 8.0 * cv2.GaussianBlur(rng.standard_normal((h, w)), (0, 0), 1.0)[..., None]
        )
        img = img + band[..., None] * (land - sky_img)
    if boats:
        for bx in (0.2, 0.45, 0.8):
            x0, bw = int(bx * w), int(0.05 * w)
            y = int(y_left + (y_right - y_left) * bx)
            img[y - int(0.04 * h) : y + int(0.01 * h), x0 : x0 + bw] = (40, 40, 45)
            img[y - int(0.09 * h) : y - int(0.04 * h), x0 + bw // 3 : x0 + bw // 2] = 230
    img = np.clip(img + noise * rng.standard_normal(img.shape), 0, 255).astype(np.uint8)
    return img, y_left + (y_right - y_left) * np.arange(w) / (w - 1)


def column_error(est: HorizonEstimate, truth: np.ndarray) -> float:
    """Mean over image columns of |y_detected(x) − y_true(x)| [px]."""
    return float(np.mean(np.abs(est.y_at(np.arange(truth.size)) - truth)))


def mask_truth(path: Path) -> np.ndarray:
    """The boundary row of an IMU mask (1 = below the horizon) at every column [px]:
    the first sea row r of a column has its top edge at r − 0.5 (pixel centres)."""
    mask = cv2.imread(str(path), cv2.IMREAD_UNCHANGED) > 0
    assert mask.any(axis=0).all()
    return np.argmax(mask, axis=0).astype(np.float64) - 0.5


# ----------------------------------------------------------------------------- synthetic truth
CASES = {
    "level": {},
    "tilted": {"y_left": 150.0, "y_right": 260.0},
    "coastline band above": {"coast": True},
    "sun glint below": {"glint": True},
    "clouds above": {"clouds": True},
    "boats on the line": {"boats": True},
    "fog (sea like sky)": {"fog": True},
    "everything, tilted": {
        "coast": True,
        "glint": True,
        "clouds": True,
        "boats": True,
        "y_left": 230.0,
        "y_right": 190.0,
    },
    "near the bottom": {"y_left": 330.0, "y_right": 335.0},
    "near the top": {"y_left": 40.0, "y_right": 50.0},
}


@pytest.mark.parametrize("case", list(CASES))
def test_synthetic_horizon_is_found_within_half_a_percent_of_the_height(case: str):
    for seed in (0, 1):
        img, truth = scene(seed=seed, **CASES[case])
        est = detect_horizon(img)
        assert est.found, (case, seed, est.confidence)
        assert 0.3 <= est.confidence <= 1.0
        assert column_error(est, truth) < 0.005 * img.shape[0], (case, seed)


def test_grayscale_and_sixteen_bit_thermal_images_give_the_same_line():
    img, truth = scene(y_left=180.0, y_right=210.0, seed=3)
    gray = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    # a 16-bit thermal-like frame: warm sea, cold sky, narrow range in a 16-bit word
    thermal = (20000 + 40 * (255 - gray.astype(np.uint32))).astype(np.uint16)
    for image in (gray, thermal, img.astype(np.float32)):
        est = detect_horizon(image)
        assert est.found and column_error(est, truth) < 0.005 * img.shape[0]


def test_resolution_does_not_change_the_line_beyond_a_pixel_of_the_working_image():
    big, truth = scene(1080, 1920, 520.0, 580.0, seed=2)
    est = detect_horizon(big)
    assert est.found and est.width == 1920 and est.height == 1080
    assert est.x0 == 0.0 and est.x1 == 1919.0
    # working width ~256: one working pixel is 7.5 full pixels; sub-pixel fits do better
    assert column_error(est, truth) < 0.005 * 1080


def test_recovers_the_pitch_and_roll_of_the_camera_that_drew_the_horizon():
    # independent truth: the camera model draws the horizon for a known attitude
    cam = PinholeCamera.from_fov(
        512, 384, 60.0, height=15.0, pitch=math.radians(-3.0), roll=math.radians(4.0)
    )
    (_, v0), (_, v1) = horizon_line(cam).endpoints(512)
    img, _ = scene(y_left=float(v0), y_right=float(v1), seed=4, glint=True)
    est = detect_horizon(img)
    att = attitude_from_horizon(cam, est.points)
    assert math.degrees(abs(float(att.pitch) - cam.pitch)) < 0.05
    assert math.degrees(abs(float(att.roll) - cam.roll)) < 0.05
    # the camera prior centres the search on the nominal horizon and finds the same line
    with_prior = detect_horizon(img, camera=cam)
    assert abs(with_prior.y0 - est.y0) < 0.5 and abs(with_prior.y1 - est.y1) < 0.5


def test_previous_line_is_a_prior_not_a_constraint():
    img, truth = scene(seed=5, coast=True)
    wrong = HorizonEstimate.from_endpoints(60.0, 60.0, 512, 384)
    est = detect_horizon(img, previous=wrong)
    assert est.found and column_error(est, truth) < 0.005 * 384


# ----------------------------------------------------------------------------- sub-pixel
def edge_image(
    h: int,
    w: int,
    y_left: float,
    y_right: float,
    *,
    blur: float,
    seed: int = 0,
    noise: float = 2.0,
    haze: float = 0.0,
) -> np.ndarray:
    """A grey sky/sea step along the line through (0, y_left) and (w − 1, y_right).

    Each pixel averages its area (the fraction of the pixel row below the line is sea:
    an anti-aliased edge at a known fractional row), then a Gaussian lens blur of
    ``blur`` px and sensor noise. The sky brightens slightly toward the horizon, the
    sea has a streaky wave texture growing toward the bottom; with ``haze`` the sea
    brightens by that much at the horizon, fading over ~4 rows (the haze ramp of real
    and rendered footage). Float image; the caller quantises.
    """
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    yl = y_left + (y_right - y_left) * xx / (w - 1)
    below = np.clip(yy + 0.5 - yl, 0.0, 1.0)
    depth = np.clip((yy - yl) / h, 0.0, 1.0)
    waves = cv2.GaussianBlur(rng.standard_normal((h, w)), (0, 0), sigmaX=6, sigmaY=1.2)
    sky = 190.0 + 0.05 * np.clip(yy - yl, -200.0, 0.0)
    sea = 110.0 + haze * np.exp(-np.clip(yy - yl, 0.0, None) / 4.0)
    sea = sea + (2.0 + 20.0 * depth) * waves / waves.std()
    img = sky * (1.0 - below) + sea * below
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    return img + noise * rng.standard_normal(img.shape)


@pytest.mark.parametrize("blur", [0.0, 0.8, 1.5])
@pytest.mark.parametrize("frac", [0.0, 0.25, 0.5, 0.75])
def test_anti_aliased_blurred_edge_is_located_to_a_tenth_of_a_pixel(frac: float, blur: float):
    # independent truth: the line the pixels were integrated against; a level and a
    # tilted line, the tilted one passing through every fraction of a row
    for y_left, y_right in ((200.0 + frac, 200.0 + frac), (180.0 + frac, 213.37 + frac)):
        img = edge_image(384, 512, y_left, y_right, blur=blur, seed=round(10 * frac))
        est = detect_horizon(np.clip(img, 0, 255).astype(np.uint8))
        truth = y_left + (y_right - y_left) * np.arange(512) / 511
        assert est.found
        assert column_error(est, truth) < 0.1, (y_left, y_right, blur)


def test_sub_pixel_edge_in_colour_grey_sixteen_bit_and_float_images_alike():
    img = edge_image(384, 512, 190.3, 205.8, blur=1.0, seed=7)
    truth = 190.3 + 15.5 * np.arange(512) / 511
    grey = np.clip(img, 0, 255).astype(np.uint8)
    images = {
        "bgr": cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR),
        "grey": grey,
        # thermal-like: cold sky dark, warm sea bright, 12 bits used of a 16-bit word
        "uint16": np.clip(30000 - 40.0 * img, 0, 65535).astype(np.uint16),
        "float": img.astype(np.float32),
    }
    for name, image in images.items():
        est = detect_horizon(image)
        assert est.found and column_error(est, truth) < 0.1, name


def test_haze_ramp_below_the_horizon_does_not_pull_the_line_down():
    # the sea brightening toward the horizon (a quarter of the step at the line) is a
    # property of the sea region, not of the boundary
    for frac in (0.1, 0.6):
        img = edge_image(384, 512, 200.0 + frac, 200.0 + frac, blur=0.8, haze=20.0)
        est = detect_horizon(np.clip(img, 0, 255).astype(np.uint8))
        assert abs(est.offset - (200.0 + frac)) < 0.2


def test_full_resolution_refinement_at_1080p_is_sub_pixel_despite_a_working_width_of_256():
    # 1920 px wide: one working pixel is 8 image rows; the line is refined on the
    # full-resolution rows around it (the working image alone gave 0.1 px low)
    for frac in (0.0, 0.3, 0.6):
        img = edge_image(1080, 1920, 520.0 + frac, 548.6 + frac, blur=1.2, seed=3)
        truth = 520.0 + frac + 28.6 * np.arange(1920) / 1919
        est = detect_horizon(np.clip(img, 0, 255).astype(np.uint8))
        assert est.found and column_error(est, truth) < 0.05, frac


def test_a_large_hull_below_the_horizon_on_one_side_does_not_tilt_the_line():
    # a dark hull 35 px below the horizon at one side once gave a line through the hull
    # on that side and the horizon on the other (50 px wrong at the end)
    h, w, y = 1080, 1920, 506.95
    base = np.clip(edge_image(h, w, y, y, blur=0.7, seed=1), 0, 255)
    for x0, x1 in ((100, 400), (1500, 1750)):
        img = base.copy()
        img[530:550, x0:x1] = 25.0  # hull
        img[500:530, x0 + 60 : x0 + 110] = 120.0  # superstructure across the horizon
        img[470:530, x0 + 80 : x0 + 90] = 20.0  # mast
        est = detect_horizon(img.astype(np.uint8))
        assert est.found
        assert abs(est.y0 - y) < 0.25 and abs(est.y1 - y) < 0.25, (x0, est.y0, est.y1)


# ----------------------------------------------------------------------------- rendered footage
def _clip_frames(folder: Path) -> Iterator[tuple[Any, tuple[float, float]]]:
    """The frames of a rendered clip's ``video.mp4`` in ``folder``, decoded one by one,
    each with its true horizon (y0, y1) [px] from the renderer's ``horizon.csv`` (as
    many rows as frames, else ValueError)."""
    import csv

    from seawatch.io.video import VideoReader

    with (folder / "horizon.csv").open() as fh:
        truth = [(float(r["y0"]), float(r["y1"])) for r in csv.DictReader(fh)]
    yield from zip(VideoReader(folder / "video.mp4"), truth, strict=True)


def _rendered(
    folder: Path, case: str, duration: float, seed: int
) -> Iterator[tuple[Any, tuple[float, float]]]:
    """:func:`_clip_frames` of ``case`` rendered at 960 × 540 for ``duration`` [s]."""
    from seawatch.synth import render_case

    render_case(case, folder, duration=duration, width=960, height=540, seed=seed)
    return _clip_frames(folder)


def test_rendered_footage_horizon_matches_the_renderer_truth(tmp_path: Path):
    """One second of the range-1km clip (1080p, camera on a swaying boat, a ferry in
    view, H.264) against the renderer's horizon.csv (exact geometry of §4.2).

    The renderer anti-aliases the sky/sea boundary row (area-weighted), so the painted
    edge is the geometric horizon: the centre row and the tilt (the difference of the
    two ends) are checked to 0.1 px (measured: 0.01–0.03 px at 1080p and 720p).
    """
    from seawatch.synth.platform_clip import platform_clip_preset, render_platform_clip

    render_platform_clip(tmp_path, **platform_clip_preset("range-1km", duration=1.0))
    n = 0
    for frame, (t0, t1) in _clip_frames(tmp_path):
        n += 1
        est = detect_horizon(frame.image)
        assert est.found
        assert abs(est.offset - 0.5 * (t0 + t1)) < 0.1, (frame.index, est.y0, est.y1, t0, t1)
        assert abs((est.y1 - est.y0) - (t1 - t0)) < 0.1, (frame.index, est.y0, est.y1, t0, t1)
    assert n >= 10


def test_rendered_night_horizon_is_found_in_every_frame(tmp_path: Path):
    """Three seconds of the rendered night case (thermal-like, 960 × 540, seed 0): a
    clear horizon (one straight edge over 99 % of the width) in every frame, found and
    within 0.5 px of the renderer's line at both ends. The region test's texture once
    counted the horizon's own edge, blurred into the band just below it, as the sea's:
    the line failed the test and was lost in 16 of the 75 frames (52–71)."""
    n = 0
    for frame, (t0, t1) in _rendered(tmp_path, "night", 3.0, seed=0):
        n += 1
        est = detect_horizon(frame.image)
        assert est.found, (frame.index, est.confidence)
        assert abs(est.y0 - t0) < 0.5 and abs(est.y1 - t1) < 0.5, (frame.index, est.y0, est.y1)
    assert n == 75


def _coast_clip_errors(tmp_path: Path, seed: int) -> list[tuple[int, float, float]]:
    """One second of the rendered crossing case (960 × 540) with rendering ``seed``:
    (frame, |Δy| at the left end, at the right end) [px] of detect_horizon's line against
    the renderer's horizon.csv."""
    out = []
    for frame, (t0, t1) in _rendered(tmp_path, "crossing", 1.0, seed=seed):
        est = detect_horizon(frame.image)
        assert est.found
        out.append((frame.index, abs(est.y0 - t0), abs(est.y1 - t1)))
    assert len(out) == 25
    return out


@pytest.fixture(scope="module")
def coast_errors(tmp_path_factory):
    """:func:`_coast_clip_errors` by seed, each clip rendered once for the module."""
    cache: dict[int, list[tuple[int, float, float]]] = {}

    def errors(seed: int) -> list[tuple[int, float, float]]:
        if seed not in cache:
            cache[seed] = _coast_clip_errors(tmp_path_factory.mktemp(f"coast{seed}"), seed)
        return cache[seed]

    return errors


def test_rendered_coast_on_part_of_the_horizon_does_not_tilt_the_line(coast_errors):
    """Rendered crossing, seed 1: a coastline sits on the horizon over the right
    two-thirds of the width, open sky over the sea on the left. The sea horizon is the
    sky/sea edge on the left and the land's water line on the right, one straight line.
    The coarse line joins the sky/sea edge to the top of the land (the right end 27–32 px
    high, its refined fit holding under half the bins); step 6b's straightest edge among
    the bins (the sky/sea part) is the better sea horizon by the region test and replaces
    it: both ends within 0.5 px in every frame (measured 0.04–0.4 px)."""
    for k, e0, e1 in coast_errors(1):
        assert e0 < 0.5 and e1 < 0.5, (k, e0, e1)


def test_rendered_coast_over_most_of_the_horizon_is_tracked_for_eight_seconds(tmp_path: Path):
    """The whole rendered crossing clip, seed 0 (8 s, 200 frames): frame by frame, step
    6b's two lines — the coast's top and the straight sea horizon below it — score
    within a few hundredths by the region test, and alone each frame takes one or the
    other (the left end 7.2 px off on average). Through :class:`HorizonTracker` the
    previous line weighs the close call, so the tracked line stays on the horizon in
    every frame: both ends within 1 px (measured 0.69 px at most, 0.12 px on average;
    the worst frames follow weak detections 1.1–1.4 px off at one end, weighed by their
    confidence 0.25–0.27). The straight line's confidence is 0.25–0.47 (the found
    threshold is 0.3). Session 21's tracker, on session 22's host: five weak
    detections in a row dropped the track at frame 12 (started again at once), and at
    frame 169, with the prior 5 % of the height wide, the coast's top (0.404 by the
    region test against the sea edge's 0.343) took the line, its left end 29 px up
    for the rest of the clip."""
    tracker = HorizonTracker()
    n = 0
    for frame, (t0, t1) in _rendered(tmp_path, "crossing", 8.0, seed=0):
        n += 1
        est = tracker.update(frame.image, time=frame.time)
        assert est.found, frame.index
        assert abs(est.y0 - t0) < 1.0 and abs(est.y1 - t1) < 1.0, (frame.index, est.y0, t0)
    assert n == 200


def test_rendered_glare_start_on_a_wrong_line_is_left_within_frames(tmp_path: Path):
    """Rendered lighting case, seed 1 (low sun, its glare band on the horizon): the
    first frame's line runs 19.6 px low at the right end, and the detections are right
    from the third frame. A young track keeps the wide prior, so the tracked line is
    within 0.5 px at both ends after a second (measured: from frame 21, its filter's
    rate settling; with the tracker's own spread as the prior from the first frame, the
    wrong line held for 30 frames)."""
    errors = []
    tracker = HorizonTracker()
    for frame, (t0, t1) in _rendered(tmp_path, "lighting", 1.4, seed=1):
        est = tracker.update(frame.image, time=frame.time)
        assert est.found, frame.index
        errors.append(max(abs(est.y0 - t0), abs(est.y1 - t1)))
    assert len(errors) == 35 and errors[0] > 10.0  # the wrong start
    assert max(errors[25:]) < 0.5, errors


def test_rendered_coast_from_the_left_border_keeps_the_open_sea_end(coast_errors):
    """Rendered crossing, seed 0 (the coast from the left border over two-thirds of the
    width): the line's right end, on the open sky/sea edge, stays within 2.5 px of the
    horizon in every frame (measured 1.9–2.2 px). Step 6b may not swap the line for a
    straight stretch of the coast's top that runs above it there (which took the right
    end 8–12 px up before its "nowhere above" condition)."""
    for k, _, e1 in coast_errors(0):
        assert e1 < 2.5, (k, e1)


def test_rendered_coast_over_most_of_the_horizon_does_not_tilt_the_line(coast_errors):
    """Rendered crossing, seed 0: a coast covers the horizon from the left border over
    two-thirds of the width. The coarse line follows the coast's top and meets the
    sky/sea edge only at the right end, so the sea horizon on the left lies beyond the
    refinement's bins; step 6b then looks for the straightest edge down to 8 % of the
    height below the line (the sky/sea edge on both sides of the coast): both ends
    within 0.5 px in every frame (measured 0.05 and 0.38 px at most; before, the left
    end was 28–29 px high in 23 of these 25 frames)."""
    for k, e0, e1 in coast_errors(0):
        assert e0 < 0.5 and e1 < 0.5, (k, e0, e1)


# ----------------------------------------------------------------------------- no horizon
def _no_horizon_images() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(1234)
    return {
        "all black": np.zeros((384, 512, 3), np.uint8),
        "all white": np.full((384, 512), 255, np.uint8),
        "16-bit constant": np.full((240, 320), 31000, np.uint16),
        "camera pointing down at the sea": scene(y_left=-60.0, y_right=-40.0, seed=6)[0],
        "camera pointing up at the sky": scene(y_left=450.0, y_right=470.0, clouds=True)[0],
        "smooth brightness ramp": np.clip(
            np.linspace(40, 220, 384)[:, None] + rng.normal(0, 4, (384, 512)), 0, 255
        ).astype(np.uint8),
        "noise": rng.integers(0, 256, (384, 512), dtype=np.uint8),
    }


@pytest.mark.parametrize("name", list(_no_horizon_images()))
def test_no_horizon_in_view_is_not_found_with_low_confidence(name: str):
    img = _no_horizon_images()[name]
    est = detect_horizon(img)
    assert not est.found and est.confidence < 0.3
    assert math.isfinite(est.y0) and math.isfinite(est.y1)
    assert not sea_mask(img.shape, est).any()


# ----------------------------------------------------------------------------- real images
@needs_data
def test_real_boat_camera_images_against_imu_horizon_masks():
    """Per-image mean column error [px] of the six WaSR examples (512 × 384).

    Measured (issue 6): 01 9.8, 02 1.9, 03 2.4, 04 5.4, 06 2.5 px; mean over the five
    with a sea horizon 4.39 px = 1.14 % of the height (the issue's target, < 1 %, is
    not met). The bounds below are those numbers with a margin, as a regression guard.

    Open sea / distant coast (02 fog, 03 coastline, 06 open sea): the line is on the
    visible sky/sea or shore/sea edge; what remains is mostly the masks' own error:
    in 03 the visible water reaches rows 216–221 at the right border (columns
    470–511, the luma step of the distant shore's water line at row 214.5) where the
    IMU horizon is at 221.5, i.e. sea above the horizon, which cannot be; in the
    middle (columns 180–299) the water line is at 221.5, the IMU horizon at 223.5.
    Harbours (01, 04): the sea horizon itself is hidden behind the near piers and
    hulls; the IMU horizon runs through that band (~20 px between the water line
    and the distant skyline), near the top of the low structures. The detector finds
    the water edge at the base of the band in 01 (10 px low) and the band's upper
    edge at the right in 04 (up to 12 px high). 05 is a Venice canal without any sea
    horizon in view: not found.
    """
    errors = {}
    for image in sorted((DATA / "images").glob("*.jpg")):
        img = cv2.imread(str(image))
        truth = mask_truth(DATA / "imus" / (image.stem + ".png"))
        est = detect_horizon(img)
        errors[image.stem] = (column_error(est, truth), est.found)
    h = 384
    bounds = {  # [px] measured + margin
        "example_01": 11.0,
        "example_02": 2.5,
        "example_03": 3.0,
        "example_04": 6.0,
        "example_06": 3.0,
    }
    for name, bound in bounds.items():
        err, found = errors[name]
        assert found and err < bound, (name, err)
    for name in ("example_02", "example_03", "example_06"):
        assert errors[name][0] < 0.01 * h, (name, errors[name][0])
    mean = float(np.mean([errors[name][0] for name in bounds]))
    assert mean < 0.012 * h, mean  # measured 1.14 %
    assert not errors["example_05"][1]


THERMAL = DATA.parent / "mardct_ir3"


@pytest.mark.skipif(
    not (THERMAL / "boxes.csv").is_file(),
    reason=f"MarDCT thermal frames not found at {THERMAL} (shared data folder absent)",
)
@pytest.mark.parametrize("grey", [False, True], ids=["as-stored", "one-channel"])
def test_real_thermal_clip_sea_boundary_is_found_and_holds_the_boat_water_line(grey):
    """MarDCT ir-3 (88 real thermal frames, a boat near a coastline; TIRSD boxes,
    Apache-2.0): the sea/land boundary is found in nearly every frame, and the boat's
    water-line point (box bottom centre) lies in the sea mask, within 40 px of the line
    — also with the frames as one grey channel, as a thermal camera gives them (found in
    1 of 88 before the region test weighed a grey channel as a colour frame's three)."""
    import csv

    from seawatch.io.video import VideoReader

    with (THERMAL / "boxes.csv").open() as fh:
        boxes = {row["file"]: row for row in csv.DictReader(fh)}
    found = 0
    frames = list(VideoReader(THERMAL / "images"))
    for frame in frames:
        image = cv2.cvtColor(frame.image, cv2.COLOR_BGR2GRAY) if grey else frame.image
        est = detect_horizon(image)
        if not est.found:
            continue
        found += 1
        box = boxes[frame.file.name]
        u = float(box["x"]) + 0.5 * float(box["w"])
        v = float(box["y"]) + float(box["h"])
        line_v = float(est.y_at(u))
        assert line_v < v < line_v + 40.0, (frame.file.name, line_v, v)
        assert sea_mask(image.shape, est)[int(v), int(u)]
    assert found >= 0.95 * len(frames)


# ----------------------------------------------------------------------------- estimate, mask
def test_estimate_line_forms_agree():
    est = HorizonEstimate.from_endpoints(100.0, 140.0, 401, 300, confidence=0.8)
    assert est.slope == pytest.approx(0.1) and est.offset == pytest.approx(120.0)
    np.testing.assert_allclose(est.y_at([0, 200, 400]), [100.0, 120.0, 140.0])
    # Hough form: x cos θ + y sin θ = ρ holds at both end points
    for x, y in est.points:
        assert x * math.cos(est.theta) + y * math.sin(est.theta) == pytest.approx(est.rho)
    assert 0.0 <= est.theta < math.pi
    np.testing.assert_allclose(est.line.v_at([0.0, 400.0]), [100.0, 140.0])
    rec = est.to_dict()
    assert set(rec) == {"found", "x0", "y0", "x1", "y1", "confidence"}
    with pytest.raises(ValueError, match="confidence"):
        HorizonEstimate.from_endpoints(1.0, 2.0, 10, 10, confidence=1.5)
    with pytest.raises(ValueError, match="y0"):
        HorizonEstimate.from_endpoints(float("nan"), 2.0, 10, 10)


def test_sea_mask_is_the_region_strictly_below_the_line():
    est = HorizonEstimate.from_endpoints(10.3, 20.7, 64, 48)
    mask = sea_mask((48, 64, 3), est)
    v, u = np.mgrid[0:48, 0:64]
    np.testing.assert_array_equal(mask, v > 10.3 + (20.7 - 10.3) * u / 63)
    with_margin = sea_mask((48, 64), est, margin=5.0)
    np.testing.assert_array_equal(with_margin, v > 10.3 + (20.7 - 10.3) * u / 63 - 5.0)
    # the same line on an image of twice the size
    double = sea_mask((96, 128), est)
    assert double.shape == (96, 128) and abs(double.mean() - mask.mean()) < 0.02
    lost = HorizonEstimate.from_endpoints(10.0, 10.0, 64, 48, found=False, confidence=0.0)
    assert not sea_mask((48, 64), lost).any()
    with pytest.raises(ValueError, match="shape"):
        sea_mask((5,), est)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"image": np.zeros((10, 10, 2), np.uint8)}, "image"),
        ({"image": np.zeros((8, 8), np.uint8)}, "image"),
        ({"image": np.full((64, 64), np.nan, np.float32)}, "image"),
        ({"image": np.zeros((64, 64), complex)}, "image"),
        ({"max_tilt_deg": 0.0}, "max_tilt_deg"),
        ({"work_width": 8}, "work_width"),
        ({"previous": (1, 2)}, "previous"),
        ({"min_confidence": 2.0}, "min_confidence"),
    ],
)
def test_bad_inputs_are_value_errors_naming_the_argument(kwargs: dict, name: str):
    args = {"image": np.zeros((64, 64), np.uint8), **kwargs}
    image = args.pop("image")
    with pytest.raises(ValueError, match=name):
        detect_horizon(image, **args)


# ----------------------------------------------------------------------------- tracker
def _detection(y0: float, y1: float, found: bool = True, conf: float = 0.9) -> HorizonEstimate:
    return HorizonEstimate.from_endpoints(y0, y1, 640, 480, found=found, confidence=conf)


def test_tracker_smooths_noisy_detections_of_a_swaying_horizon():
    rng = np.random.default_rng(1234)
    fps, n = 25.0, 200
    t = np.arange(n) / fps
    y0 = 240 + 20 * np.sin(2 * np.pi * 0.2 * t)
    y1 = 250 + 15 * np.sin(2 * np.pi * 0.15 * t + 1.0)
    tracker = HorizonTracker(sigma_measurement=3.0, sigma_a=100.0)
    raw, smooth = [], []
    for k in range(n):
        z0, z1 = y0[k] + rng.normal(0, 3), y1[k] + rng.normal(0, 3)
        est = tracker.step(_detection(z0, z1), t[k])
        assert est.found
        if k >= 25:  # after the start-up transient
            raw.append([z0 - y0[k], z1 - y1[k]])
            smooth.append([est.y0 - y0[k], est.y1 - y1[k]])
    rms_raw = np.sqrt(np.mean(np.square(raw)))
    rms_smooth = np.sqrt(np.mean(np.square(smooth)))
    assert rms_smooth < 0.6 * rms_raw


def test_tracker_gates_an_outlier_and_coasts_through_missed_frames():
    tracker = HorizonTracker(max_misses=3)
    for k in range(10):
        tracker.step(_detection(200.0, 210.0), k / 25)
    # a coastline 60 px higher: gated out, the line stays
    est = tracker.step(_detection(140.0, 150.0), 10 / 25)
    assert est.found and abs(est.y0 - 200.0) < 1.0 and tracker.misses == 1
    assert tracker.last_nis > tracker.gate
    # not found twice more: still coasting, confidence decaying
    est2 = tracker.step(_detection(0.0, 0.0, found=False, conf=0.0), 11 / 25)
    assert est2.found and est2.confidence < est.confidence
    # the third miss drops the track
    lost = tracker.step(_detection(0.0, 0.0, found=False, conf=0.0), 12 / 25)
    assert not lost.found and not tracker.tracking
    # the next detection starts a new track at once
    new = tracker.step(_detection(300.0, 290.0), 13 / 25)
    assert new.found and new.y0 == pytest.approx(300.0)


def test_tracker_keeps_the_track_on_weak_detections_in_its_gate():
    """A detection under the found threshold (0.3) by at most half, inside the gate,
    updates the track, weighed by its confidence, instead of counting as a miss: a
    horizon seen only between coasts keeps its track. Weaker ones, and weak ones
    outside the gate, are misses."""
    tracker = HorizonTracker(max_misses=3)
    for k in range(10):
        tracker.step(_detection(200.0, 210.0), k / 25)
    for k in range(10, 20):  # ten weak detections 1 px lower: held and followed
        est = tracker.step(_detection(201.0, 211.0, found=False, conf=0.2), k / 25)
        assert est.found and tracker.misses == 0 and est.confidence == pytest.approx(0.2)
    assert abs(est.y0 - 201.0) < 0.3 and tracker.age == 20  # (a step: the rate overshoots)
    miss = tracker.step(_detection(201.0, 211.0, found=False, conf=0.1), 20 / 25)
    assert miss.found and tracker.misses == 1  # under half the threshold: a miss
    far = tracker.step(_detection(150.0, 160.0, found=False, conf=0.29), 21 / 25)
    assert far.found and tracker.misses == 2 and far.y0 > 199.0  # outside the gate
    lost = tracker.step(_detection(150.0, 160.0, found=False, conf=0.29), 22 / 25)
    assert not lost.found and not tracker.tracking  # a weak one never starts a track


def test_tracker_follows_a_real_jump_after_max_misses_frames():
    tracker = HorizonTracker(max_misses=4)
    for k in range(10):
        tracker.step(_detection(200.0, 200.0), k / 25)
    outs = [tracker.step(_detection(120.0, 120.0), (10 + k) / 25) for k in range(4)]
    assert all(o.found for o in outs)
    assert abs(outs[-2].y0 - 200.0) < 5.0  # still held while gating
    assert outs[-1].y0 == pytest.approx(120.0)  # replaced by the persistent new line


def test_tracker_on_video_frames_handles_a_blackout():
    tracker = HorizonTracker()
    errors = []
    for k in range(8):
        t = k / 25
        img, truth = scene(y_left=200 + 2 * k, y_right=215 - k, seed=k, glint=True)
        if k in (3, 4):
            img[:] = 0
        est = tracker.update(img, t)
        assert est.found  # coasting through the two black frames
        errors.append(column_error(est, truth))
    assert max(errors) < 0.01 * 384


def test_tracker_rejects_bad_options_and_times():
    with pytest.raises(ValueError, match="gate"):
        HorizonTracker(gate=0.0)
    with pytest.raises(ValueError, match="max_misses"):
        HorizonTracker(max_misses=0)
    with pytest.raises(ValueError, match="sigma_a"):
        HorizonTracker(sigma_a=-1.0)
    with pytest.raises(ValueError, match="detector"):
        HorizonTracker(colour="red")
    with pytest.raises(ValueError, match="prior_sigma"):
        detect_horizon(np.zeros((48, 64), np.uint8), prior_sigma=0.0)
    tracker = HorizonTracker()
    tracker.step(_detection(200.0, 200.0), 1.0)
    tracker.step(_detection(200.0, 200.0), 1.1)
    with pytest.raises(ValueError, match="time"):
        tracker.step(_detection(200.0, 200.0), 1.0)
    with pytest.raises(ValueError, match="detection"):
        tracker.step((200.0, 200.0), 1.2)  # type: ignore[arg-type]
