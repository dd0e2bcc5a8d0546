"""Ship detectors: the classical one (vision.detect), callable and ONNX ones (vision.external).

Truths: synthetic sea scenes drawn here with known ship boxes and water lines (textured
sea with perspective waves and noise, small and large, dark and bright ships with hull
and superstructure, a sun-glitter patch and a coastline band that must give no boxes,
camera roll); hulls painted with their exact area coverage at fractional water lines
(and sloping, one in front of another, with a sub-pixel mast), blurred like a lens;
rendered H.264 footage (``seawatch.synth.render``) against its ``truth.csv``; 88 real
thermal frames with a hand-made boat box per frame (MarDCT video ir-3 annotated by the
TIRSD repository, Apache-2.0; ``../shared/data/mardct_ir3/``, read in place); a real
boat-camera images with a moored sailboat and a buoy whose columns are read off their
pixels (WaSR's examples 03 and 02, ``../shared/data/horizon/``); hand-built YOLO output
tensors whose boxes are known. Both object refinements of the classical
detector (``refine="mask"``, the default, and ``"flank"``) are checked.
"""

from __future__ import annotations

import csv
import sys
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seawatch.vision.detect import (
    DETECTION_COLUMNS,
    ClassicalShipDetector,
    Detections,
    Detector,
    sea_region,
    waterline_points,
)
from seawatch.vision.detect import _one_sided_hits as one_sided_hits
from seawatch.vision.detect import _trim_other_polarity as trim_other_polarity
from seawatch.vision.detect import _union_rects as union_rects
from seawatch.vision.external import (
    CallableDetector,
    MaskedDetector,
    OnnxDetector,
    decode_yolo,
    make_detector,
)

WASR = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "horizon" / "images"
MARDCT = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "mardct_ir3"
needs_mardct = pytest.mark.skipif(
    not (MARDCT / "boxes.csv").is_file(),
    reason=f"MarDCT ir-3 frames not found at {MARDCT} (shared data folder absent)",
)
REFINE = ("mask", "flank")  # ClassicalShipDetector's object refinements


# ------------------------------------------------------------------ synthetic scenes


def sea_scene(
    rng: np.random.Generator,
    h: int = 360,
    w: int = 640,
    horizon: float = 120.0,
    *,
    roll_deg: float = 0.0,
    ships: tuple[dict, ...] | list[dict] = (),
    glint: tuple[float, float, float, float] | None = None,
    coast: bool = False,
    noise: float = 2.0,
    wave_amp: float = 4.0,
) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float, float]]:
    """A grey sky/sea frame (float, grey levels) with known ships.

    Sky brightening away from the horizon with faint clouds; sea darkening towards the
    bottom with five horizontally elongated wave trains that get finer towards the
    horizon (perspective); optional coastline band of textured land standing on the
    horizon (left half) with bright 4×3 px buildings at least 6 px above the line;
    optional sun glitter: 1–2 px sparkles, dense in the middle of an elliptical patch
    ``(cx, cy, a, b)``; Gaussian noise. Each ship dict: ``cx, base`` (hull bottom row
    edge), ``length, height`` (hull), optional ``sup_w, sup_h`` (superstructure) and
    ``contrast`` (signed, grey levels against the local sea).

    Returns the image, the truth rows ``(x, y, w, h, u_wl, v_wl)`` [px, pixel-centre
    origin] and the horizon ``(x0, y0, x1, y1)``.
    """
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    slope = np.tan(np.radians(roll_deg))
    yh = horizon + (xx - (w - 1) / 2) * slope
    below = yy - yh
    t = np.clip(below / (h - horizon), 0, 1)
    img = np.where(below < 0, 150 + 25 * np.clip(-below / horizon, 0, 1), 90 - 25 * t)
    img += np.where(below < 0, cv2.GaussianBlur(rng.normal(0, 1, (h, w)), (0, 0), 12) * 60, 0)
    p = 0.08 + t
    waves = np.zeros((h, w))
    for _ in range(5):
        th = rng.uniform(-0.5, 0.5)
        lx, ly = rng.uniform(40, 140) * p, rng.uniform(4, 10) * p
        waves += np.sin(2 * np.pi * (xx * np.sin(th) / lx + below / ly) + rng.uniform(0, 6.3))
    img += np.where(below >= 0, wave_amp * np.sqrt(p) * waves / np.sqrt(5), 0)
    if coast:
        prof = cv2.GaussianBlur(rng.normal(0, 1, (1, w)), (0, 0), 40)[0]
        prof = np.clip(8 + 22 * np.abs(prof) / 0.05, 6, 40)
        band = (below < 0) & (below > -prof[None, :])
        band[:, : int(0.05 * w)] = False
        band[:, int(0.55 * w) :] = False
        land = 120 + cv2.GaussianBlur(rng.normal(0, 1, (h, w)), (0, 0), 2) * 40
        img = np.where(band, land, img)
        for _ in range(12):
            bx = int(rng.uniform(0.05 * w + 5, 0.55 * w - 5))
            by = int(yh[0, bx] - rng.uniform(6, max(7, prof[bx] - 2)))
            img[by - 1 : by + 2, bx - 2 : bx + 2] = 230
    truth = []
    for s in ships:
        cx, base, length, hh = s["cx"], s["base"], s["length"], s["height"]
        c0, c1 = round(cx - length / 2), round(cx + length / 2) - 1
        r1 = round(base) - 1
        r0 = r1 - hh + 1
        val = img[r0 : r1 + 1, max(c0 - 30, 0) : c1 + 30].mean() + s["contrast"]
        for r in range(r0, r1 + 1):  # hull, a little narrower at the bottom
            inset = round((r - r0) / max(1, hh) * 0.15 * length)
            img[r, c0 + inset : c1 - inset + 1] = val
        top, lo, hi = r0, c0, c1
        if s.get("sup_h", 0):
            sw, sh = s["sup_w"], s["sup_h"]
            sc0 = round(cx - sw / 2)
            top = r0 - sh
            img[top:r0, sc0 : sc0 + sw] = val + s.get("sup_extra", 0.0)
            lo, hi = min(c0, sc0), max(c1, sc0 + sw - 1)
        truth.append((lo - 0.5, top - 0.5, hi - lo + 1, r1 - top + 1, (c0 + c1) / 2, r1 + 0.5))
    if glint is not None:
        gx, gy, a, b = glint
        env = np.exp(-0.5 * (((xx - gx) / a) ** 2 + ((yy - gy) / b) ** 2))
        sparkle = (rng.random((h, w)) < 0.25 * env) & (below > 2)
        sparkle |= np.roll(sparkle, 1, axis=1) & (rng.random((h, w)) < 0.5)
        img += sparkle * rng.uniform(50, 130, (h, w)) * np.sqrt(env)
    img += rng.normal(0, noise, (h, w))
    return img, np.array(truth).reshape(-1, 6), (0.0, yh[0, 0], w - 1.0, yh[0, -1])


def as_u8(img: np.ndarray) -> np.ndarray:
    return np.clip(np.round(img), 0, 255).astype(np.uint8)


def random_ships(rng: np.random.Generator, h: int, w: int, horizon: float, n: int) -> list:
    """n non-overlapping ships: half small (6–14 × 3–5 px hulls), half large (30–110 px
    long with a superstructure), contrast ±15–40 grey levels."""
    ships: list[dict] = []
    used: list[tuple[float, float, float, float]] = []
    for _ in range(n):
        for _ in range(100):
            small = rng.random() < 0.5
            if small:
                length, hh, sup = int(rng.uniform(6, 14)), int(rng.uniform(3, 5)), (0, 0)
            else:
                length = int(rng.uniform(30, 110))
                hh = int(max(4, length * rng.uniform(0.12, 0.2)))
                sup = (int(length * rng.uniform(0.2, 0.4)), int(hh * rng.uniform(0.6, 1.2)))
            base = rng.uniform(horizon + 6 + (0 if small else 20), h - 10)
            cx = rng.uniform(length / 2 + 20, w - length / 2 - 20)
            box = (cx - length / 2 - 15, base - hh - sup[1] - 10, cx + length / 2 + 15, base + 10)
            if all(box[2] < u[0] or u[2] < box[0] or box[3] < u[1] or u[3] < box[1] for u in used):
                used.append(box)
                break
        else:
            continue
        ships.append(
            {
                "cx": cx,
                "base": base,
                "length": length,
                "height": hh,
                "sup_w": sup[0],
                "sup_h": sup[1],
                "contrast": rng.choice([-1, 1]) * rng.uniform(15, 40),
                "sup_extra": rng.uniform(-10, 10),
            }
        )
    return ships


def match(det: Detections, truth: np.ndarray, tol: float = 12.0) -> tuple[np.ndarray, int]:
    """Greedy one-to-one matching: a truth is found when an unused detection centre is
    within max(tol, (w + h)/4) px city-block of the truth box centre. Returns the index
    of the matching detection per truth (-1 = missed) and the number of false boxes."""
    centres = det.centers
    tc = truth[:, :2] + truth[:, 2:4] / 2
    used = np.zeros(len(det), bool)
    found = np.full(len(truth), -1)
    for i in range(len(truth)):
        if not len(det):
            break
        d = np.abs(centres - tc[i]).sum(axis=1)
        ok = np.flatnonzero((d <= max(tol, 0.25 * (truth[i, 2] + truth[i, 3]))) & ~used)
        if ok.size:
            j = ok[np.argmin(d[ok])]
            used[j] = True
            found[i] = j
    return found, int((~used).sum())


def fixed_ships() -> list[dict]:
    """Five well-separated ships: small dark, small bright, tiny (3 px high), large dark
    with superstructure, large bright with superstructure."""
    return [
        {"cx": 100, "base": 170, "length": 12, "height": 4, "contrast": -30},
        {"cx": 250, "base": 200, "length": 10, "height": 4, "contrast": 30},
        {"cx": 560, "base": 160, "length": 8, "height": 3, "contrast": -35},
        {"cx": 420, "base": 300, "length": 90, "height": 14, "sup_w": 30, "sup_h": 12,
         "contrast": -35},
        {"cx": 150, "base": 320, "length": 60, "height": 10, "sup_w": 20, "sup_h": 9,
         "contrast": 30},
    ]  # fmt: skip


# ------------------------------------------------------------------ result type


def test_detections_from_boxes_defaults_score_one_and_bottom_centre_waterline():
    det = Detections.from_boxes([[10, 20, 30, 8], [0, 0, 4, 4]], score=[0.2, 0.9])
    assert det.boxes.shape == (2, 7)
    assert list(det.score) == [0.9, 0.2]  # sorted by score
    np.testing.assert_allclose(det.u_wl, det.x + det.w / 2)
    np.testing.assert_allclose(det.v_wl, det.y + det.h)
    rec = det.records()[1]
    assert tuple(rec) == DETECTION_COLUMNS
    assert rec["x"] == 10 and rec["v_wl"] == 28
    with pytest.raises(ValueError, match="boxes"):
        Detections(np.zeros((2, 6)))
    with pytest.raises(ValueError, match="score"):
        Detections(np.array([[0, 0, 1, 1, 1.5, 0, 0]]))
    assert len(Detections.empty()) == 0


