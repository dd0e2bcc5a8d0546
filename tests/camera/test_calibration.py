"""Chessboard calibration on OpenCV's sample stereo pairs (../shared/data/opencv/).

Data: OpenCV ``samples/data`` left/right01–14 (no 10), 9×6 inner corners, 25 mm squares,
640×480 (Debian opencv-doc 4.6.0; Apache-2.0 / BSD-3, see DEBIAN_COPYRIGHT_opencv).
Independent facts (../shared/data/README.md): left RMS ≈ 0.41 px, f ≈ 536 px, principal
point ≈ (342.3, 235.6), baseline ≈ 83.6 mm, triangulated corner spacing 24.95 ± 0.53 mm.
All 13 pairs are calibrated once per module.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from seawatch.camera.calibration import (
    CameraCalibration,
    StereoCalibration,
    board_points,
    calibrate_camera,
    calibrate_stereo,
    find_corners,
)
from seawatch.camera.stereo import triangulate

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv"
pytestmark = pytest.mark.skipif(
    not (DATA / "left01.jpg").is_file(),
    reason=f"OpenCV chessboard images not found at {DATA} (shared data folder absent)",
)


def _pairs() -> tuple[list[Path], list[Path]]:
    left = sorted(DATA.glob("left[0-9][0-9].jpg"))
    right = [DATA / p.name.replace("left", "right") for p in left]
    return left, right


@pytest.fixture(scope="module")
def stereo() -> StereoCalibration:
    left, right = _pairs()
    assert len(left) == 13
    # plus three bad entries: a text file, a missing file and an image without the board
    bad_l = [DATA / "DEBIAN_COPYRIGHT_opencv", DATA / "missing.jpg", np.zeros((480, 640), np.uint8)]
    bad_r = [DATA / "right01.jpg", DATA / "right02.jpg", DATA / "right03.jpg"]
    return calibrate_stereo(left + bad_l, right + bad_r, pattern=(9, 6), square=0.025)


def test_left_camera_reproduces_the_known_intrinsics(stereo: StereoCalibration) -> None:
    cal = stereo.left
    assert len(cal.images_used) == 13
    assert cal.fx == pytest.approx(536.0, abs=2.0) and cal.fy == pytest.approx(536.0, abs=2.0)
    assert cal.cx == pytest.approx(342.3, abs=1.0) and cal.cy == pytest.approx(235.6, abs=1.0)
    assert cal.rms_px < 0.5
    assert cal.rms_px == pytest.approx(0.41, abs=0.02)
    assert cal.image_size == (640, 480)


def test_rms_is_consistent_with_the_per_image_errors(stereo: StereoCalibration) -> None:
    for cal in (stereo.left, stereo.right):
        # every image has the same 54 corners: total RMS^2 = mean of per-image RMS^2
        assert np.sqrt(np.mean(cal.per_image_rms_px**2)) == pytest.approx(cal.rms_px, rel=1e-5)
        assert cal.per_image_rms_px.shape == (len(cal.images_used),)


def test_rejected_images_are_listed_with_reasons_not_fatal(stereo: StereoCalibration) -> None:
    reasons = dict(stereo.left.images_rejected)
    assert "unreadable" in reasons[str(DATA / "DEBIAN_COPYRIGHT_opencv")]
    assert "not found" in reasons[str(DATA / "missing.jpg")]
    assert "chessboard 9x6 not found" in reasons["<image 15>"]
    assert len(stereo.pairs_used) == 13 and len(stereo.pairs_rejected) == 3
    # the right images of the bad pairs were usable for the right camera alone
    assert len(stereo.right.images_used) == 16


def test_stereo_baseline_is_83_6_mm(stereo: StereoCalibration) -> None:
    assert stereo.baseline_m * 1000 == pytest.approx(83.6, abs=0.5)
    assert stereo.T[0] < 0  # right camera to the right of the left one: X_R = R X_L + T
    np.testing.assert_allclose(stereo.R @ stereo.R.T, np.eye(3), atol=1e-9)
    assert stereo.stereo_rms_px < 1.0
    assert stereo.per_pair_rms_px.shape == (13, 2)


def test_triangulated_chessboard_squares_are_25_mm(stereo: StereoCalibration) -> None:
    rig = stereo.rig()
    P = rig.projection_matrices()
    spacing = []
    for left, right in zip(stereo.image_points_left, stereo.image_points_right, strict=True):
        ul, ur = rig.undistort(left, right)
        grid = triangulate(P, [ul, ur]).reshape(6, 9, 3)
        spacing.append(np.linalg.norm(np.diff(grid, axis=1), axis=2).ravel())
        spacing.append(np.linalg.norm(np.diff(grid, axis=0), axis=2).ravel())
    mm = np.concatenate(spacing) * 1000.0
    assert mm.mean() == pytest.approx(25.0, abs=1.0)
    assert mm.std() < 1.0


def test_calibration_json_has_the_interface_keys(stereo: StereoCalibration) -> None:
    doc = json.loads(stereo.to_json())
    for key in (
        "rms_px",
        "fx",
        "fy",
        "cx",
        "cy",
        "dist",
        "image_size",
        "images_used",
        "images_rejected",
        "baseline_m",
        "R",
        "T",
        "stereo_rms_px",
    ):
        assert key in doc
    assert len(doc["dist"]) == 5 and doc["image_size"] == [640, 480]
    assert np.array(doc["R"]).shape == (3, 3) and len(doc["T"]) == 3
    assert doc["images_rejected"][0]["reason"]
    single = json.loads(stereo.left.to_json())
    assert "baseline_m" not in single and single["fx"] == stereo.left.fx


def test_single_camera_calibration_on_a_subset_and_camera_export() -> None:
    left, _ = _pairs()
    cal = calibrate_camera(left[:6], pattern=(9, 6), square=0.025)
    assert isinstance(cal, CameraCalibration) and len(cal.images_used) == 6
    assert cal.fx == pytest.approx(536.0, abs=10.0)
    cam = cal.to_camera()
    np.testing.assert_allclose(cam.K, cal.K)


def test_board_points_follow_opencv_detection_order() -> None:
    pts = board_points((9, 6), 0.025)
    assert pts.shape == (54, 3)
    np.testing.assert_allclose(pts[1], [0.025, 0, 0])
    np.testing.assert_allclose(pts[9], [0, 0.025, 0])
    corners = find_corners(DATA / "left01.jpg", (9, 6))
    assert corners is not None and corners.shape == (54, 2)
    assert find_corners(np.zeros((100, 100), np.uint8)) is None


def test_too_few_images_and_bad_arguments_raise_value_errors() -> None:
    left, right = _pairs()
    with pytest.raises(ValueError, match="images: the chessboard was found in 1 of 2"):
        calibrate_camera([left[0], np.zeros((480, 640), np.uint8)])
    with pytest.raises(ValueError, match="right_images"):
        calibrate_stereo(left[:3], right[:2])
    with pytest.raises(ValueError, match="pattern"):
        calibrate_camera(left[:3], pattern=(9,))
    with pytest.raises(ValueError, match="square"):
        calibrate_camera(left[:3], square=-1.0)
    with pytest.raises(ValueError, match="images"):
        calibrate_camera([])
