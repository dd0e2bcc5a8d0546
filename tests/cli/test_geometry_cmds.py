"""``seawatch locate``, ``stereo`` and ``calibrate`` (seawatch.cli.geometry_cmds) through a
tiny Typer app: known truths in, CSV/JSON out, and the exit-code contract (INTERFACES.md)."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from seawatch.camera.pinhole import PinholeCamera
from seawatch.cli.geometry_cmds import calibrate, locate, stereo
from seawatch.geometry.geodesy import north_east_to_geodetic
from seawatch.io.camera_file import load_camera, save_camera
from seawatch.models.angles import SeaSurfaceAngles

app = typer.Typer()
app.command()(locate)
app.command()(stereo)
app.command()(calibrate)
runner = CliRunner()

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv"
needs_chessboards = pytest.mark.skipif(
    not (DATA / "left01.jpg").is_file(),
    reason=f"OpenCV chessboard images not found at {DATA} (shared data folder absent)",
)


def _msg(result: object) -> str:
    """The command's output with rich's line wrapping undone."""
    return " ".join(result.output.split())  # type: ignore[attr-defined]


def _rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def _write(path: Path, header: list[str], rows: list[list[object]]) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    return path


# ----------------------------------------------------------------------------- help
@pytest.mark.parametrize("command", ["locate", "stereo", "calibrate"])
def test_help_shows_an_example_and_the_columns(command: str) -> None:
    result = runner.invoke(app, [command, "--help"])
    assert result.exit_code == 0
    assert "Example" in result.stdout and f"seawatch {command}" in result.stdout
    assert "--json" in result.stdout


# ----------------------------------------------------------------------------- locate
def _sightings(tmp_path: Path, h: float, heading_deg: float, targets: np.ndarray) -> Path:
    model = SeaSurfaceAngles(height=h, heading=math.radians(heading_deg), curved=True)
    z = model(targets)
    rows = [[i, f"{math.degrees(a):.12f}", f"{math.degrees(b):.12f}"] for i, (a, b) in enumerate(z)]
    return _write(tmp_path / "angles.csv", ["id", "azimuth_deg", "depression_deg"], rows)


def test_locate_recovers_known_targets_with_sigmas_and_lat_lon(tmp_path: Path) -> None:
    targets = np.array([[1500.0, 300.0], [800.0, -900.0], [4000.0, 2500.0]])
    path = _sightings(tmp_path, 12.0, 30.0, targets)
    result = runner.invoke(
        app,
        [
            "locate",
            str(path),
            "--height",
            "12",
            "--heading",
            "30",
            "--lat",
            "50.8",
            "--lon",
            "-1.3",
        ],
    )
    assert result.exit_code == 0, result.output
    rows = _rows(result.stdout)
    assert [r["id"] for r in rows] == ["0", "1", "2"]
    got = np.array([[float(r["north_m"]), float(r["east_m"])] for r in rows])
    np.testing.assert_allclose(got, targets, atol=1e-3)
    np.testing.assert_allclose([float(r["range_m"]) for r in rows], np.hypot(*targets.T), rtol=1e-7)
    lat, lon = north_east_to_geodetic(targets, 50.8, -1.3)
    for r, la, lo in zip(rows, lat, lon, strict=True):
        assert float(r["lat"]) == pytest.approx(la, abs=2e-7)  # < 2 cm: geodesic vs plane
        assert float(r["lon"]) == pytest.approx(lo, abs=3e-7)
        assert r["flag"] == "ok" and float(r["sigma_range_m"]) > 0
    # farther targets have larger range errors (σ ∝ D²)
    sig = [float(r["sigma_range_m"]) for r in rows]
    assert sig[2] > sig[0] > 0


def test_locate_json_is_one_document_and_flags_bad_rows(tmp_path: Path) -> None:
    path = _write(
        tmp_path / "a.csv",
        ["time", "azimuth_deg", "depression_deg"],
        [[0, 10, 0.5], [1, 10, -0.2], [2, "", 0.5], [3, 5, 0.0]],
    )
    out = tmp_path / "out.csv"
    result = runner.invoke(
        app, ["locate", str(path), "--height", "10", "--flat", "--json", "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["model"] == "flat" and doc["rows"] == 4 and doc["output"] == str(out)
    assert doc["counts"] == {"ok": 1, "above_horizon": 2, "invalid": 1}
    rec = doc["records"]
    assert rec[0]["range_m"] == pytest.approx(10 / math.tan(math.radians(0.5)), rel=1e-12)
    assert rec[1]["flag"] == "above_horizon" and rec[1]["range_m"] is None
    assert rec[2]["flag"] == "invalid" and rec[2]["north_m"] is None
    rows = _rows(out.read_text())
    assert rows[1]["range_m"] == "inf" and rows[1]["north_m"] == ""


def test_locate_interpolates_the_platform_track(tmp_path: Path) -> None:
    # the platform moves north at 5 m/s with heading 90°; targets fixed in the world
    h = 8.0
    target = np.array([600.0, 700.0])
    times = [0.0, 5.0, 10.0]
    rows = []
    for t in times:
        obs = np.array([5.0 * t, 0.0])
        a, b = SeaSurfaceAngles(height=h, observer=obs, heading=math.pi / 2, curved=True)(target)
        rows.append([t, math.degrees(a), math.degrees(b)])
    angles = _write(tmp_path / "a.csv", ["time", "azimuth_deg", "depression_deg"], rows)
    nav = _write(
        tmp_path / "nav.csv",
        ["time", "north_m", "east_m", "heading_deg", "height_m"],
        [[0, 0, 0, 90, h], [10, 50, 0, 90, h]],
    )
    result = runner.invoke(
        app, ["locate", str(angles), "--height", "99", "--platform", str(nav), "--json"]
    )
    assert result.exit_code == 0, result.output
    for rec in json.loads(result.stdout)["records"]:
        assert [rec["north_m"], rec["east_m"]] == pytest.approx(target.tolist(), abs=1e-3)


def test_locate_malformed_line_is_bad_input_naming_the_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("azimuth_deg,depression_deg\n10,0.5\n12,abc\n")
    result = runner.invoke(app, ["locate", str(path), "--height", "10"])
    assert result.exit_code == 2
    assert "line 3" in _msg(result) and "depression_deg" in _msg(result)
    path.write_text("azimuth_deg,depression_deg\n10,0.5\n12,0.5,7\n")
    result = runner.invoke(app, ["locate", str(path), "--height", "10"])
    assert result.exit_code == 2 and "line 3" in _msg(result) and "fields" in _msg(result)


def test_locate_bad_inputs_exit_2(tmp_path: Path) -> None:
    path = _write(tmp_path / "a.csv", ["azimuth_deg", "elev"], [[1, 2]])
    result = runner.invoke(app, ["locate", str(path), "--height", "10"])
    assert result.exit_code == 2 and "depression_deg" in _msg(result)
    result = runner.invoke(app, ["locate", str(tmp_path / "none.csv"), "--height", "10"])
    assert result.exit_code == 2 and "not found" in _msg(result)
    good = _write(tmp_path / "g.csv", ["azimuth_deg", "depression_deg"], [[1, 2]])
    assert runner.invoke(app, ["locate", str(good), "--height", "-3"]).exit_code == 2
    assert runner.invoke(app, ["locate", str(good), "--height", "3", "--lat", "50"]).exit_code == 2


# ----------------------------------------------------------------------------- stereo
def _stereo_rig(tmp_path: Path) -> tuple[Path, Path, PinholeCamera, PinholeCamera]:
    left = PinholeCamera(
        fx=900.0,
        fy=900.0,
        cx=320.0,
        cy=240.0,
        image_size=(640, 480),
        dist=(-0.1, 0.02, 0.0, 0.0, 0.0),
        heading=math.radians(30.0),
        height=10.0,
        lat=50.8,
        lon=-1.3,
    )
    right = PinholeCamera(
        fx=910.0,
        fy=910.0,
        cx=322.0,
        cy=238.0,
        image_size=(640, 480),
        dist=(-0.12, 0.03, 0.0, 0.0, 0.0),
        heading=math.radians(29.0),
        height=10.0,
        position=(0.5 * math.cos(math.radians(120)), 0.5 * math.sin(math.radians(120))),
    )
    lp, rp = tmp_path / "left.yaml", tmp_path / "right.yaml"
    save_camera(left, lp)
    save_camera(right, rp)
    return lp, rp, left, right


def _pixel(cam: PinholeCamera, X: np.ndarray) -> np.ndarray:
    C = np.array([cam.position[0], cam.position[1], -cam.height])
    ray = (X - C) @ np.asarray(cam.R_nc)  # world -> camera frame
    ideal = ray[:, :2] / ray[:, 2:] * [cam.fx, cam.fy] + [cam.cx, cam.cy]
    return cam.distort(ideal)


def test_stereo_triangulates_known_points_in_the_world_frame(tmp_path: Path) -> None:
    lp, rp, left, right = _stereo_rig(tmp_path)
    X = np.array([[30.0, 20.0, 9.0], [60.0, 30.0, 10.0], [20.0, 5.0, 8.0]])  # NED, near sea level
    ul, ur = _pixel(left, X), _pixel(right, X)
    rows = [[i, *ul[i], *ur[i]] for i in range(3)] + [[3, "", 1, 2, 3]]
    pairs = _write(tmp_path / "pairs.csv", ["id", "u_left", "v_left", "u_right", "v_right"], rows)
    result = runner.invoke(
        app, ["stereo", str(pairs), "--camera-left", str(lp), "--camera-right", str(rp), "--json"]
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["baseline_m"] == pytest.approx(0.5, rel=1e-9)
    rec = doc["records"]
    got = np.array([[r["north_m"], r["east_m"], r["down_m"]] for r in rec[:3]])
    np.testing.assert_allclose(got, X, atol=1e-6)
    for r, x in zip(rec[:3], X, strict=True):
        assert r["flag"] == "ok"
        assert r["range_m"] == pytest.approx(np.linalg.norm(x - [0, 0, -10.0]), rel=1e-9)
        assert r["sigma_range_m"] > r["sigma_east_m"] * 0  # present and positive
        lat, lon = north_east_to_geodetic(x[:2], 50.8, -1.3, up=-x[2])
        assert r["lat"] == pytest.approx(lat, abs=1e-9) and r["lon"] == pytest.approx(lon, abs=1e-9)
    assert rec[3]["flag"] == "invalid" and rec[3]["north_m"] is None
    # farther point: larger range error
    assert rec[1]["sigma_range_m"] > rec[0]["sigma_range_m"]


def test_stereo_extrinsics_file_overrides_the_right_pose(tmp_path: Path) -> None:
    import cv2

    lp, _, left, right = _stereo_rig(tmp_path)
    X = np.array([[25.0, 18.0, 9.5]])
    ul, ur = _pixel(left, X), _pixel(right, X)
    pairs = _write(
        tmp_path / "p.csv", ["u_left", "v_left", "u_right", "v_right"], [[*ul[0], *ur[0]]]
    )
    # the true relative pose, X_R = R X_L + T, from the two world poses
    R_l, R_r = np.asarray(left.R_nc).T, np.asarray(right.R_nc).T
    C_l = np.array([0, 0, -10.0])
    C_r = np.array([*right.position, -10.0])
    R = R_r @ R_l.T
    T = R_r @ (C_l - C_r)
    ext = tmp_path / "ext.yml"
    fs = cv2.FileStorage(str(ext), cv2.FILE_STORAGE_WRITE)
    fs.write("R", R)
    fs.write("T", T.reshape(3, 1))
    fs.release()
    plain = tmp_path / "plain.yaml"
    save_camera(PinholeCamera.from_matrix(right.K, right.dist, right.image_size), plain)
    result = runner.invoke(
        app,
        [
            "stereo",
            str(pairs),
            "--camera-left",
            str(lp),
            "--camera-right",
            str(plain),
            "--extrinsics",
            str(ext),
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    r = json.loads(result.stdout)["records"][0]
    np.testing.assert_allclose([r["north_m"], r["east_m"], r["down_m"]], X[0], atol=1e-6)


def test_stereo_bad_inputs_exit_2(tmp_path: Path) -> None:
    lp, rp, _, _ = _stereo_rig(tmp_path)
    pairs = tmp_path / "p.csv"
    pairs.write_text("u_left,v_left,u_right,v_right\n1,2,3,4\n1,2,x,4\n")
    cmd = ["stereo", str(pairs), "--camera-left", str(lp), "--camera-right", str(rp)]
    result = runner.invoke(app, cmd)
    assert result.exit_code == 2 and "line 3" in _msg(result) and "u_right" in _msg(result)
    result = runner.invoke(app, [*cmd[:-1], str(lp)])  # the same camera twice: no baseline
    pairs.write_text("u_left,v_left,u_right,v_right\n1,2,3,4\n")
    result = runner.invoke(app, [*cmd[:-1], str(lp)])
    assert result.exit_code == 2 and "baseline" in _msg(result)
    result = runner.invoke(app, [*cmd, "--method", "magic"])
    assert result.exit_code == 2 and "--method" in _msg(result)
    bad_cam = tmp_path / "bad.yaml"
    bad_cam.write_text("format: seawatch-camera/1\nimage_size: [640, 480]\nwhat: 1\n")
    result = runner.invoke(app, [*cmd[:-1], str(bad_cam)])
    assert result.exit_code == 2 and "what" in _msg(result)


# ----------------------------------------------------------------------------- calibrate
@needs_chessboards
def test_calibrate_single_camera_writes_a_loadable_camera_file(tmp_path: Path) -> None:
    images = [str(DATA / f"left0{i}.jpg") for i in range(1, 7)] + [str(DATA / "aloeL.jpg")]
    out = tmp_path / "camera.yaml"
    result = runner.invoke(
        app,
        ["calibrate", *images, "--pattern", "9x6", "--square", "0.025", "-o", str(out), "--json"],
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["output"] == str(out) and doc["fx"] == pytest.approx(536.0, abs=10.0)
    assert doc["rms_px"] < 0.6 and len(doc["images_used"]) == 6  # 6 of 13 images
    assert doc["images_rejected"][0]["image"].endswith("aloeL.jpg")
    cam = load_camera(out)
    assert cam.fx == pytest.approx(doc["fx"]) and cam.image_size == (640, 480)


@needs_chessboards
def test_calibrate_stereo_writes_both_cameras_and_the_extrinsics(tmp_path: Path) -> None:
    left = [str(DATA / f"left0{i}.jpg") for i in range(1, 7)]
    right = str(DATA / "right0[1-6].jpg")  # a quoted glob
    out = tmp_path / "left.yaml"
    result = runner.invoke(
        app, ["calibrate", "--stereo", *left, "--right", right, "-o", str(out), "--json"]
    )
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["baseline_m"] * 1000 == pytest.approx(83.6, abs=1.5)
    for key in ("R", "T", "stereo_rms_px", "output_right", "extrinsics"):
        assert key in doc
    cam_r = load_camera(doc["output_right"])
    assert math.hypot(*cam_r.position) == pytest.approx(doc["baseline_m"], rel=0.02)
    # the written files triangulate the first pair's corners into 25 mm squares
    from seawatch.camera.calibration import find_corners

    cl, cr = find_corners(left[0]), find_corners(str(DATA / "right01.jpg"))
    pairs = _write(
        tmp_path / "corners.csv",
        ["u_left", "v_left", "u_right", "v_right"],
        np.hstack([cl, cr]).tolist(),
    )
    result = runner.invoke(
        app,
        [
            "stereo",
            str(pairs),
            "--camera-left",
            str(out),
            "--camera-right",
            doc["output_right"],
            "--extrinsics",
            doc["extrinsics"],
            "--json",
        ],
    )
    assert result.exit_code == 0, result.output
    rec = json.loads(result.stdout)["records"]
    P = np.array([[r["north_m"], r["east_m"], r["down_m"]] for r in rec]).reshape(6, 9, 3)
    spacing = np.linalg.norm(np.diff(P, axis=1), axis=2)
    assert spacing.mean() * 1000 == pytest.approx(25.0, abs=1.0)


def test_calibrate_bad_inputs_exit_2(tmp_path: Path) -> None:
    img = str(tmp_path / "x.jpg")
    assert runner.invoke(app, ["calibrate", img, "--pattern", "nine"]).exit_code == 2
    assert runner.invoke(app, ["calibrate", img, "--square", "0"]).exit_code == 2
    result = runner.invoke(app, ["calibrate", "--stereo", img])
    assert result.exit_code == 2 and "--right" in _msg(result)
    result = runner.invoke(app, ["calibrate", "--stereo", img, img, "--right", img])
    assert result.exit_code == 2 and "1 right" in _msg(result)
    # no usable image: the message names the images and the reasons
    result = runner.invoke(app, ["calibrate", img, "-o", str(tmp_path / "c.yaml")])
    assert result.exit_code == 2 and "file not found" in _msg(result)