def test_every_detector_satisfies_the_detector_protocol():
    assert isinstance(ClassicalShipDetector(), Detector)
    assert isinstance(CallableDetector(lambda im: []), Detector)


def test_sea_region_is_the_area_below_the_line():
    m = sea_region((10, 20), (0, 4.0, 19, 4.0))
    assert m[4:].all() and not m[:4].any()
    assert sea_region((5, 5), None).all()


# ------------------------------------------------------------------ classical detector


@pytest.mark.parametrize("refine", REFINE)
def test_finds_small_large_dark_and_bright_ships_with_their_water_lines(refine):
    rng = np.random.default_rng(1234)
    img, truth, hz = sea_scene(rng, ships=fixed_ships(), coast=True)
    det = ClassicalShipDetector(refine=refine)(as_u8(img), horizon=hz)
    found, n_false = match(det, truth)
    assert (found >= 0).all(), f"missed {truth[found < 0]}"
    assert n_false == 0
    assert ((det.score > 0) & (det.score <= 1)).all()
    for i in range(5):
        # the whole ship is boxed (hull and superstructure), each edge within a pixel; the
        # water line is the hull's bottom edge (at a pixel border here) near the hull's
        # centre column. The 60 px bright hull (+30 grey levels over 4-level waves) is
        # wider than the finest scale's CFAR guard window, and at the coarser scale its
        # own contrast raises the noise: until session 32 refine="mask" boxed only its
        # superstructure (20 × 9 px); the wide-target pass (step 4b) finds it whole
        j = found[i]
        edges = np.r_[det.boxes[j, :2], det.boxes[j, :2] + det.boxes[j, 2:4]]
        np.testing.assert_allclose(
            edges, np.r_[truth[i, :2], truth[i, :2] + truth[i, 2:4]], atol=1.0
        )
        assert abs(det.v_wl[j] - truth[i, 5]) <= 0.3
        assert abs(det.u_wl[j] - truth[i, 4]) <= max(2.0, truth[i, 2] / 8)


@pytest.mark.parametrize("refine", REFINE)
def test_random_scenes_recall_and_false_boxes_per_frame(refine):
    """Seeded random scenes (5 ships, glitter patch, coastline, roll up to ±3°): recall
    ≥ 0.75 and at most 0.5 false boxes per frame (committed detector: 0.80 and 0.08 on
    these 12 scenes; measured 0.78 and 0.17 with refine="mask", 0.78 and 0.17 with
    "flank"; the misses are ships inside the glitter and large ones hugging the
    horizon)."""
    rng = np.random.default_rng(1234)
    det = ClassicalShipDetector(refine=refine)
    hits = total = false = 0
    n = 12
    for _ in range(n):
        hz = 360 * rng.uniform(0.25, 0.4)
        ships = random_ships(rng, 360, 640, hz, 5)
        glint = (rng.uniform(0.3, 0.7) * 640, hz + rng.uniform(0.2, 0.4) * (360 - hz), 60, 15)
        img, truth, line = sea_scene(
            rng, horizon=hz, roll_deg=rng.uniform(-3, 3), ships=ships, glint=glint, coast=True
        )
        found, n_false = match(det(as_u8(img), horizon=line), truth)
        hits += int((found >= 0).sum())
        total += len(truth)
        false += n_false
    assert hits / total >= 0.75
    assert false / n <= 0.5


def test_frames_prepared_ahead_give_the_detections_of_whole_calls():
    """prepare() may run frames ahead of detect_prepared() (VisualTracker.stream): three
    rolled colour scenes prepared first, then detected, equal three whole calls."""
    rng = np.random.default_rng(99)
    frames = []
    for roll in (-2.0, 0.0, 2.5):
        img, _, line = sea_scene(rng, roll_deg=roll, ships=fixed_ships(), coast=True)
        grey = as_u8(img)
        frames.append((np.dstack([grey, np.roll(grey, 1, axis=1), grey]), line))
    det = ClassicalShipDetector()
    want = [det(img, horizon=line).boxes for img, line in frames]
    assert all(w.shape[0] >= 4 for w in want)
    ready = [det.prepare(img, horizon=line) for img, line in frames]
    for r, w in zip(ready, want, strict=True):
        np.testing.assert_array_equal(det.detect_prepared(r).boxes, w)
    # no sea in view: an empty prepared frame gives no detections
    img, line = frames[0]
    none = det.prepare(img, sea_mask=np.zeros(img.shape[:2], bool))
    assert none.frame is None and len(det.detect_prepared(none)) == 0


@pytest.mark.parametrize("refine", REFINE)
def test_glitter_patch_and_coastline_give_no_boxes(refine):
    rng = np.random.default_rng(7)
    img, _, hz = sea_scene(rng, glint=(320, 220, 70, 18), coast=True)
    det = ClassicalShipDetector(refine=refine)(as_u8(img), horizon=hz)
    assert len(det) == 0, det.boxes


def test_land_above_the_horizon_is_ignored_but_found_without_a_horizon():
    rng = np.random.default_rng(3)
    img, _, hz = sea_scene(rng, coast=True, noise=1.0)
    u8 = as_u8(img)
    assert len(ClassicalShipDetector()(u8, horizon=hz)) == 0
    # the bright buildings on the land band are targets when the sea region is unknown
    everywhere = ClassicalShipDetector()(u8)
    assert len(everywhere) >= 1
    assert (everywhere.v_wl < hz[1]).all()


def test_ship_rising_above_the_horizon_keeps_its_superstructure():
    rng = np.random.default_rng(5)
    ship = {"cx": 300, "base": 126, "length": 40, "height": 5, "sup_w": 14, "sup_h": 12,
            "contrast": -40}  # fmt: skip
    img, truth, hz = sea_scene(rng, ships=[ship], noise=1.0)
    det = ClassicalShipDetector()(as_u8(img), horizon=hz)
    found, n_false = match(det, truth)
    assert found[0] >= 0 and n_false == 0
    assert det.y[found[0]] < hz[1] - 5  # the box reaches above the horizon line


def test_tiny_ship_three_pixels_high_is_found_in_a_1080p_frame():
    rng = np.random.default_rng(11)
    ship = {"cx": 1200, "base": 520, "length": 9, "height": 3, "contrast": -30}
    img, truth, hz = sea_scene(rng, 1080, 1920, 450.0, ships=[ship], noise=2.0)
    det = ClassicalShipDetector()(as_u8(img), horizon=hz)
    found, n_false = match(det, truth)
    assert found[0] >= 0 and n_false == 0


def test_sixteen_bit_thermal_frame_gives_the_same_ships_as_eight_bit():
    rng = np.random.default_rng(1234)
    img, truth, hz = sea_scene(rng, ships=fixed_ships())
    u8 = as_u8(img)
    u16 = (u8.astype(np.uint16) * 40 + 3000).astype(np.uint16)
    a = ClassicalShipDetector()(u8, horizon=hz)
    b = ClassicalShipDetector()(u16, horizon=hz)
    assert len(a) == len(b) == len(truth)
    order_a, order_b = np.argsort(a.x), np.argsort(b.x)
    np.testing.assert_allclose(a.boxes[order_a][:, :4], b.boxes[order_b][:, :4], atol=1.0)


def test_colour_boat_as_bright_as_the_sea_is_found_by_its_chroma():
    rng = np.random.default_rng(2)
    img, _, hz = sea_scene(rng, noise=1.0)
    grey = as_u8(img)
    bgr = np.dstack([grey, grey, grey]).astype(np.float64)
    # an orange hull of the sea's own luma: 0.299 R + 0.587 G + 0.114 B unchanged
    r0, r1, c0, c1 = 196, 200, 300, 312
    luma = bgr[r0:r1, c0:c1, 0].copy()
    bgr[r0:r1, c0:c1, 2] = luma + 40  # R
    bgr[r0:r1, c0:c1, 1] = luma - 40 * 0.299 / 0.587  # G
    bgr[r0:r1, c0:c1, 0] = luma  # B
    bgr = as_u8(bgr)
    truth = np.array([[c0 - 0.5, r0 - 0.5, c1 - c0, r1 - r0, (c0 + c1 - 1) / 2, r1 - 0.5]])
    found, n_false = match(ClassicalShipDetector()(bgr, horizon=hz), truth)
    assert found[0] >= 0 and n_false == 0
    found, _ = match(ClassicalShipDetector(colour=False)(bgr, horizon=hz), truth)
    assert found[0] < 0  # the luma alone does not show it


def test_sea_mask_restricts_boxes_to_the_sea():
    rng = np.random.default_rng(1234)
    img, truth, _ = sea_scene(rng, ships=fixed_ships())
    mask = np.zeros(img.shape, bool)
    mask[130:, :320] = True  # only the left half of the sea
    det = ClassicalShipDetector()(as_u8(img), sea_mask=mask)
    found, n_false = match(det, truth)
    left = truth[:, 4] < 320
    assert (found[left] >= 0).all() and (found[~left] < 0).all() and n_false == 0


def test_temporal_model_fades_a_static_hot_spot_but_keeps_a_moving_ship():
    rng = np.random.default_rng(4)
    base_img, _, _ = sea_scene(rng, 240, 320, 60.0, wave_amp=0.0, noise=0.0)
    det_t = ClassicalShipDetector(temporal=True, temporal_rate=1.0)  # learns in ~100 frames
    det_0 = ClassicalShipDetector()
    hot = (150, 80)  # fixed-pattern hot spot (row, col), 3×3 px
    for k in range(120):
        img = base_img + rng.normal(0, 2.0, base_img.shape)
        img[hot[0] - 1 : hot[0] + 2, hot[1] - 1 : hot[1] + 2] += 40
        c = 20 + 2 * k  # a dark ship moving 2 px per frame
        img[186:191, c : c + 14] -= 35
        u8 = as_u8(img)
        a = det_t(u8)
    b = det_0(u8)
    truth_hot = np.array([[hot[1] - 1.5, hot[0] - 1.5, 3, 3, hot[1], hot[0] + 1.5]])
    truth_ship = np.array([[c - 0.5, 185.5, 14, 5, c + 6.5, 190.5]])
    assert match(b, truth_hot)[0][0] >= 0  # frame by frame the hot spot is a target
    assert match(a, truth_hot)[0][0] < 0  # the temporal model has learnt it
    assert match(a, truth_ship)[0][0] >= 0 and match(b, truth_ship)[0][0] >= 0
    det_t.reset()
    assert match(det_t(u8), truth_hot)[0][0] >= 0


def test_temporal_model_keeps_a_ship_that_stays_put_at_the_default_rate():
    rng = np.random.default_rng(6)
    base_img, _, _ = sea_scene(rng, 240, 320, 60.0, wave_amp=0.0, noise=0.0)
    det = ClassicalShipDetector(temporal=True)
    truth = np.array([[99.5, 185.5, 14, 5, 106.5, 190.5]])
    for _ in range(150):  # 6 s at 25 frames/s, static camera, anchored ship
        img = base_img + rng.normal(0, 2.0, base_img.shape)
        img[186:191, 100:114] -= 35
        boxes = det(as_u8(img))
    found, n_false = match(boxes, truth)
    assert found[0] >= 0 and n_false == 0


