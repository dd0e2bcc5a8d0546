"""Track tables of simulated straight-line ships for the report tests (no pipeline needed).

A shore camera (10 m up, heading 200°, 60° HFOV, 1280×720) at 50.78° N 1.10° W sees:
track 1, a ship on a straight line at constant velocity (1.5, 4.0) m/s (North, East),
0–60 s, no MMSI and empty speed/course columns (as the first pipeline stage writes);
track 2, another straight-line ship labelled with MMSI 235000001, with speed and course
columns; track 3, a single fix. Rows carry full-precision numbers; positions, ranges and
geodetic coordinates are the simulated truth (pymap3d-based geodesy of seawatch).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from seawatch.camera import PinholeCamera
from seawatch.geometry.geodesy import north_east_to_geodetic
from seawatch.pipeline import TRACK_TABLE_COLUMNS

CAM_LAT, CAM_LON, CAM_HEIGHT = 50.78, -1.10, 10.0

# track id -> (t0, t1, p0 (north, east) [m], v (north, east) [m/s], mmsi, with speed column)
SHIPS: dict[int, tuple[float, float, tuple[float, float], tuple[float, float], str, bool]] = {
    1: (0.0, 60.0, (-2400.0, -1200.0), (1.5, 4.0), "", False),
    2: (10.0, 50.0, (-900.0, 300.0), (-0.5, -2.5), "235000001", True),
    3: (30.0, 30.0, (-1500.0, 100.0), (0.0, 0.0), "", False),
}
FPS = 4.0


def make_camera() -> PinholeCamera:
    return PinholeCamera.from_fov(
        1280, 720, 60.0, height=CAM_HEIGHT, heading=math.radians(200.0), lat=CAM_LAT, lon=CAM_LON
    )


def _cell(value: Any) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return repr(float(value)) if isinstance(value, float) else str(value)


def ship_rows(camera: PinholeCamera | None = None) -> list[dict[str, str]]:
    """Rows of tracks.csv (strings, as csv.DictReader gives them), ordered by time."""
    camera = camera or make_camera()
    out: list[tuple[float, int, dict[str, str]]] = []
    for tid, (t0, t1, p0, v, mmsi, speed_col) in SHIPS.items():
        times = np.arange(round(t0 * FPS), round(t1 * FPS) + 1) / FPS
        n = p0[0] + v[0] * times
        e = p0[1] + v[1] * times
        rng = np.hypot(n, e)
        az = np.arctan2(e, n) % (2 * math.pi)
        dep = np.arctan2(CAM_HEIGHT, rng)
        uv = camera.angles_to_pixel(az, -dep)
        lat, lon = north_east_to_geodetic(np.stack([n, e], -1), CAM_LAT, CAM_LON)
        width = camera.fx * 60.0 / rng
        for k, t in enumerate(times):
            w, h = float(width[k]), float(width[k]) / 3.0
            row = {
                "time": float(t),
                "frame": round(t * 25),
                "track_id": tid,
                "x": float(uv[k, 0]) - w / 2,
                "y": float(uv[k, 1]) - h,
                "w": w,
                "h": h,
                "u_wl": float(uv[k, 0]),
                "v_wl": float(uv[k, 1]),
                "azimuth_deg": math.degrees(az[k]),
                "depression_deg": math.degrees(dep[k]),
                "range_m": float(rng[k]),
                "east_m": float(e[k]),
                "north_m": float(n[k]),
                "lat": float(lat[k]),
                "lon": float(lon[k]),
                "speed_mps": math.hypot(*v) if speed_col else None,
                "course_deg": math.degrees(math.atan2(v[1], v[0])) % 360 if speed_col else None,
                "sigma_range_m": 1e-5 * float(rng[k]) ** 2 / CAM_HEIGHT,
                "sigma_east_m": None,
                "sigma_north_m": None,
                "mmsi": mmsi,
            }
            out.append((float(t), tid, {c: _cell(row.get(c)) for c in TRACK_TABLE_COLUMNS}))
    out.sort(key=lambda r: (r[0], r[1]))
    return [r for _, _, r in out]


def write_csv(path: Path, rows: list[dict[str, str]]) -> Path:
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(TRACK_TABLE_COLUMNS))
        writer.writeheader()
        writer.writerows(rows)
    return path


@pytest.fixture
def camera() -> PinholeCamera:
    return make_camera()


@pytest.fixture
def rows(camera: PinholeCamera) -> list[dict[str, str]]:
    return ship_rows(camera)


@pytest.fixture
def tracks_csv(tmp_path: Path, rows: list[dict[str, str]]) -> Path:
    return write_csv(tmp_path / "tracks.csv", rows)


@pytest.fixture(scope="session")
def sim() -> SimpleNamespace:
    """The simulation's constants and helpers (test modules cannot import conftest under
    pytest's importlib import mode)."""
    return SimpleNamespace(
        cam_lat=CAM_LAT, cam_lon=CAM_LON, ships=SHIPS, fps=FPS, write_csv=write_csv,
        ship_rows=ship_rows, make_camera=make_camera,
    )  # fmt: skip
