"""Tests of camera files: OpenCV FileStorage and the seawatch format (seawatch.io.camera_file)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml

from seawatch.camera import PinholeCamera
from seawatch.io import FORMAT_TAG, load_camera, save_camera

OPENCV_DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv"

FULL = PinholeCamera(
    fx=1371.25,
    fy=1370.5,
    cx=958.25,
    cy=541.75,
    image_size=(1920, 1080),
    dist=(-0.12, 0.034, 0.0011, -0.0007, 0.002),
    heading=math.radians(123.4),
    pitch=math.radians(-2.5),
    roll=math.radians(0.75),
    height=12.5,
    lat=50.7912345,
    lon=-1.1054321,
    position=(10.5, -3.25),
)
PLAIN = PinholeCamera.from_fov(640, 480, 60.0)

SEAWATCH_OK = {
    "format": FORMAT_TAG,
    "image_size": [640, 480],
    "intrinsics": {"fx": 500.0, "fy": 501.0, "cx": 320.0, "cy": 240.0},
}


def _assert_same_camera(a: PinholeCamera, b: PinholeCamera) -> None:
    for name in ("fx", "fy", "cx", "cy", "height", "lat", "lon"):
        va, vb = getattr(a, name), getattr(b, name)
        assert (va is None and vb is None) or va == pytest.approx(vb, rel=1e-15), name
    for name in ("heading", "pitch", "roll"):  # degrees at the edge: within an ulp or two
        assert getattr(a, name) == pytest.approx(getattr(b, name), abs=1e-15), name
    assert a.image_size == b.image_size
    np.testing.assert_allclose(a.dist, b.dist, rtol=1e-15)
    np.testing.assert_allclose(a.position, b.position, rtol=1e-15)


def _write_yaml(path: Path, data: dict) -> Path:
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


# ---------------------------------------------------------------- real OpenCV data
def test_reads_opencv_sample_left_intrinsics_yml():
    path = OPENCV_DATA / "left_intrinsics.yml"
    if not path.exists():
        pytest.skip(f"OpenCV sample data not found at {path}")
    cam = load_camera(path)
    # ../shared/data/README.md: f ≈ 536 px, principal point ≈ (342.3, 235.6), 640x480
    assert cam.fx == pytest.approx(536.0, abs=0.5) and cam.fy == cam.fx
    assert (cam.cx, cam.cy) == (pytest.approx(342.3, abs=0.05), pytest.approx(235.6, abs=0.05))
    assert cam.image_size == (640, 480)
    # the file's own distortion_coefficients (k1, k2, p1, p2, k3) as printed in it
    assert cam.dist[0] == pytest.approx(-2.6637260909660682e-01, rel=1e-15)
    assert cam.dist[4] == pytest.approx(2.3839153080878486e-01, rel=1e-15)
    assert len(cam.dist) == 5 and cam.height is None and cam.pitch == 0.0


# ---------------------------------------------------------------- round trips
@pytest.mark.parametrize("name", ["cam.yaml", "cam.yml", "cam.json"])
@pytest.mark.parametrize("camera", [FULL, PLAIN], ids=["full", "plain"])
def test_seawatch_format_round_trip(tmp_path, name, camera):
    path = save_camera(camera, tmp_path / name, description="test camera")
    _assert_same_camera(load_camera(path), camera)


@pytest.mark.parametrize("name", ["cam.yml", "cam.yaml", "cam.xml", "cam.json"])
@pytest.mark.parametrize("camera", [FULL, PLAIN], ids=["full", "plain"])
def test_opencv_format_round_trip(tmp_path, name, camera):
    path = save_camera(camera, tmp_path / name, format="opencv")
    _assert_same_camera(load_camera(path), camera)


def test_saved_seawatch_file_is_documented_yaml_in_degrees_and_metres(tmp_path):
    path = save_camera(FULL, tmp_path / "cam.yaml")
    data = yaml.safe_load(path.read_text())
    assert data["format"] == "seawatch-camera/1"
    assert data["image_size"] == [1920, 1080]
    assert data["intrinsics"] == {"fx": 1371.25, "fy": 1370.5, "cx": 958.25, "cy": 541.75}
    assert data["mounting"]["pitch_deg"] == pytest.approx(-2.5, rel=1e-14)
    assert data["mounting"]["heading_deg"] == pytest.approx(123.4, rel=1e-14)
    assert data["mounting"]["height_m"] == 12.5
    assert data["position"] == {
        "lat_deg": 50.7912345,
        "lon_deg": -1.1054321,
        "north_m": 10.5,
        "east_m": -3.25,
    }
    as_json = json.loads(save_camera(FULL, tmp_path / "cam.json").read_text())
    assert as_json == data


def test_saved_opencv_file_is_read_by_cv2_filestorage(tmp_path):
    path = save_camera(FULL, tmp_path / "cam.yml", format="opencv")
    assert path.read_text().startswith("%YAML")  # 4.x: "%YAML:1.0", 5.x: "%YAML 1.2"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    try:
        np.testing.assert_array_equal(
            fs.getNode("camera_matrix").mat(),
            [[1371.25, 0.0, 958.25], [0.0, 1370.5, 541.75], [0.0, 0.0, 1.0]],
        )
        np.testing.assert_array_equal(
            fs.getNode("distortion_coefficients").mat().ravel(), FULL.dist
        )
        assert fs.getNode("image_width").real() == 1920
        assert fs.getNode("image_height").real() == 1080
        assert fs.getNode("mount_pitch_deg").real() == pytest.approx(-2.5, rel=1e-14)
    finally:
        fs.release()


def test_opencv_file_with_image_size_key_and_no_distortion_is_read(tmp_path):
    path = tmp_path / "k.yml"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("K", np.array([[400.0, 0, 300], [0, 410.0, 200], [0, 0, 1]]))
    fs.write("image_size", np.array([[600.0, 400.0]]))
    fs.release()
    cam = load_camera(path)
    assert (cam.fx, cam.fy, cam.cx, cam.cy, cam.image_size) == (400, 410, 300, 200, (600, 400))
    assert not cam.has_distortion


# ---------------------------------------------------------------- bad files
@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"colour": "red"}, "colour"),
        (
            {"intrinsics": {"fx": 1.0, "fy": 1.0, "cx": 1.0, "cy": 1.0, "skew": 0.0}},
            "intrinsics.skew",
        ),
        ({"mounting": {"pitch": -2.0}}, "mounting.pitch"),
        ({"position": {"latitude": 50.0}}, "position.latitude"),
    ],
)
def test_unknown_keys_raise_value_error_naming_file_and_key(tmp_path, change, key):
    path = _write_yaml(tmp_path / "bad.yaml", {**SEAWATCH_OK, **change})
    with pytest.raises(ValueError, match=rf"bad\.yaml.*unknown key '{key}'"):
        load_camera(path)


@pytest.mark.parametrize("missing", ["format", "image_size", "intrinsics", "intrinsics.cy"])
def test_missing_keys_raise_value_error_naming_file_and_key(tmp_path, missing):
    data = json.loads(json.dumps(SEAWATCH_OK))
    if "." in missing:
        del data["intrinsics"]["cy"]
    else:
        del data[missing]
    path = _write_yaml(tmp_path / "gap.yaml", data)
    with pytest.raises(ValueError, match=rf"gap\.yaml.*missing key '{missing}'"):
        load_camera(path)


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"format": "seawatch-camera/2"}, "format"),
        ({"image_size": [640]}, "image_size"),
        ({"image_size": [640.0, 480.0]}, "image_size"),
        ({"intrinsics": {"fx": "500", "fy": 1.0, "cx": 1.0, "cy": 1.0}}, "intrinsics.fx"),
        ({"intrinsics": {"fx": -500.0, "fy": 1.0, "cx": 1.0, "cy": 1.0}}, "fx"),
        ({"distortion": [0.1, 0.2, 0.3]}, "dist"),
        ({"distortion": "none"}, "distortion"),
        ({"mounting": {"height_m": True}}, "mounting.height_m"),
        ({"mounting": [1, 2]}, "mounting"),
        ({"position": {"lat_deg": 50.0}}, "lat"),
    ],
)
def test_invalid_values_raise_value_error_naming_file_and_key(tmp_path, change, key):
    path = _write_yaml(tmp_path / "val.yaml", {**SEAWATCH_OK, **change})
    with pytest.raises(ValueError, match=rf"val\.yaml.*{key}"):
        load_camera(path)


def test_opencv_unknown_key_is_an_error_unless_not_strict(tmp_path):
    path = save_camera(PLAIN, tmp_path / "cam.xml", format="opencv")
    text = path.read_text().replace(
        "</opencv_storage>", "<lens_serial>42</lens_serial>\n</opencv_storage>"
    )
    path.write_text(text)
    with pytest.raises(ValueError, match=r"cam\.xml.*unknown key 'lens_serial'"):
        load_camera(path)
    _assert_same_camera(load_camera(path, strict=False), PLAIN)


@pytest.mark.parametrize("drop", ["camera_matrix", "image_width"])
def test_opencv_missing_keys_raise_value_error_naming_them(tmp_path, drop):
    path = tmp_path / "cv.yml"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    if drop != "camera_matrix":
        fs.write("camera_matrix", np.array(PLAIN.K))
    if drop != "image_width":
        fs.write("image_width", 640)
    fs.write("image_height", 480)
    fs.release()
    with pytest.raises(ValueError, match=rf"cv\.yml.*missing key '{drop}'"):
        load_camera(path)


def test_unreadable_files_and_bad_save_arguments_raise_value_error(tmp_path):
    broken = tmp_path / "broken.yaml"
    broken.write_text("format: [unclosed\n")
    with pytest.raises(ValueError, match=r"broken\.yaml"):
        load_camera(broken)
    listing = _write_yaml(tmp_path / "list.yaml", [1, 2, 3])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"list\.yaml.*mapping"):
        load_camera(listing)
    with pytest.raises(ValueError, match="format"):
        save_camera(PLAIN, tmp_path / "c.yaml", format="matlab")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="suffix"):
        save_camera(PLAIN, tmp_path / "c.txt", format="opencv")
    with pytest.raises(ValueError, match="camera"):
        save_camera("not a camera", tmp_path / "c.yaml")  # type: ignore[arg-type]
    with pytest.raises(FileNotFoundError):
        load_camera(tmp_path / "absent.yaml")


def test_seawatch_yaml_with_a_yaml_directive_is_not_mistaken_for_opencv(tmp_path):
    path = tmp_path / "directive.yaml"
    path.write_text("%YAML 1.1\n---\n" + yaml.safe_dump(SEAWATCH_OK), encoding="utf-8")
    cam = load_camera(path)
    assert (cam.fx, cam.fy, cam.cx, cam.cy, cam.image_size) == (500, 501, 320, 240, (640, 480))