@pytest.mark.parametrize("value", [0, 255])
def test_all_black_or_all_white_frame_gives_no_boxes(value):
    frame = np.full((480, 640, 3), value, np.uint8)
    assert len(ClassicalShipDetector()(frame)) == 0
    assert len(ClassicalShipDetector()(frame, horizon=(0, 200, 639, 200))) == 0
    assert len(ClassicalShipDetector()(np.full((64, 64), float(value)))) == 0


def test_horizon_not_found_or_off_the_image_is_handled():
    rng = np.random.default_rng(1234)
    img, truth, _ = sea_scene(rng, ships=fixed_ships())

    class NotFound:
        found, x0, y0, x1, y1, confidence = False, 0.0, 0.0, 639.0, 0.0, 0.1

    assert len(ClassicalShipDetector()(as_u8(img), horizon=NotFound())) >= len(truth)
    assert len(ClassicalShipDetector()(as_u8(img), horizon=(0, 500, 639, 500))) == 0
    assert len(ClassicalShipDetector()(as_u8(img), sea_mask=np.zeros(img.shape, bool))) == 0


@pytest.mark.parametrize(
    "image",
    [
        np.zeros((32, 32, 2), np.uint8),
        np.zeros(32, np.uint8),
        np.zeros((4, 4), np.uint8),
        np.zeros((32, 32), complex),
        np.full((32, 32), np.nan),
    ],
)
def test_bad_image_raises_value_error_naming_image(image):
    with pytest.raises(ValueError, match="image"):
        ClassicalShipDetector()(image)


def test_bad_mask_horizon_and_options_raise_value_error_naming_them():
    img = np.zeros((64, 64), np.uint8)
    with pytest.raises(ValueError, match="sea_mask"):
        ClassicalShipDetector()(img, sea_mask=np.ones((10, 10), bool))
    with pytest.raises(ValueError, match="horizon"):
        ClassicalShipDetector()(img, horizon=(0, 1, 0, 5))
    with pytest.raises(ValueError, match="horizon"):
        ClassicalShipDetector()(img, horizon="left")
    for kw, name in [
        ({"threshold": -1}, "threshold"),
        ({"threshold": 4, "grow_threshold": 5}, "grow_threshold"),
        ({"polarity": "up"}, "polarity"),
        ({"levels": 0}, "levels"),
        ({"max_size": 2}, "max_size"),
        ({"max_aspect": (0.5, 2)}, "max_aspect"),
        ({"temporal_rate": 0}, "temporal_rate"),
        ({"refine": "grabcut"}, "refine"),
        ({"cell": 8}, r"cell: expected \(rows, cols\)"),
        ({"cell": (8, 64, 2)}, r"cell: expected \(rows, cols\)"),
        ({"cell": (8, 1)}, "cell: expected both sides >= 2 px"),
    ]:
        with pytest.raises(ValueError, match=name):
            ClassicalShipDetector(**kw)
    assert ClassicalShipDetector(cell=(6.0, 40)).cell == (6, 40)


# ------------------------------------------------------------------ water line, whole ships


def paint_polygon(img: np.ndarray, poly, value: float, ss: int = 16) -> None:
    """Paint a convex polygon (K, 2) [px] onto a float image in place, each pixel mixed
    by the fraction of it the polygon covers (ss × ss samples per pixel; pixel (r, c)
    covers [c − ½, c + ½] × [r − ½, r + ½]): an ideal anti-aliased drawing."""
    poly = np.asarray(poly, float)
    h, w = img.shape
    c0 = max(0, int(np.floor(poly[:, 0].min() + 0.5)))
    c1 = min(w - 1, int(np.ceil(poly[:, 0].max() - 0.5)))
    r0 = max(0, int(np.floor(poly[:, 1].min() + 0.5)))
    r1 = min(h - 1, int(np.ceil(poly[:, 1].max() - 0.5)))
    off = (np.arange(ss) + 0.5) / ss - 0.5
    X = (np.arange(c0, c1 + 1)[:, None] + off).ravel()[None, :]
    Y = (np.arange(r0, r1 + 1)[:, None] + off).ravel()[:, None]
    inside = np.ones((Y.size, X.size), bool)
    k = len(poly)
    area2 = sum(
        poly[i, 0] * poly[(i + 1) % k, 1] - poly[(i + 1) % k, 0] * poly[i, 1] for i in range(k)
    )
    for i in range(k):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % k]
        inside &= np.sign(area2) * ((bx - ax) * (Y - ay) - (by - ay) * (X - ax)) >= 0
    a = inside.reshape(r1 - r0 + 1, ss, c1 - c0 + 1, ss).mean(axis=(1, 3))
    img[r0 : r1 + 1, c0 : c1 + 1] += a * (value - img[r0 : r1 + 1, c0 : c1 + 1])


def box_ship(img, base, cx, wl, length, hull, contrast, sup=(0.4, 6), slope=0.0):
    """A hull (length × hull px) whose bottom edge passes through (cx, wl) with the given
    slope [px/px], a superstructure (sup[0] × length wide, sup[1] px high) on it, drawn
    with exact coverage at ``contrast`` grey levels from the local sea. Returns the truth
    row (x, y, w, h, u_wl, v_wl)."""
    bg = float(np.median(base[int(wl) - 12 : int(wl) + 12, int(cx - length) : int(cx + length)]))
    a, b = cx - length / 2, cx + length / 2
    ya, yb = wl - slope * length / 2, wl + slope * length / 2
    paint_polygon(img, [(a, ya - hull), (b, yb - hull), (b, yb), (a, ya)], bg + contrast)
    top = min(ya, yb) - hull
    if sup[1]:
        s = sup[0] * length / 2
        paint_polygon(img, [(cx - s, top - sup[1]), (cx + s, top - sup[1]), (cx + s, top + 0.5),
                            (cx - s, top + 0.5)], bg + 0.8 * contrast)  # fmt: skip
        top -= sup[1]
    return (a, top, length, max(ya, yb) - top, cx, wl)


def hull_scene(seed: int, blur: float):
    """Six ships (hulls 5–10 px high, 36–60 px long, ±40–45 grey levels) whose water
    lines fall at eighths of a pixel, blurred like a lens (Gaussian, ``blur`` px), with
    noise 2 grey levels; returns the 8-bit frame, truth and horizon."""
    rng = np.random.default_rng(seed)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    specs = [
        (130, 175.0, 40, 6, -40),
        (300, 190.125, 50, 8, 40),
        (470, 205.25, 36, 5, -45),
        (140, 260.375, 56, 9, 45),
        (320, 285.5, 44, 7, -40),
        (500, 300.625, 60, 10, 40),
    ]  # (cx, water line, length, hull height, contrast)
    truth = np.array([box_ship(img, base, *sp) for sp in specs])
    if blur:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    return as_u8(img + rng.normal(0, 2.0, img.shape)), truth, hz


@pytest.mark.parametrize("refine", REFINE)
@pytest.mark.parametrize("blur", [0.0, 0.8, 1.2])
def test_water_line_of_antialiased_blurred_hulls_is_found_to_a_tenth_of_a_pixel(blur, refine):
    """Sub-pixel water line: the bottom of a thresholded mask is off by up to a pixel
    (0.3 px RMS from the pixel grid alone, more with blur); the coverage integral across
    the hull/sea edge is not moved by a symmetric blur. Measured RMS 0.05–0.09 px, worst
    0.2 px (a 5 px hull under 1.2 px blur); the committed detector: 0.25–1.5 px on the
    same five hulls (it also boxes the sixth without its hull, as refine="mask" does)."""
    img, truth, hz = hull_scene(1234, blur)
    det = ClassicalShipDetector(refine=refine)(img, horizon=hz)
    found, n_false = match(det, truth)
    assert (found >= 0).all() and n_false == 0
    hulls = np.arange(6)
    if refine == "mask":  # the 56 px bright hull: its superstructure boxed alone (above)
        hulls = np.array([0, 1, 2, 4, 5])
        j = found[3]
        assert truth[3, 0] <= det.x[j] and det.x[j] + det.w[j] <= truth[3, 0] + truth[3, 2]
    dv = det.v_wl[found[hulls]] - truth[hulls, 5]
    assert np.abs(dv).max() <= 0.3
    assert np.sqrt(np.mean(dv**2)) <= 0.12
    assert abs(dv.mean()) <= 0.08
    assert np.abs(det.u_wl[found[hulls]] - truth[hulls, 4]).max() <= 1.0  # the hull's middle


@pytest.mark.parametrize("refine", REFINE)
def test_water_line_of_a_hull_seen_at_an_angle_lies_on_its_sloping_edge(refine):
    rng = np.random.default_rng(1234)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    slope = 4.0 / 70  # the hull's bottom falls 4 px over its 70 px
    t = box_ship(img, base, 320.0, 230.3, 70, 9, -40, sup=(0.3, 7), slope=slope)
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.8) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector(refine=refine)(img, horizon=hz)
    found, n_false = match(det, np.array([t]))
    assert found[0] >= 0 and n_false == 0
    u, v = det.u_wl[found[0]], det.v_wl[found[0]]
    assert abs(u - t[4]) <= 1.0
    assert abs(v - (t[5] + slope * (u - t[4]))) <= 0.15  # on the edge, not its lowest end


@pytest.mark.parametrize("colour", [False, True])
def test_ship_ends_follow_a_fraction_of_a_pixel(colour):
    """A 40 px hull (with its superstructure) moved by eighths of a pixel, drawn with
    exact coverage, lens-blurred (0.8 px), noise 2 grey levels: the box's ends are on
    the hull's ends to 0.15 px and move with it. Whole-pixel ends (the mask's, before)
    were 0.5 px off at the half-pixel shifts and stood still between them."""
    rng = np.random.default_rng(5)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    noise = rng.normal(0, 2.0, base.shape)
    lefts = []
    for k in range(8):
        img = base.copy()
        t = box_ship(img, base, 300.0 + k / 8, 220.4, 40, 6, -45)
        img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.8) + noise)
        if colour:
            img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
        det = ClassicalShipDetector()(img, horizon=hz)
        found, n_false = match(det, np.array([t]))
        assert found[0] >= 0 and n_false == 0, det.boxes
        x, w = det.x[found[0]], det.w[found[0]]
        assert abs(x - t[0]) < 0.15 and abs(x + w - t[0] - t[2]) < 0.15, (k, x, w, t)
        lefts.append(x)
    assert np.all(np.diff(lefts) > 0), lefts


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    shift=st.floats(0.0, 1.0, exclude_max=True),
    length=st.integers(8, 70),
    contrast=st.sampled_from([-60.0, -35.0, 35.0, 60.0]),
    blur=st.floats(0.0, 1.2),
)
def test_ship_ends_on_a_calm_sea_are_its_outline(shift, length, contrast, blur):
    """Property: a hull of any length, position and polarity on a calm sea, drawn with
    exact coverage and blurred by up to 1.2 px (noise 1 grey level): its box's ends lie
    within 0.15 px of the hull's (the coverage integral is blind to the blur but for its
    tail beyond the 4-px window: up to 0.13 px at 1 px of blur)."""
    rng = np.random.default_rng(3)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0, wave_amp=0.0)
    img = base.copy()
    t = box_ship(img, base, 300.0 + shift, 230.4, length, 6, contrast, sup=(0.4, 4))
    if blur:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    img = as_u8(img + rng.normal(0, 1.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, _ = match(det, np.array([t]))
    assert found[0] >= 0, det.boxes
    x, w = det.x[found[0]], det.w[found[0]]
    assert abs(x - t[0]) < 0.15 and abs(x + w - t[0] - t[2]) < 0.15, (x, w, t)


def _two_ships(seed: int, first: tuple, second: tuple, **detector):
    """A sea scene with two ships drawn by :func:`box_ship` (``(cx, wl, length, hull,
    contrast, sup)`` each), lens-blurred, noise 2 grey levels; returns the detections,
    the truth rows and the index of each truth row's detection (no false box)."""
    rng = np.random.default_rng(seed)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    truth = np.array([box_ship(img, base, *first[:5], sup=first[5]),
                      box_ship(img, base, *second[:5], sup=second[5])])  # fmt: skip
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector(**detector)(img, horizon=hz)
    found, n_false = match(det, truth)
    assert (found >= 0).all() and n_false == 0, det.boxes
    return det, truth, found


def _own_sides(det, truth: np.ndarray, found: np.ndarray) -> None:
    """Each ship's box has its own left and right sides, within a pixel."""
    np.testing.assert_allclose(det.x[found], truth[:, 0], atol=1.0)
    np.testing.assert_allclose(det.x[found] + det.w[found], truth[:, 0] + truth[:, 2], atol=1.0)


@pytest.mark.parametrize("refine", REFINE)
def test_ship_in_front_of_another_gives_two_boxes_with_their_own_water_lines(refine):
    """A 40 px ship 2.3 px lower in the image (nearer) in front of a 90 px one: one
    connected object whose water line jumps; the committed detector gave one box (the
    far ship's) with a water line between the two."""
    far, near = (300.0, 200.4, 90, 7, -45, (1 / 3, 6)), (310.0, 202.7, 40, 8, -70, (0, 0))
    det, truth, found = _two_ships(1234, far, near, refine=refine)
    np.testing.assert_allclose(det.v_wl[found], truth[:, 5], atol=0.2)
    _own_sides(det, truth, found)  # the far ship spans the near one


def test_merge_rule_keeps_a_boat_at_a_ship_s_corner_apart_but_not_glitter():
    """:meth:`ClassicalShipDetector._mergeable` on the crossing case's own candidates
    (working pixels): the ships' box and the boat hanging below its bottom at a corner
    stay apart; the same geometry of bright-only boxes (glitter) merges; a
    superstructure on its hull (sharing its columns) and two pieces of a hull side by
    side (sharing their rows) merge."""
    from seawatch.vision.detect import _Candidate

    def cand(box, polarity):
        return _Candidate(np.array(box, float), 1, 10.0, polarity)

    rule = ClassicalShipDetector()._mergeable
    ships, boat = [441, 132, 536, 152], [426, 150, 442, 158]
    assert not rule(cand(ships, 2), cand(boat, 3))
    assert not rule(cand(boat, 3), cand(ships, 2))  # either order
    assert rule(cand(ships, 1), cand(boat, 1))  # glitter
    assert rule(cand([470, 120, 500, 131], 2), cand([441, 132, 536, 152], 2))  # stacked
    assert rule(cand([441, 140, 480, 152], 2), cand([483, 141, 536, 152], 2))  # side by side


def test_a_nearer_boat_at_a_far_ship_s_corner_is_boxed_alone():
    """The rendered crossing case (seed 0, 960 × 540, lossless) in its last second: the
    14 × 5 px boat passes under the container ship's bow, its top in the ship's bottom
    rows and its columns reaching 1-2 of the ship's. Its box is its own in each frame
    (within 1.5 px of its centre, its width within 30 %). Before, the two candidates,
    overlapping at a corner, were merged, and the boat, the container ship and the
    ferry were one 117-123 px box in frames 182, 191 and 194."""
    from seawatch.synth.cases import ship_video_case
    from seawatch.synth.render import Renderer
    from seawatch.vision.horizon import HorizonTracker

    case = ship_video_case("crossing", duration=8.0, width=960, height=540, seed=0)
    renderer = Renderer(case.camera, case.ships, 25.0, lighting=case.lighting,
                        sway=case.sway, coastline=case.coastline, seed=case.seed)  # fmt: skip
    detector, horizon = ClassicalShipDetector(), HorizonTracker(fps=25.0)
    for index in range(178, 195):
        frame = renderer.frame(index)
        img = frame.bgr()
        det = detector(img, horizon=horizon.update(img))
        if index not in (182, 191, 194):
            continue
        boat = next(o for o in frame.objects if o.object_id == 3)
        cx, cy = det.x + det.w / 2, det.y + det.h / 2
        near = np.hypot(cx - boat.x - boat.w / 2, cy - boat.y - boat.h / 2) < 1.5
        own = near & (np.abs(det.w - boat.w) < 0.3 * boat.w)
        assert own.any(), (index, det.boxes[:, :4].round(1), (boat.x, boat.y, boat.w, boat.h))


@pytest.mark.parametrize("seed", [1234, 99])
def test_ship_one_pixel_nearer_than_the_one_behind_it_gives_two_boxes(seed):
    """Two ships whose water lines are 1.0 px apart (a 40 px ship in front of the middle
    of a 90 px one, the overtaking case's geometry at 960×540): two boxes, each with its
    own water line and sides. With the 1 px jump for every split (before) they were one
    box: the running medians put the step at 0.9–1.0 px."""
    far, near = (300.0, 200.4, 90, 7, -45, (1 / 3, 6)), (280.0, 201.4, 40, 8, -70, (0, 0))
    det, truth, found = _two_ships(seed, far, near)
    np.testing.assert_allclose(det.v_wl[found], truth[:, 5], atol=0.2)
    _own_sides(det, truth, found)


@pytest.mark.parametrize("gap", [5.0, 7.0, 9.0])
def test_two_ships_side_by_side_are_split_at_the_sea_between_them(gap):
    """A 40 px ship with a superstructure and, ``gap`` px of sea to its right, a 26 px
    boat 1.1 px nearer (the rendered meeting case's ferry and workboat): one connected
    object whose water line steps across the columns of sea. Two boxes, each with its
    own sides. Before, a run of columns without an edge was never a break: the break
    fell one column into the boat, and the two were one box (72-76 px) in all three
    cases. (Other noise draws: seed 99 still gives one box at 5 and 7 px, seed 7 boxes
    the ship 8-10 px into the sea at 7 and 9 px.)"""
    ship, boat = (300.0, 200.4, 40, 5, -45, (0.6, 4)), (333.0 + gap, 201.5, 26, 6, -70, (0, 0))
    _own_sides(*_two_ships(1234, ship, boat))


@pytest.mark.parametrize("refine", REFINE)
def test_thin_mast_is_inside_the_box(refine):
    rng = np.random.default_rng(1234)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    t = box_ship(img, base, 320.0, 240.5, 40, 6, -40, sup=(0, 0))
    paint_polygon(img, [(319.65, 218.2), (320.35, 218.2), (320.35, 234.5), (319.65, 234.5)],
                  float(np.median(base[230:250, 280:360])) - 60)  # fmt: skip
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector(refine=refine)(img, horizon=hz)
    found, n_false = match(det, np.array([t]))
    assert found[0] >= 0 and n_false == 0
    assert abs(det.y[found[0]] - 218.2) <= 1.0  # a 0.7 px mast 16 px high: the box's top


def test_pale_superstructure_five_times_fainter_than_its_hull_is_inside_the_box():
    """A dark hull (−80 grey levels from the sea) under a pale superstructure (+16): the
    superstructure is far above the noise (2 grey levels) but below 0.4 × the hull's
    contrast; it is part of the ship, and the box's top is its top. The default
    refinement only: ``refine="flank"`` seeds each polarity at half the candidate's peak
    and leaves such a superstructure out."""
    rng = np.random.default_rng(4321)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    t = box_ship(img, base, 320.0, 240.5, 60, 6, -80, sup=(0, 0))
    bg = float(np.median(base[230:250, 260:380]))
    paint_polygon(img, [(305.0, 224.5), (335.0, 224.5), (335.0, 235.0), (305.0, 235.0)], bg + 16)
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, n_false = match(det, np.array([t]))
    assert found[0] >= 0 and n_false == 0
    k = found[0]
    assert abs(det.y[k] - 224.5) <= 1.0, det.y[k]  # the superstructure's top
    assert abs(det.v_wl[k] - 240.5) <= 0.3, det.v_wl[k]  # the hull's water line


@pytest.mark.parametrize("base_y", [210.2, 210.5, 210.8, 211.1])
def test_box_bottom_is_the_water_line_not_the_smoothing_spill_below_a_strong_hull(base_y):
    """A strong dark hull (−90 grey levels, 60 × 9 px with a superstructure) at four
    sub-pixel water lines: the box ends at the water line, its lowest point, within
    0.25 px — a half-covered row of the smoothing's spill below the hull does not extend
    it. Measured: 0.15–0.21 px; before (the mask's bottom row, extended to the water
    line): 0.14–0.40 px, and in the rendered cases the box bottom lay a median 0.4–1.3 px
    below the water line (medium CLE 1.03 → 0.70 %)."""
    rng = np.random.default_rng(11)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    t = box_ship(img, base, 320.0, base_y, 60, 9, -90, sup=(0.4, 5))
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, _ = match(det, np.array([t]), tol=3.0)
    assert found[0] >= 0, det.boxes
    b = det.boxes[found[0]]
    assert abs((b[1] + b[3]) - (t[1] + t[3])) <= 0.25, (b, t)


def test_dark_hull_between_bright_glint_streaks_is_boxed_alone():
    """A dark hull (−60 grey levels, 50 × 7 px, with a superstructure) with a bright sun
    glint streak (+60, 40 px long) beside it on either side, touching it, at its water
    line's rows — the lighting case's low sun. Hull and glint are of opposite
    polarities and not stacked, so they are not one object: the hull's box is its own
    (within a pixel), its water line is the hull's. Measured before the polarity split:
    one 137 px box from the left streak's start to the right streak's end."""
    rng = np.random.default_rng(77)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    bright = float(np.median(base[195:225, 240:400])) + 60.0
    paint_polygon(img, [(262.0, 205.5), (302.0, 205.5), (302.0, 209.5), (262.0, 209.5)], bright)
    t = box_ship(img, base, 330.0, 210.5, 50, 7, -60, sup=(0.4, 4))
    paint_polygon(img, [(358.0, 207.5), (400.0, 207.5), (400.0, 212.5), (358.0, 212.5)], bright)
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, _ = match(det, np.array([t]), tol=3.0)
    assert found[0] >= 0, det.boxes
    k = found[0]
    assert np.all(np.abs(det.boxes[k, :4] - t[:4]) <= 1.0), (det.boxes[k], t)
    assert abs(det.v_wl[k] - t[5]) <= 0.3, (det.v_wl[k], t[5])
    assert not np.any(det.w > 60), det.boxes  # no box spans hull and glint


def test_rendered_sun_glitter_boxes_must_stand_out_from_a_background_of_their_own(tmp_path):
    """The rendered lighting case (seed 0, 960×540, its first second) looks into a low
    sun: a bright candidate is kept only where the flank refinement, which drops a
    glint path's structure running on beyond its windows, also finds an object.
    Measured (session 16): 89 boxes in the 25 frames, 112 without that check; the
    dark ferry is boxed (centre within 3 px, city block) in 16 frames either way."""
    from seawatch.scenarios.ship_video import detect_video, read_truth
    from seawatch.synth import render_case

    res = render_case("lighting", tmp_path, duration=1.0, width=960, height=540, seed=0)
    dets = detect_video(res.video)
    truth = read_truth(res.truth)
    assert len(dets) == 25
    assert sum(len(b) for b in dets) <= 95
    hits = 0
    for f, _, x, y, w, h in truth[truth[:, 1] == 1]:
        b = dets[int(f)]
        if len(b):
            c = b[:, :2] + b[:, 2:4] / 2
            hits += int(np.min(np.abs(c - [x + w / 2, y + h / 2]).sum(axis=1)) <= 3.0)
    assert hits >= 15


def test_a_boat_under_two_pixels_high_is_kept():
    """A dark boat 8 × 1.7 px (−50 grey levels, lens blur 0.5 px, noise 2 levels) with
    its water line at four sub-pixel phases on four seas: found in all 16 (a centre
    within 2 px). The box of a boat under 2 px is under 2 px high in some phases (the
    rendered lighting case's 7.2 × 1.8 px boat: in 80 of its 295 boxes); a least side
    of 2 px (before session 16) lost one of the 16 here."""
    found = {2.0: 0, None: 0}
    for seed in range(4):
        for frac in (0.0, 0.25, 0.5, 0.75):
            rng = np.random.default_rng(100 + seed)
            base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
            img = base.copy()
            t = box_ship(img, base, 320.0, 200.0 + frac, 8, 1.7, -50, sup=(0.0, 0))
            img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.5) + rng.normal(0, 2.0, img.shape))
            for least in found:
                kw = {} if least is None else {"min_size": least}
                det = ClassicalShipDetector(**kw)(img, horizon=hz)
                k = match(det, np.array([t]), tol=2.0)[0][0]
                found[least] += int(k >= 0)
    assert found[None] == 16
    assert found[2.0] < 16  # what the default's 1.5 px keeps


def test_dark_hull_over_glint_streaks_is_not_merged_with_them():
    """A dark hull (−60 grey levels, 50 × 7 px, with a superstructure) with bright glint
    streaks (+60, 40 × 3 px) under it: one touching its water line and two more below
    it, 6 px apart — looking into a low sun. A dark part above a bright one is no
    ship's fragments (a pale superstructure sits on a dark hull, not under it): the
    hull is boxed alone (within a pixel) and no box reaches from the hull down into the
    streaks. Measured before (session 16): one 60 × 32 px box over hull and streaks,
    the hull not boxed (the rendered lighting case, seed 1: 215 × 129 px)."""
    rng = np.random.default_rng(78)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    bright = float(np.median(base[195:245, 240:420])) + 60.0
    t = box_ship(img, base, 330.0, 210.5, 50, 7, -60, sup=(0.4, 4))
    for x0, x1, y0 in ((310.0, 350.0, 210.5), (300.0, 340.0, 219.5), (320.0, 360.0, 228.5)):
        paint_polygon(img, [(x0, y0), (x1, y0), (x1, y0 + 3.0), (x0, y0 + 3.0)], bright)
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, _ = match(det, np.array([t]), tol=3.0)
    assert found[0] >= 0, det.boxes
    assert np.all(np.abs(det.boxes[found[0], :4] - t[:4]) <= 1.0), (det.boxes[found[0]], t)
    spans = (det.y < t[1] + t[3]) & (det.y + det.h > t[1] + t[3] + 6.0)
    assert not spans.any(), det.boxes  # no box from the hull down into the streaks


@pytest.mark.parametrize("cx", [300.0, 330.0, 352.25])
def test_dark_hull_in_front_of_a_glare_band_is_boxed_without_it(cx):
    """A dark hull (−120 grey levels, 56 × 4 px, a superstructure 5 px high) in front
    of a band of glare (+45, 150 × 8 px, from the superstructure's foot to the water
    line) — the rendered lighting case's ferry against the low sun's haze. Beside the
    hull's ends the band is brighter than the CFAR background that the hull darkens
    around it; it is the other polarity beyond the hull's columns, no part of the ship:
    the box is the ship's (within a pixel). Measured before (session 21): 77 and 86 px
    long at 300 and 352.25 (56.4 at 330), the boxes running on into the band."""
    rng = np.random.default_rng(79)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    bright = min(255.0, float(np.median(base[190:230, 220:440])) + 45.0)
    paint_polygon(img, [(250.0, 202.5), (400.0, 202.5), (400.0, 210.5), (250.0, 210.5)], bright)
    t = box_ship(img, base, cx, 210.5, 56, 4, -120, sup=(0.6, 5))
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, _ = match(det, np.array([t]), tol=3.0)
    assert found[0] >= 0, det.boxes
    assert np.all(np.abs(det.boxes[found[0], :4] - t[:4]) <= 1.0), (det.boxes[found[0]], t)


def test_rendered_ferry_against_the_low_sun_is_boxed_its_own_length(tmp_path):
    """The rendered lighting case (seed 0, 960×540, its first 2 s): the ferry sails in
    front of the low sun's glare band. Its box (the one nearest its centre, within
    10 px city block) is its own length to 2 px in every frame it is found, found in
    48 or more of the 50. Measured (session 21): 50 found, every width within 1.4 px;
    without the trimming of the other polarity beside and under a hull, 28 of the 49
    found off by more than 2 px (up to 19.0 px, the box run on into the band)."""
    from seawatch.scenarios.ship_video import detect_video, read_truth
    from seawatch.synth import render_case

    res = render_case("lighting", tmp_path, duration=2.0, width=960, height=540, seed=0)
    dets = detect_video(res.video)
    truth = read_truth(res.truth)
    found, off = 0, []
    for f, _, x, y, w, h in truth[truth[:, 1] == 1]:
        b = dets[int(f)]
        if not len(b):
            continue
        d = np.abs(b[:, 0] + b[:, 2] / 2 - x - w / 2) + np.abs(b[:, 1] + b[:, 3] / 2 - y - h / 2)
        j = int(np.argmin(d))
        if d[j] <= 10.0:
            found += 1
            off.append(abs(b[j, 2] - w))
    assert found >= 48, found
    assert max(off) <= 2.0, max(off)


@pytest.mark.parametrize("cx", [300.0, 320.5, 341.25])
def test_glint_streak_under_part_of_a_dark_hull_is_no_part_of_it(cx):
    """A dark hull (−120 grey levels, 56 × 5 px, with a superstructure) and a bright
    glint streak (+45, 44 × 3 px) on the water under its first two thirds, touching its
    water line — the rendered lighting case's ferry in frames 37–39 (seed 0). The
    streak is the other polarity under the hull's lowest pixels, no part of the ship:
    one box, within a pixel, its water line within half a pixel. Measured before
    (session 21): the boxes 1.2 px too tall with their water lines 0.75–1.0 px low, and
    at 320.5 the ship split where the streak ends (a 42.8 px box: two hulls over two
    seas, one water line dragged down by the streak)."""
    rng = np.random.default_rng(80)
    base, _, hz = sea_scene(rng, 360, 640, 120.0, noise=0.0)
    img = base.copy()
    bright = min(255.0, float(np.median(base[200:240, 220:440])) + 45.0)
    t = box_ship(img, base, cx, 210.5, 56, 5, -120, sup=(0.6, 5))
    a = t[0] - 6.0
    paint_polygon(img, [(a, 210.5), (a + 44.0, 210.5), (a + 44.0, 213.5), (a, 213.5)], bright)
    img = as_u8(cv2.GaussianBlur(img, (0, 0), 0.7) + rng.normal(0, 2.0, img.shape))
    det = ClassicalShipDetector()(img, horizon=hz)
    found, _ = match(det, np.array([t]), tol=3.0)
    assert found[0] >= 0, det.boxes
    assert np.all(np.abs(det.boxes[found[0], :4] - t[:4]) <= 1.0), (det.boxes[found[0]], t)
    assert abs(det.v_wl[found[0]] - t[5]) <= 0.5, (det.v_wl[found[0]], t[5])


@settings(max_examples=60, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10_000), dark=st.booleans(), thr=st.floats(0.5, 4.0))
def test_trimming_keeps_the_own_polarity_and_what_lies_within_its_columns_above_its_bottom(
    seed, dark, thr
):
    """Property of :func:`_trim_other_polarity` on random contrast planes: it only
    removes pixels; it removes none of the candidate's own polarity, none of the other
    polarity within the own pixels' columns and above their lowest one there, and none
    that stands out at least 2/3 as much as the strongest own pixel; what it removes is
    of the other polarity. Returns the mask itself when nothing is removed."""
    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(3, 20)), int(rng.integers(3, 40))
    own = np.abs(rng.normal(0.0, 3.0, (h, w))).astype(np.float32)
    other = np.abs(rng.normal(0.0, 3.0, (h, w))).astype(np.float32)
    r0, c0 = int(rng.integers(0, h - 1)), int(rng.integers(0, w - 1))
    r1, c1 = int(rng.integers(r0 + 1, h + 1)), int(rng.integers(c0 + 1, w + 1))
    own[r0:r1, c0:c1] += 6.0  # the candidate: its own polarity stands out over its pixels
    sel = np.maximum(own, other) > thr
    bright, darkp = (other, own) if dark else (own, other)
    out = trim_other_polarity(sel, bright, darkp, thr, (r0, r1, c0, c1))
    assert out.dtype == bool and out.shape == sel.shape
    assert not np.any(out & ~sel)  # nothing added
    removed = sel & ~out
    if not removed.any():
        assert out is sel
        return
    assert np.all(other[removed] > own[removed])  # only the other polarity goes
    own_px = sel & (own > thr) & (own >= other)
    assert own_px.any()
    assert float(other[removed].max()) < 2.0 / 3.0 * float(own[own_px].max())
    cols = np.flatnonzero(own_px.any(axis=0))
    rows = np.arange(h)[:, None]
    low = np.where(own_px, rows, -1).max(axis=0)
    inside = np.zeros((h, w), bool)
    inside[:, cols[0] : cols[-1] + 1] = True
    inside &= ~((rows > low) & (low >= 0))
    assert not np.any(removed & inside)


@pytest.mark.parametrize("refine", REFINE)
def test_rendered_footage_water_line_matches_truth_within_the_renderers_fill(tmp_path, refine):
    """Rendered H.264 footage (``seawatch.synth.render``): a 50 m ferry 800 m out and a
    30 m workboat 1 km out, broadside to a camera 10 m up (960×540, 60°), 10 frames.
    Detected minus truth water line, per ship: mean in [−0.1, +0.4] px, spread ≤ 0.15 px.
    The upper margin is the renderer's, not the detector's: its anti-aliased fill paints a
    hull's bottom edge 0.21–0.52 px (mean 0.29) below the polygon (OpenCV LINE_AA on a
    polygon pulled in by half a pixel), and the visible water line is the hull's near
    side, 0.05 px below midship here; measured +0.26 (ferry) and +0.29 (workboat). The
    committed detector: +1.2 and +1.1 px."""
    from seawatch.camera import PinholeCamera
    from seawatch.io.video import VideoReader
    from seawatch.synth import render
    from seawatch.synth.world import Trajectory, make_ship

    cam = PinholeCamera.from_fov(960, 540, 60.0, height=10.0, heading=0.0, pitch=-0.0175)
    t = np.array([0.0, 10.0])
    ships = [
        make_ship(1, Trajectory(t, np.full(2, 800.0), -60 + 3 * t, np.full(2, np.pi / 2)), 50.0,
                  kind="ferry"),
        make_ship(2, Trajectory(t, np.full(2, 1000.0), 120 + 3 * t, np.full(2, np.pi / 2)), 30.0,
                  kind="workboat"),
    ]  # fmt: skip
    res = render(cam, ships, 1.0, 10.0, out_dir=tmp_path, seed=3)
    truth = list(csv.DictReader(res.truth.open()))
    lines = {int(r["frame"]): [float(r[k]) for k in ("x0", "y0", "x1", "y1")]
             for r in csv.DictReader(res.horizon.open())}  # fmt: skip
    det = ClassicalShipDetector(refine=refine)
    errors: dict[int, list[float]] = {1: [], 2: []}
    with VideoReader(res.video) as reader:
        for fr in reader:
            boxes = det(fr.image, horizon=lines[fr.index])
            for r in (r for r in truth if int(r["frame"]) == fr.index):
                x, y, w, h = (float(r[k]) for k in "xywh")
                d = np.abs(boxes.centers - [x + w / 2, y + h / 2]).sum(axis=1)
                assert d.min() <= 3.0  # found, its box centre within 3 px
                errors[int(r["object_id"])].append(boxes.v_wl[np.argmin(d)] - float(r["v_wl"]))
    for e in errors.values():
        assert len(e) == 10
        assert -0.1 <= np.mean(e) <= 0.4
        assert np.std(e) <= 0.15


# ------------------------------------------------------------------ real thermal frames


@needs_mardct
@pytest.mark.parametrize("grey", [False, True], ids=["as-stored", "one-channel"])
@pytest.mark.parametrize("refine", REFINE)
def test_mardct_thermal_boat_recall_at_least_0_9_with_at_most_half_a_false_box_per_frame(
    refine, grey
):
    """Issue 6 target on real pixels: a detection centre within 12 px (city block) of the
    annotated box centre in ≥ 90 % of the 88 frames, ≤ 0.5 false boxes per frame. The
    sea region comes from the horizon detector (the sea–land boundary here). The frames
    are stored as RGBA; as a thermal camera gives them, one grey channel, they must do
    as well (they gave 5.2 false boxes a frame when the horizon weighed one channel
    less than three and was lost in 87 of the 88 frames)."""
    from seawatch.vision.horizon import detect_horizon

    rows = sorted(csv.DictReader((MARDCT / "boxes.csv").open()), key=lambda r: int(r["frame"]))
    det = ClassicalShipDetector(refine=refine)
    hits = false = 0
    for r in rows:
        img = cv2.imread(str(MARDCT / "images" / r["file"]), cv2.IMREAD_UNCHANGED)
        if grey:
            img = cv2.cvtColor(img, cv2.COLOR_BGRA2GRAY)
        boxes = det(img, horizon=detect_horizon(img))
        x, y, w, h = (float(r[k]) for k in "xywh")
        d = np.abs(boxes.centers - [x + w / 2, y + h / 2]).sum(axis=1)
        hits += bool((d <= 12).any())
        false += int((d > 12).sum())
    assert hits / len(rows) >= 0.9
    assert false / len(rows) <= 0.5


# ------------------------------------------------------------------ callable detector


def test_callable_detector_fills_scores_and_refines_the_water_line():
    rng = np.random.default_rng(1234)
    ship = {"cx": 300, "base": 220, "length": 40, "height": 8, "contrast": -40}
    img, truth, _ = sea_scene(rng, ships=[ship], noise=1.0)
    u8 = as_u8(img)
    x, y, w, h = truth[0, :4]
    loose = [[x - 3, y - 3, w + 6, h + 9]]  # a user box with slack below the hull
    det = CallableDetector(lambda im: np.array(loose))(u8)
    assert len(det) == 1 and det.score[0] == 1.0
    assert abs(det.v_wl[0] - truth[0, 5]) <= 1.0  # at the hull bottom, not the box bottom
    np.testing.assert_allclose(waterline_points(u8, loose)[0], det.boxes[0, 5:], atol=1e-9)
    plain = CallableDetector(lambda im: np.array(loose), refine_waterline=False)(u8)
    assert plain.v_wl[0] == pytest.approx(y - 3 + h + 9)


def test_callable_detector_accepts_dicts_passes_keywords_and_filters_off_sea_boxes():
    seen = {}

    def fn(image, *, sea_mask=None, horizon=None):
        seen["horizon"] = horizon
        return [
            {"x": 10, "y": 30, "w": 8, "h": 4, "score": 0.7, "u_wl": 14, "v_wl": 34},
            {"x": 10, "y": 2, "w": 8, "h": 4, "score": 0.9, "u_wl": 14, "v_wl": 6},
        ]

    img = np.full((64, 64), 100, np.uint8)
    det = CallableDetector(fn)(img, horizon=(0, 20, 63, 20))
    assert seen["horizon"] == (0, 20, 63, 20)
    assert len(det) == 1 and det.score[0] == pytest.approx(0.7)
    assert len(CallableDetector(fn, filter_sea=False)(img, horizon=(0, 20, 63, 20))) == 2


def test_callable_detector_rejects_bad_results_and_non_callables():
    img = np.full((64, 64), 100, np.uint8)
    with pytest.raises(ValueError, match="fn's result"):
        CallableDetector(lambda im: np.zeros((2, 3)))(img)
    with pytest.raises(ValueError, match="fn's result"):
        CallableDetector(lambda im: [{"x": 1}])(img)
    with pytest.raises(ValueError, match="fn"):
        CallableDetector(42)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="image"):
        CallableDetector(lambda im: [])(np.zeros((3, 3, 3, 3)))
    assert len(CallableDetector(lambda im: None)(img)) == 0


# ------------------------------------------------------------------ YOLO decoding / ONNX


def _yolov8_output(boxes_cxcywh, class_scores, anchors: int = 50) -> np.ndarray:
    """A (1, 4 + nc, A) tensor holding the given boxes first, zeros elsewhere."""
    nc = class_scores.shape[1]
    out = np.zeros((1, 4 + nc, anchors), np.float32)
    out[0, :4, : len(boxes_cxcywh)] = np.asarray(boxes_cxcywh).T
    out[0, 4:, : len(boxes_cxcywh)] = class_scores.T
    return out


def test_decode_yolov8_keeps_the_best_of_overlapping_boxes_and_filters_classes():
    boxes = [[100, 100, 40, 20], [102, 101, 40, 20], [300, 200, 10, 6], [50, 50, 8, 8]]
    scores = np.array([[0.1, 0.9], [0.2, 0.6], [0.05, 0.8], [0.7, 0.1]])
    xyxy, s, cls = decode_yolo(_yolov8_output(boxes, scores), score_threshold=0.5)
    np.testing.assert_allclose(s, [0.9, 0.8, 0.7], rtol=1e-6)
    np.testing.assert_allclose(xyxy[0], [80, 90, 120, 110])
    assert list(cls) == [1, 1, 0]
    xyxy, s, cls = decode_yolo(_yolov8_output(boxes, scores), classes=[1], iou_threshold=0.95)
    assert list(cls) == [1, 1, 1] and len(s) == 3  # the near-duplicate survives a loose NMS


def test_decode_yolov5_multiplies_objectness_and_class_probability():
    rows = np.zeros((1, 30, 7), np.float32)
    rows[0, 0] = [50, 60, 10, 4, 0.8, 0.5, 0.9]
    rows[0, 1] = [10, 10, 4, 4, 0.2, 0.9, 0.1]
    xyxy, s, cls = decode_yolo(rows, layout="yolov5", score_threshold=0.3)
    assert len(s) == 1 and s[0] == pytest.approx(0.72) and cls[0] == 1
    np.testing.assert_allclose(xyxy[0], [45, 58, 55, 62])


def test_decode_end2end_and_bad_tensors():
    e2e = np.array([[[1, 2, 11, 8, 0.9, 8], [0, 0, 5, 5, 0.1, 8]]], np.float32)
    xyxy, s, cls = decode_yolo(e2e, layout="end2end")
    assert len(s) == 1 and cls[0] == 8
    np.testing.assert_allclose(xyxy[0], [1, 2, 11, 8])
    with pytest.raises(ValueError, match="output"):
        decode_yolo(np.zeros((2, 3, 4, 5)))
    with pytest.raises(ValueError, match="layout"):
        decode_yolo(np.zeros((6, 10)), layout="ssd")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="output"):
        decode_yolo(np.zeros((10, 5)), layout="end2end")


def test_onnx_detector_needs_an_existing_model_and_says_how_to_get_onnxruntime(
    tmp_path, monkeypatch
):
    with pytest.raises(FileNotFoundError, match="model_path"):
        OnnxDetector(tmp_path / "missing.onnx")
    model = tmp_path / "m.onnx"
    model.write_bytes(b"not really a model")
    with pytest.raises(ValueError, match=r"input_size: expected \(width, height\)"):
        OnnxDetector(model, input_size="640")
    with pytest.raises(ValueError, match="input_size: expected both sides >= 8 px"):
        OnnxDetector(model, input_size=(640, 4))
    monkeypatch.setitem(sys.modules, "onnxruntime", None)  # as if not installed
    with pytest.raises(ImportError, match="pip install onnxruntime"):
        OnnxDetector(model)


def test_masked_detector_keeps_the_boxes_whose_water_line_is_in_the_region(tmp_path):
    """The six hulls of :func:`hull_scene`, a region of the right half only: the hulls
    right of column 320 are kept, as the unmasked detector boxes them, by a direct call
    and through prepare/detect_prepared (the tracker's two threads) alike."""
    img, _, hz = hull_scene(1234, 0.8)
    inner = ClassicalShipDetector()
    region = np.zeros(img.shape[:2], np.uint8)
    region[:, 320:] = 255
    masked = MaskedDetector(inner, region)
    full = inner(img, horizon=hz)
    right = full.boxes[np.round(full.u_wl) >= 320]  # the pixel of the water-line point
    assert 0 < len(right) < len(full)
    np.testing.assert_array_equal(masked(img, horizon=hz).boxes, right)
    prepared = masked.prepare(img, horizon=hz)
    np.testing.assert_array_equal(masked.detect_prepared(prepared).boxes, right)
    cv2.imwrite(str(tmp_path / "region.png"), region[::2, ::2])  # half size: scaled
    np.testing.assert_array_equal(MaskedDetector(inner, tmp_path / "region.png")(
        img, horizon=hz).boxes, right)  # fmt: skip
    with pytest.raises(ValueError, match="--mask: the region is empty"):
        MaskedDetector(inner, np.zeros((10, 10)))
    with pytest.raises(ValueError, match=r"--mask: expected an \(H, W\) image"):
        MaskedDetector(inner, np.ones((4, 4, 3)))
    (tmp_path / "junk.png").write_bytes(b"not a png")
    with pytest.raises(ValueError, match="not a readable image"):
        MaskedDetector(inner, tmp_path / "junk.png")
    with pytest.raises(ValueError, match="--mask: 640x180, the frames are 640x360"):
        MaskedDetector(inner, region[::2])(img, horizon=hz)


def test_make_detector_builds_the_options_detector_or_names_the_bad_option(tmp_path, monkeypatch):
    det = make_detector(threshold=8.0, polarity="dark", temporal=True)
    assert isinstance(det, ClassicalShipDetector)
    assert (det.threshold, det.grow_threshold, det.polarity, det.temporal) == (8, 3, "dark", True)
    assert make_detector(threshold=2.0).grow_threshold == 2.0  # hysteresis low <= high
    with pytest.raises(ValueError, match="--polarity"):
        make_detector(polarity="grey")
    with pytest.raises(ValueError, match="--threshold"):
        make_detector(threshold=0.0)
    with pytest.raises(ValueError, match=r"--model .*missing\.onnx"):
        make_detector(tmp_path / "missing.onnx")
    model = tmp_path / "m.onnx"
    model.write_bytes(b"not really a model")
    with pytest.raises(ValueError, match="--threshold: a model score"):
        make_detector(model, threshold=6.0)
    monkeypatch.setitem(sys.modules, "onnxruntime", None)  # as if not installed
    with pytest.raises(ValueError, match=r"--model .*pip install onnxruntime"):
        make_detector(model)


def test_onnx_detector_maps_model_boxes_back_through_the_letterbox(tmp_path):
    import onnx  # in the test extras with onnxruntime: the real runtime runs a real model
    from onnx import TensorProto, helper, numpy_helper

    # a model whose output is a fixed YOLOv8 tensor (plus 0 × the mean of its input)
    boxes = [[320, 320, 64, 32]]  # one box at the centre of the 640×640 input
    const = _yolov8_output(boxes, np.array([[0.9]]), anchors=8)
    nodes = [
        helper.make_node("ReduceMean", ["images"], ["m"], keepdims=1),
        helper.make_node("Mul", ["m", "zero"], ["z"]),
        helper.make_node("Add", ["z", "const"], ["output0"]),
    ]
    graph = helper.make_graph(
        nodes,
        "fixed",
        [helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, 640, 640])],
        [helper.make_tensor_value_info("output0", TensorProto.FLOAT, list(const.shape))],
        [
            numpy_helper.from_array(np.zeros((1, 1, 1, 1), np.float32), "zero"),
            numpy_helper.from_array(const, "const"),
        ],
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    path = tmp_path / "fixed.onnx"
    onnx.save(model, str(path))
    det = OnnxDetector(path, refine_waterline=False)
    frame = np.full((360, 640, 3), 100, np.uint8)  # letterboxed: scale 1, 140 px bars
    out = det(frame)
    assert len(out) == 1 and out.score[0] == pytest.approx(0.9)
    # input box x 288…352, y 304…336 → frame y 164…196 (minus the 140 px bar)
    np.testing.assert_allclose(out.boxes[0, :4], [287.5, 163.5, 64, 32], atol=1e-4)


def test_fast_row_median_equals_numpys():
    """The per-candidate row median of the refinement equals numpy's nanmedian per masked
    row, NaN for a row with nothing in it."""
    from seawatch.vision.detect import _row_median

    rng = np.random.default_rng(3)
    for _ in range(100):
        v = rng.normal(size=(6, 9)).astype(np.float32)
        m = rng.random((6, 9)) < 0.5
        m[0] = False
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ref = np.nanmedian(np.where(m, v, np.nan), axis=1)
        np.testing.assert_allclose(_row_median(v, m), ref, rtol=0, atol=1e-6)


def test_a_ship_beside_another_is_boxed_whole_not_by_its_finest_scale_fragment():
    """The rendered meeting case (seed 1, frames 8-14, drawn without the codec): a 40-px
    ferry and a 26-px workboat 8 px apart. At the finest scale only each hull's middle
    stands out (its ends have hull in one CFAR window), at the next scale each whole
    hull; that candidate failed the clutter threshold on the other ship's pixels in its
    ring, and the box was the fragment (the ferry 25-27 px, the workboat 16-23 px, in 8
    of the 14 boxes). A candidate holding a finer one that passed is tried again with
    the passed candidates' boxes left out of its ring: 10 of the 14 boxes are within 2
    px of their ship's length."""
    from seawatch.synth.cases import ship_video_case
    from seawatch.synth.render import Renderer

    case = ship_video_case("meeting", duration=8.0, width=960, height=540, seed=1)
    r = Renderer(
        case.camera, case.ships, 25.0, lighting=case.lighting, sway=case.sway,
        coastline=case.coastline, seed=case.seed,
    )  # fmt: skip
    w, h = case.camera.image_size
    whole = 0
    for k in range(8, 15):
        buf = np.empty((h * 3 // 2, w), np.uint8)
        _, truth, hz = r.render_into(k, buf)
        det = ClassicalShipDetector()(cv2.cvtColor(buf, cv2.COLOR_YUV2BGR_I420), horizon=hz)
        for t in truth:
            near = np.abs(det.x + 0.5 * det.w - (t.x + 0.5 * t.w)) < 12.0
            whole += int(np.any(near & (np.abs(det.w - t.w) <= 2.0)))
    assert whole >= 10, whole


def _boat_beside_ship(seed: int) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """A grey 960 × 540 frame: sky over a noisy sea (σ 2 grey levels), horizon at row 200
    (edge at 199.5), a dark 56 × 13 px ship and, 18 px left of it, a dark 7 × 2 px boat
    (pixels 535–541, rows 216–217)."""
    rng = np.random.default_rng(seed)
    img = np.full((540, 960), 160.0) + rng.normal(0.0, 2.0, (540, 960))
    img[:200] = 190.0 + rng.normal(0.0, 1.0, (200, 960))
    img[210:223, 560:616] -= 80.0
    img[216:218, 535:542] -= 60.0
    return np.clip(img, 0, 255).astype(np.uint8), (0.0, 199.5, 959.0, 199.5)


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_censored_windows_find_the_boat_a_ship_beside_it_hides(seed):
    """Greatest-of CFAR masks a weak target beside a strong one: the ship lies in the
    boat's right training window and fills its noise cell (measured on the rendered
    lighting case, z 2.4 against the threshold 6). With ``censor=True`` the candidates'
    boxes are left out of the windows and cells around them and the boat is found, its
    box to the pixel (534.5–541.5 × 215.5–217.5); the ship's box is unchanged."""
    img, line = _boat_beside_ship(seed)
    plain = ClassicalShipDetector(censor=False)(img, horizon=line).boxes
    censored = ClassicalShipDetector(censor=True)(img, horizon=line).boxes
    assert plain.shape[0] == 1 and abs(plain[0, 0] - 559.5) < 1.0  # the ship alone
    assert censored.shape[0] == 2
    ship = censored[np.argmax(censored[:, 2])]
    boat = censored[np.argmin(censored[:, 2])]
    np.testing.assert_array_equal(ship, plain[0])
    np.testing.assert_allclose(boat[:4], [534.5, 215.5, 7.0, 2.0], atol=0.5)


def test_censoring_changes_nothing_where_nothing_is_hidden():
    """Rolled colour scenes with a coast and ships apart: the censored pass adds no box
    and moves none. In the roll −2° scene it finds the right end of the 90-px ship
    (458.5–464.1 px; the ship's box ends at 452.5 px, the CFAR's own shadow on a long
    hull), 6 px beside the ship's candidate: within ``guard`` columns, so not a target
    of its own."""
    rng = np.random.default_rng(99)
    for roll in (-2.0, 0.0, 2.5):
        img, _, line = sea_scene(rng, roll_deg=roll, ships=fixed_ships(), coast=True)
        plain = ClassicalShipDetector(censor=False)(as_u8(img), horizon=line).boxes
        censored = ClassicalShipDetector(censor=True)(as_u8(img), horizon=line).boxes
        assert plain.shape[0] >= 4
        np.testing.assert_array_equal(censored, plain)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    st.lists(
        st.tuples(st.integers(0, 60), st.integers(1, 20), st.integers(0, 60), st.integers(1, 20)),
        min_size=1,
        max_size=12,
    )
)
def test_union_rects_covers_every_rectangle_with_disjoint_ones(spec):
    """The censored pass's regions: every given rectangle lies inside one result, the
    results overlap nowhere, and each result is the bounding box of given ones."""
    rects = [[r, r + h, c, c + w] for r, h, c, w in spec]
    out = union_rects(rects)

    def within(a, b):
        return b[0] <= a[0] and a[1] <= b[1] and b[2] <= a[2] and a[3] <= b[3]

    for a in rects:
        assert any(within(a, b) for b in out)
    for i, a in enumerate(out):
        for b in out[i + 1 :]:
            assert not (a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3])
        inside = [r for r in rects if within(r, a)]
        assert [min(r[0] for r in inside), max(r[1] for r in inside)] == a[:2]
        assert [min(r[2] for r in inside), max(r[3] for r in inside)] == a[2:]


@pytest.mark.parametrize(
    "scale",
    [
        1.64,
        2.2,
        2.7,
        pytest.param(
            3.0,
            marks=pytest.mark.xfail(
                strict=True,
                reason="known gap: a ship longer than about 24 % of the frame's width "
                "(here 251 px at 960) is no longer boxed whole — at the coarsest scale "
                "the CFAR's guard cells reach 108 px (12 × 9) from a pixel, and the "
                "hull's middle is its own background",
            ),
        ),
    ],
)
def test_a_near_ship_filling_a_large_part_of_the_width_is_boxed_whole(tmp_path, scale):
    """A ship near the camera (or zoomed in on) fills much of the frame: the rendered
    large ship, 84 px long at 960 px, seen at ``scale`` times that (138, 184 and 226 px:
    14, 19 and 24 % of the width): one box over at least 90 % of its length, its ends
    within 3 % of the true ones. Up to session 29 nothing was boxed from 14 %: at the
    coarsest scale the ship's own contrast in the training windows of the sea beside it
    set the noise level (at 14 % σ 15.3 for its contrast of 102, z 6.6, failed by the
    clutter-map test; at 17.5 % z 5.4); now that sea is left out of the noise cells
    (``_window_hits``): σ 6.0, z 16.7."""
    from seawatch.io.video import VideoReader
    from seawatch.scenarios.ship_video import read_truth
    from seawatch.synth import render_case
    from seawatch.vision.horizon import detect_horizon

    res = render_case("large", tmp_path, duration=0.04, width=960, height=540)
    with VideoReader(res.video) as reader:
        frame = next(iter(reader)).image
    x, y, w, h = read_truth(res.truth)[0, 2:6]
    big = cv2.resize(frame, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
    left, top = int(scale * (x + w / 2)) - 480, max(0, int(scale * (y + h / 2)) - 270)
    view = np.ascontiguousarray(big[top : top + 540, left : left + 960])
    boxes = ClassicalShipDetector()(view, horizon=detect_horizon(view)).boxes
    assert boxes.shape[0] >= 1
    ship = boxes[np.argmax(boxes[:, 2])]
    x0, x1 = scale * x - left, scale * (x + w) - left  # the true ends in the view
    assert ship[2] >= 0.9 * scale * w
    assert abs(ship[0] - x0) < 0.03 * scale * w and abs(ship[0] + ship[2] - x1) < 0.03 * scale * w


@pytest.mark.parametrize(
    "cx",
    [
        400,
        480,
        500,
        520,
        540,
        580,
        pytest.param(
            300,
            marks=pytest.mark.xfail(
                strict=True,
                reason="known gap (session 33): at x = 300 the second scale's candidate "
                "holds the whole ship but its object mask takes the hull's bottom row "
                "alone (56 of 80 px: the hull narrows by 12 px at each end towards the "
                "water line), its upper corners below 0.4 × the mask's 95th percentile",
            ),
        ),
    ],
)
def test_a_dark_ship_straddling_the_horizon_is_boxed_whole_across_the_frame(cx):
    """A dark ship (−60 grey levels, hull 80 × 20 px, superstructure 30 × 24 px above
    it, its top 14 px above the horizon) on the synthetic sea at column ``cx``: one box
    over at least 90 % of its columns. At x = 480-540 the second scale loses the hull
    (80 px against its 75-px reach) and the coarsest scale's whole-ship candidate gave
    way to the finest scale's superstructure: boxed alone (30 × 13-22 px), or, at 520,
    where its object lies above the horizon, nothing boxed at all. Since session 33 a
    coarse candidate gives way only to finer ones that hold its peak, and one whose
    finer ones yield no ship is refined itself."""
    rng = np.random.default_rng(7)
    ship = {"cx": cx, "base": 150, "length": 80, "height": 20, "sup_w": 30, "sup_h": 24,
            "contrast": -60}  # fmt: skip
    img, truth, hz = sea_scene(rng, ships=[ship])
    boxes = ClassicalShipDetector()(as_u8(img), horizon=hz).boxes
    x0, x1 = truth[0, 0], truth[0, 0] + truth[0, 2]
    cover = [(min(b[0] + b[2], x1) - max(b[0], x0)) / (x1 - x0) for b in boxes]
    assert max(cover, default=0.0) >= 0.9, boxes[:, :4].round(1).tolist()


def _wasr_cover(name: str, x0: float, x1: float, **options) -> float:
    """The largest share of columns ``x0 … x1`` [px] covered by one box whose centre lies
    between them, on WaSR's image ``name`` with its detected horizon."""
    from seawatch.vision.horizon import detect_horizon

    view = cv2.imread(str(WASR / name))
    boxes = ClassicalShipDetector(**options)(view, horizon=detect_horizon(view)).boxes
    cover = [
        (min(b[0] + b[2], x1) - max(b[0], x0)) / (x1 - x0)
        for b in boxes
        if x0 < b[0] + b[2] / 2 < x1
    ]
    return max(cover, default=0.0)


@pytest.mark.skipif(
    not (WASR / "example_03.jpg").is_file(), reason=f"WaSR images not found at {WASR}"
)
@pytest.mark.parametrize(
    ("name", "x0", "x1"),
    [
        # the sailboat moored on the right: its white hull's columns (luma > 200 in at
        # least three of rows 205-239)
        ("example_03.jpg", 396.0, 476.0),
        # the buoy lying on the sea, its body: the columns more than 25 grey levels off
        # their row's sea (the median of columns 100-179) in rows 248-280 (below them
        # its orange end, lower left, reaches column 196)
        ("example_02.jpg", 210.0, 293.0),
    ],
)
def test_a_wide_target_on_a_real_image_is_boxed_whole(name, x0, x1):
    """WaSR's real boat-camera images (512 × 384): a target wider than the noise cells
    gets one box over at least 80 % of its columns — found by the wide-target pass
    (``wide=True``, step 4b); without it the yacht's hull is not boxed and the buoy is
    boxed in two pieces (20 × 29 and 31 × 13 px; session 31), its own contrast filling the
    noise cells (σ 45-68 grey levels over the hull's rows at the finest scale, the sea's
    4: z ≤ 4.2 at every scale)."""
    assert _wasr_cover(name, x0, x1) >= 0.8
    assert _wasr_cover(name, x0, x1, wide=False) < 0.5


@settings(max_examples=60, deadline=None)
@given(
    st.integers(6, 40),
    st.integers(1, 8),
    st.integers(2, 10),
    st.integers(0, 2**31 - 1),
)
def test_one_sided_hits_are_the_edge_pixels_whose_one_window_holds_a_strong_pixel(
    w, guard, flank, seed
):
    """:func:`_one_sided_hits` against its definition pixel by pixel: within guard +
    flank columns of the left edge the right window (3 rows × flank columns starting
    guard + 1 to the right), within as many of the right edge the left one, holds a
    strong pixel (rows past the top and bottom are no rows)."""
    strong = np.random.default_rng(seed).random((7, w)) < 0.08
    got = one_sided_hits(strong, guard, flank)
    edge = min(guard + flank, w)
    want = np.zeros_like(strong)
    for r in range(7):
        rows = strong[max(0, r - 1) : r + 2]
        for j in range(w):
            if j < edge and rows[:, j + guard + 1 : j + guard + 1 + flank].any():
                want[r, j] = True
            if j >= w - edge and rows[:, max(0, j - guard - flank) : max(0, j - guard)].any():
                want[r, j] = True
    np.testing.assert_array_equal(got, want)


def test_a_close_boat_on_the_rendered_uav_clip_is_boxed_whole_without_an_echo(tmp_path):
    """The rendered ``uav-sea`` clip (1920 × 1080, our renderer's default) in its last
    seconds, the work boat 105-92 m off and 172-221 px long, its superstructure rising
    above the horizon, the sea right of it within guard + flank of the frame's right edge
    at the second scale. The wide-target pass boxes the whole boat (seeded on its hull
    below the horizon, grown past it; with the search cut at the horizon it boxed the
    hull alone, 40 px low) and no box beside it: the sea there, whose one training window
    holds the dark hull, is its echo (a bright 187 × 71 px box in frames 680 and 685 in
    session 32)."""
    import av

    from seawatch.synth.platform_clip import render_platform_clip
    from seawatch.vision.horizon import detect_horizon

    clip = render_platform_clip(tmp_path, duration=68.6)
    truth = {int(r["frame"]): r for r in csv.DictReader(clip.truth.open())}
    det = ClassicalShipDetector()
    seen = []
    with av.open(str(clip.video)) as container:
        for i, frame in enumerate(container.decode(video=0)):
            if i not in (670, 678, 680, 685):
                continue
            image = frame.to_ndarray(format="bgr24")
            boxes = det(image, horizon=detect_horizon(image)).boxes
            x, y, w, h = (float(truth[i][k]) for k in "xywh")
            ours = [b for b in boxes if b[0] < x + w and b[0] + b[2] > x]  # columns shared
            assert len(ours) == 1, f"frame {i}: {boxes[:, :4].round(1).tolist()}"
            edges = np.r_[ours[0][:2], ours[0][:2] + ours[0][2:4]]
            np.testing.assert_allclose(edges, [x, y, x + w, y + h], atol=3.0)
            assert not any(b[0] >= x + w - 10 and b[1] < y + h for b in boxes), f"frame {i}"
            seen.append(i)
    assert seen == [670, 678, 680, 685]


def test_a_ship_is_not_boxed_across_the_gap_to_the_next():
    """Two ships side by side in one object mask, 10 px of sea between them, their water
    lines 4 px apart, the right one's first two columns ending on the left one's level (a
    bow rising): each ship gets its own columns (``_frame_ships``). Until session 30 the
    left one took the right one's bow across the gap (the rendered meeting case, seed 1,
    frame 0: the ferry's box 52.8 px for its 39.5)."""
    from seawatch.vision.waterline import _frame_ships

    rng = np.random.default_rng(0)
    img = np.full((120, 200), 160.0) + rng.normal(0.0, 1.0, (120, 200))
    img[:40] = 200.0
    img[50:60, 40:80] = 60.0  # the far ship: columns 40-79, water line at row 59.5
    img[50:64, 90:116] = 100.0  # the near one: columns 90-115, water line at 63.5
    img[60:64, 90:92] = 160.0  # ... its bow's two columns end at the far one's level
    img = np.clip(img, 0, 255).astype(np.uint8)
    fr = ClassicalShipDetector().prepare(img).frame
    x0, y0 = 36, 44
    ships = _frame_ships(fr, img[y0:70, x0:120] < 130, x0, y0)
    spans = sorted((x0 + c0, x0 + c1, v) for c0, c1, _, _, _, v, _ in ships)
    assert [s[:2] for s in spans] == [(40, 79), (90, 115)]
    assert [s[2] for s in spans] == pytest.approx([59.5, 63.5], abs=0.1)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    st.integers(0, 2**31 - 1),
    st.integers(1, 6),
    st.integers(1, 8),
    st.floats(0.0, 0.05),
)
def test_window_hits_are_the_pixels_whose_training_windows_hold_a_strong_pixel(
    seed, guard, flank, density
):
    """``_window_hits`` against a direct reading of the CFAR's windows
    (``_contrast_kernel``: 3 rows × ``flank`` columns, ending ``guard`` columns left of
    the pixel / starting ``guard`` columns right of it): a pixel is hit when it, or a
    window's part inside the image, holds a strong pixel."""
    from seawatch.vision.detect import _window_hits

    rng = np.random.default_rng(seed)
    strong = rng.random((9, 40)) < density
    hit = _window_hits(strong, guard, flank)
    h, w = strong.shape
    for r in range(h):
        rows = strong[max(0, r - 1) : r + 2]
        for j in range(w):
            left = rows[:, max(0, j - guard - flank) : max(0, j - guard)]
            right = rows[:, min(w, j + guard + 1) : min(w, j + guard + flank + 1)]
            assert hit[r, j] == bool(left.any() or right.any() or rows[:, j].any())


def test_censored_cell_noise_leaves_out_a_long_ship_s_shadow():
    """``_cell_grid`` with ``censor``: Gaussian noise (σ = 1) whose middle columns hold a
    ship's contrast (+40): uncensored, the 30 % quantile of its two middle cells (of four
    in a row) is the contrast's (and of the outer two, half covered, inflated too);
    censored, the other values give σ within 20 % (the estimate's standard error is 5-7
    %) — of the cell where a quarter of it is left, else of its row of cells."""
    from seawatch.vision.detect import _cell_grid

    rng = np.random.default_rng(7)
    d = rng.normal(0.0, 1.0, (32, 256)).astype(np.float32)
    shadow = np.zeros(d.shape, bool)
    shadow[:, 32:224] = True  # the middle cells (64 columns) and half of the outer two
    d[shadow] += 40.0
    plain, ch, cw = _cell_grid(d, 8, 64, 1, 0.3)
    censored, _, _ = _cell_grid(d, 8, 64, 1, 0.3, censor=shadow)
    assert (ch, cw) == (8, 64)
    assert plain[:, 1:3].min() > 30.0 and plain[:, [0, 3]].min() > 1.5
    assert np.allclose(censored, 1.0, rtol=0.2)
    assert np.array_equal(_cell_grid(d, 8, 64, 1, 0.3, censor=np.zeros_like(shadow))[0], plain)
