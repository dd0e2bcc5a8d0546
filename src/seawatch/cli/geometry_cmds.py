"""Command functions of the geometry stage: ``seawatch locate``, ``stereo`` and ``calibrate``.

Plain typer-compatible functions (the CLI registers them with ``app.command()(locate)``).
They read CSV/camera/image files, call :mod:`seawatch.geometry`,
:mod:`seawatch.camera.stereo` and :mod:`seawatch.camera.calibration`, and write CSV,
camera files and JSON. The contract of INTERFACES.md holds: ``--json`` prints exactly one
JSON document on stdout (progress and logs go to stderr); exit code 0 ok, 1 failed,
2 bad input, with a message naming the file, the line and the column.

CSV input: a header line, comma separated, ``#`` comment lines and blank lines skipped;
an empty cell (or ``nan``) is a missing value, which gives a NaN/empty output row.
CSV output: the input columns unchanged, then the computed ones; NaN is written as an
empty cell, an infinite range as ``inf``.
"""

from __future__ import annotations

import csv
import glob
import io
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from seawatch.cli._common import BadInput, emit_json, err, exit_codes, progress_bar

__all__ = ["calibrate", "locate", "stereo"]

_MISSING = ("", "nan", "na", "null", "none")


# ----------------------------------------------------------------------------- CSV
class _Table:
    """A CSV file read into strings, with the file line number of every row."""

    def __init__(self, path: Path, header: list[str], rows: list[list[str]], lines: list[int]):
        self.path = path
        self.header = header
        self.rows = rows
        self.lines = lines

    def __len__(self) -> int:
        return len(self.rows)

    def has(self, name: str) -> bool:
        return name in self.header

    def require(self, *names: str) -> None:
        missing = [n for n in names if n not in self.header]
        if missing:
            raise BadInput(
                f"{self.path}: missing column(s) {', '.join(missing)} "
                f"(header has: {', '.join(self.header)})"
            )

    def numbers(self, name: str) -> np.ndarray:
        """A column as floats: an empty cell or 'nan' is NaN; anything else must parse."""
        j = self.header.index(name)
        out = np.empty(len(self.rows))
        for i, (rec, line) in enumerate(zip(self.rows, self.lines, strict=True)):
            cell = rec[j].strip()
            if cell.lower() in _MISSING:
                out[i] = np.nan
                continue
            try:
                out[i] = float(cell)
            except ValueError:
                raise BadInput(
                    f"{self.path}: line {line}: column '{name}': {cell!r} is not a number"
                ) from None
        return out

    def passthrough(self) -> dict[str, list[str]]:
        return {name: [rec[j] for rec in self.rows] for j, name in enumerate(self.header)}


def _read_csv(path: Path, label: str) -> _Table:
    if not path.is_file():
        raise BadInput(f"{label} {path}: file not found")
    header: list[str] | None = None
    rows: list[list[str]] = []
    lines: list[int] = []
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            reader = csv.reader(fh)
            try:
                for rec in reader:
                    if (
                        not rec
                        or all(not c.strip() for c in rec)
                        or rec[0].lstrip().startswith("#")
                    ):
                        continue
                    if header is None:
                        header = [c.strip() for c in rec]
                        dup = {h for h in header if header.count(h) > 1}
                        if "" in header or dup:
                            raise BadInput(
                                f"{path}: line {reader.line_num}: header has empty or repeated "
                                f"column names ({', '.join(sorted(dup)) or 'empty name'})"
                            )
                        continue
                    if len(rec) != len(header):
                        raise BadInput(
                            f"{path}: line {reader.line_num}: expected {len(header)} fields "
                            f"({', '.join(header)}), got {len(rec)}"
                        )
                    rows.append(rec)
                    lines.append(reader.line_num)
            except csv.Error as exc:
                raise BadInput(f"{path}: line {reader.line_num}: malformed CSV ({exc})") from None
    except UnicodeDecodeError:
        raise BadInput(f"{label} {path}: not a UTF-8 text CSV file") from None
    if header is None:
        raise BadInput(f"{label} {path}: empty file (expected a header line)")
    return _Table(path, header, rows, lines)


def _cell(value: Any) -> str:
    if isinstance(value, str):
        return value
    v = float(value)
    if math.isnan(v):
        return ""
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return repr(v)


def _write_csv(columns: dict[str, Sequence[Any]], output: Path | None) -> None:
    names = list(columns)
    n = len(next(iter(columns.values()))) if columns else 0
    buf = io.StringIO() if output is None else None
    fh = buf if output is None else output.open("w", newline="", encoding="utf-8")
    try:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(names)
        for i in range(n):
            writer.writerow([_cell(columns[c][i]) for c in names])
    finally:
        if output is not None:
            fh.close()
    if buf is not None:
        sys.stdout.write(buf.getvalue())
        sys.stdout.flush()


def _json_value(value: Any) -> Any:
    if isinstance(value, str):
        try:
            return float(value) if value.strip().lower() not in _MISSING else None
        except ValueError:
            return value
    v = float(value)
    return v if math.isfinite(v) else None


def _records(columns: dict[str, Sequence[Any]]) -> list[dict[str, Any]]:
    names = list(columns)
    n = len(next(iter(columns.values()))) if columns else 0
    return [{c: _json_value(columns[c][i]) for c in names} for i in range(n)]


def _interp(t: np.ndarray, tn: np.ndarray, values: np.ndarray) -> np.ndarray:
    good = np.isfinite(values)
    if not np.any(good):
        return np.full(t.shape, np.nan)
    out = np.interp(t, tn[good], values[good])
    return np.where((t < tn[good][0]) | (t > tn[good][-1]) | np.isnan(t), np.nan, out)


# ----------------------------------------------------------------------------- locate
def locate(
    angles: Annotated[
        Path,
        typer.Argument(help="CSV of sightings: azimuth_deg, depression_deg (see below)."),
    ],
    height: Annotated[
        float,
        typer.Option("--height", help="Camera height above the sea surface (m), > 0."),
    ],
    platform: Annotated[
        Path | None,
        typer.Option(
            "--platform",
            help="Navigation CSV: time and any of north_m, east_m, lat, lon, heading_deg, "
            "height_m; interpolated linearly at each sighting's time.",
        ),
    ] = None,
    heading: Annotated[
        float,
        typer.Option(
            "--heading",
            help="Platform heading (deg clockwise from North) used when NAV has no "
            "heading_deg (0: the azimuths are true bearings).",
        ),
    ] = 0.0,
    lat: Annotated[
        float | None,
        typer.Option("--lat", help="WGS-84 latitude (deg) of the local origin (the camera)."),
    ] = None,
    lon: Annotated[
        float | None,
        typer.Option("--lon", help="WGS-84 longitude (deg) of the local origin (the camera)."),
    ] = None,
    flat: Annotated[
        bool,
        typer.Option(
            "--flat/--curved",
            help="Flat sea (seed 000 eqs. 3-5) or curved sea with refraction (ALGORITHMS.md "
            "§4.2, default).",
        ),
    ] = False,
    refraction: Annotated[
        float, typer.Option("--refraction", help="Refraction coefficient k (curved sea).")
    ] = 0.14,
    sigma_azimuth: Annotated[
        float,
        typer.Option("--sigma-azimuth", help="1-sigma azimuth error (deg) (column overrides)."),
    ] = 0.05,
    sigma_depression: Annotated[
        float,
        typer.Option(
            "--sigma-depression", help="1-sigma depression error (deg) (column overrides)."
        ),
    ] = 0.02,
    sigma_height: Annotated[
        float, typer.Option("--sigma-height", help="1-sigma camera height error (m).")
    ] = 0.0,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Output CSV (default: stdout).")
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON document with every row on stdout.")
    ] = False,
) -> None:
    """Turn camera angles into ranges and positions on the sea surface, with 1-sigma errors.

    Input ANGLES.csv, one sighting per row: [bold]azimuth_deg[/] (of the waterline point,
    clockwise from the platform heading), [bold]depression_deg[/] (below the TRUE
    horizontal, not the visible horizon; or elevation_deg = -depression), optional
    [bold]time[/] (s, needed with --platform), sigma_azimuth_deg, sigma_depression_deg;
    other columns are copied to the output.

    Output columns (CSV, one row per input row): the input columns, then
    [bold]bearing_deg[/] (true bearing of the sighting), [bold]range_m[/] (horizontal
    distance; along the surface on the curved sea; inf above the horizon),
    [bold]north_m, east_m[/] (target in the local frame: platform position + offset),
    [bold]lat, lon[/] (WGS-84, when --lat/--lon or NAV lat/lon give the camera's position),
    [bold]sigma_range_m, sigma_north_m, sigma_east_m, cov_north_east_m2[/] (first-order
    1-sigma errors and covariance) and [bold]flag[/] (ok, above_horizon, invalid).

    Example: [cyan]seawatch locate angles.csv --height 12 --lat 50.8 --lon -1.3 -o fixes.csv[/]
    """
    from seawatch.geometry.geodesy import destination, north_east_to_geodetic
    from seawatch.geometry.sea import (
        RangeFlag,
        range_sigma,
        sea_position,
        sea_position_covariance,
    )

    with exit_codes():
        if not (math.isfinite(height) and height > 0):
            raise BadInput(f"--height: expected a camera height > 0 m, got {height}")
        if (lat is None) != (lon is None):
            raise BadInput("--lat, --lon: give both the latitude and the longitude, or neither")
        if not (0.0 <= refraction < 1.0):
            raise BadInput(f"--refraction: expected a value in [0, 1), got {refraction}")
        for name, value in (
            ("--sigma-azimuth", sigma_azimuth),
            ("--sigma-depression", sigma_depression),
            ("--sigma-height", sigma_height),
        ):
            if not (math.isfinite(value) and value >= 0):
                raise BadInput(f"{name}: expected a standard deviation >= 0, got {value}")

        tab = _read_csv(angles, "ANGLES")
        tab.require("azimuth_deg")
        if tab.has("depression_deg"):
            dep = np.radians(tab.numbers("depression_deg"))
        elif tab.has("elevation_deg"):
            dep = -np.radians(tab.numbers("elevation_deg"))
        else:
            tab.require("depression_deg")
        az = np.radians(tab.numbers("azimuth_deg"))
        n = len(tab)

        def sigma_col(name: str, default_deg: float) -> np.ndarray:
            if not tab.has(name):
                return np.full(n, math.radians(default_deg))
            s = tab.numbers(name)
            bad = np.isfinite(s) & (s < 0)
            if np.any(bad):
                line = tab.lines[int(np.argmax(bad))]
                raise BadInput(f"{angles}: line {line}: column '{name}': must be >= 0")
            return np.radians(np.where(np.isfinite(s), s, default_deg))

        s_az = sigma_col("sigma_azimuth_deg", sigma_azimuth)
        s_dep = sigma_col("sigma_depression_deg", sigma_depression)

        obs = np.zeros((n, 2))
        psi = np.full(n, math.radians(heading))
        h = np.full(n, float(height))
        cam_lat = cam_lon = None
        if platform is not None:
            nav = _read_csv(platform, "NAV")
            nav.require("time")
            tab.require("time")
            t = tab.numbers("time")
            tn = nav.numbers("time")
            if len(nav) == 0 or not np.all(np.isfinite(tn)) or np.any(np.diff(tn) <= 0):
                raise BadInput(f"{platform}: column 'time' must be finite and strictly increasing")
            if nav.has("north_m") or nav.has("east_m"):
                nav.require("north_m", "east_m")
                obs = np.column_stack(
                    [_interp(t, tn, nav.numbers("north_m")), _interp(t, tn, nav.numbers("east_m"))]
                )
            if nav.has("heading_deg"):
                hd = nav.numbers("heading_deg")
                good = np.isfinite(hd)
                hd[good] = np.unwrap(hd[good], period=360.0)
                psi = np.radians(_interp(t, tn, hd))
            if nav.has("height_m"):
                hn = nav.numbers("height_m")
                bad = np.isfinite(hn) & (hn <= 0)
                if np.any(bad):
                    line = nav.lines[int(np.argmax(bad))]
                    raise BadInput(f"{platform}: line {line}: column 'height_m': must be > 0")
                h = _interp(t, tn, hn)
            if nav.has("lat") or nav.has("lon"):
                nav.require("lat", "lon")
                ln = nav.numbers("lon")
                good = np.isfinite(ln)
                ln[good] = np.unwrap(ln[good], period=360.0)
                cam_lat = _interp(t, tn, nav.numbers("lat"))
                cam_lon = (_interp(t, tn, ln) + 180.0) % 360.0 - 180.0
            outside = np.isnan(_interp(t, tn, np.zeros(len(nav))))
            az = np.where(outside, np.nan, az)
            if np.any(outside):
                err.print(
                    f"[yellow]warning:[/] {int(outside.sum())} sighting(s) outside the time "
                    f"span of {platform}: flagged invalid"
                )
        if cam_lat is None and lat is not None:
            if not (-90.0 <= lat <= 90.0 and math.isfinite(lon)):  # type: ignore[arg-type]
                raise BadInput(f"--lat, --lon: not a valid position ({lat}, {lon})")
            cam_lat, cam_lon = north_east_to_geodetic(np.nan_to_num(obs), lat, lon)  # type: ignore[arg-type]
            cam_lat = np.where(np.isnan(obs[:, 0]), np.nan, cam_lat)

        curved = not flat
        pos = sea_position(obs, psi, az, dep, h, curved=curved, refraction=refraction)
        s_r = range_sigma(dep, h, s_dep, sigma_height, curved=curved, refraction=refraction)
        cov = sea_position_covariance(
            psi, az, dep, h, s_az, s_dep, sigma_height, curved=curved, refraction=refraction
        )
        s_r = np.where(pos.flag == RangeFlag.INVALID, np.nan, s_r)
        if cam_lat is not None:
            t_lat, t_lon = destination(
                cam_lat, cam_lon, np.where(pos.ok, pos.range, np.nan), pos.bearing
            )
        else:
            t_lat = t_lon = np.full(n, np.nan)
        names = {RangeFlag.OK: "ok", RangeFlag.ABOVE_HORIZON: "above_horizon"}
        flags = [names.get(RangeFlag(int(f)), "invalid") for f in pos.flag]

        columns: dict[str, Sequence[Any]] = dict(tab.passthrough())
        columns.update(
            {
                "bearing_deg": np.degrees(pos.bearing),
                "range_m": pos.range,
                "north_m": pos.xy[:, 0],
                "east_m": pos.xy[:, 1],
                "lat": np.atleast_1d(t_lat),
                "lon": np.atleast_1d(t_lon),
                "sigma_range_m": np.where(pos.ok, s_r, np.nan),
                "sigma_north_m": np.sqrt(cov[:, 0, 0]),
                "sigma_east_m": np.sqrt(cov[:, 1, 1]),
                "cov_north_east_m2": cov[:, 0, 1],
                "flag": flags,
            }
        )
        counts = {k: flags.count(k) for k in ("ok", "above_horizon", "invalid")}
        if output is not None or not json_out:
            _write_csv(columns, output)
        if json_out:
            emit_json(
                {
                    "input": str(angles),
                    "output": None if output is None else str(output),
                    "model": "curved" if curved else "flat",
                    "refraction": refraction if curved else None,
                    "rows": n,
                    "counts": counts,
                    "columns": list(columns),
                    "records": _records(columns),
                }
            )
        else:
            err.print(
                f"locate: {n} rows, {counts['ok']} ok, {counts['above_horizon']} above the "
                f"horizon, {counts['invalid']} invalid ({'curved' if curved else 'flat'} sea)"
            )
            if output is not None:
                typer.echo(f"wrote {output}")


# ----------------------------------------------------------------------------- stereo
def _world_projection(camera: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(P, R_cn, C): world NED → pixel projection of a camera file's pose.

    Camera centre C = (north_m, east_m, -height_m) (height None counts as 0).
    """
    R_cn = np.asarray(camera.R_nc).T
    C = np.array([camera.position[0], camera.position[1], -(camera.height or 0.0)])
    P = np.asarray(camera.K) @ np.hstack([R_cn, (-R_cn @ C)[:, None]])
    return P, R_cn, C


def _read_extrinsics(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(R, T) (m) of the right camera relative to the left from an OpenCV FileStorage file."""
    import cv2

    if not path.is_file():
        raise BadInput(f"--extrinsics {path}: file not found")
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    except cv2.error as exc:
        raise BadInput(f"{path}: not a readable OpenCV FileStorage file ({exc})") from None
    if not fs.isOpened():
        raise BadInput(f"{path}: not a readable OpenCV FileStorage file")
    try:
        R = fs.getNode("R").mat()
        T = fs.getNode("T").mat()
    finally:
        fs.release()
    if R is None or T is None:
        raise BadInput(f"{path}: missing key 'R' (3x3) or 'T' (3x1)")
    R = np.asarray(R, dtype=np.float64)
    if R.size == 3:
        R = cv2.Rodrigues(R.reshape(3))[0]
    T = np.asarray(T, dtype=np.float64).reshape(-1)
    if (
        R.shape != (3, 3)
        or T.shape != (3,)
        or not np.all(np.isfinite(R))
        or not np.all(np.isfinite(T))
    ):
        raise BadInput(f"{path}: key 'R' must be 3x3 (or a rotation vector) and 'T' 3x1")
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-6):
        raise BadInput(f"{path}: key 'R' is not a rotation matrix")
    return R, T


def stereo(
    pairs: Annotated[
        Path,
        typer.Argument(help="CSV of pixel pairs: u_left, v_left, u_right, v_right (px)."),
    ],
    camera_left: Annotated[
        Path, typer.Option("--camera-left", help="Left camera file (seawatch or OpenCV).")
    ],
    camera_right: Annotated[
        Path, typer.Option("--camera-right", help="Right camera file (seawatch or OpenCV).")
    ],
    extrinsics: Annotated[
        Path | None,
        typer.Option(
            "--extrinsics",
            help="OpenCV FileStorage file with R and T (m) of the right camera relative to "
            "the left (as written by seawatch calibrate --stereo); overrides the right "
            "camera file's pose.",
        ),
    ] = None,
    method: Annotated[
        str,
        typer.Option(
            "--method",
            help="DLT solution: homogeneous (SVD, as cv2.triangulatePoints) or "
            "inhomogeneous (seed 003 eq. 3).",
        ),
    ] = "homogeneous",
    sigma_px: Annotated[
        float, typer.Option("--sigma-px", help="1-sigma pixel error of each coordinate (px).")
    ] = 0.5,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Output CSV (default: stdout).")
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON document with every row on stdout.")
    ] = False,
) -> None:
    """Triangulate pixel pairs of a calibrated stereo pair into 3-D points with 1-sigma errors.

    Input PAIRS.csv: [bold]u_left, v_left, u_right, v_right[/] (raw pixels; undistorted
    with each camera's distortion), other columns copied to the output. The cameras'
    poses come from their files (mounting heading/pitch/roll, position north_m/east_m,
    height_m as the centre's height; world frame NED), or the right camera's from
    --extrinsics. Linear DLT triangulation (ALGORITHMS.md §6.1).

    Output columns: the input columns, then [bold]north_m, east_m, down_m[/] (world
    NED), [bold]x_m, y_m, z_m[/] (left camera frame: right, down, forward),
    [bold]range_m[/] (from the left camera), [bold]lat, lon[/] (when the left camera
    file has lat/lon), [bold]sigma_north_m, sigma_east_m, sigma_down_m, sigma_range_m[/]
    (first order from --sigma-px), [bold]reprojection_px[/], [bold]parallax_deg[/] and
    [bold]flag[/] (ok, at_infinity, behind_camera, invalid).

    Example: [cyan]seawatch stereo pairs.csv --camera-left l.yaml --camera-right r.yaml[/]
    """
    from seawatch.camera.stereo import (
        TriangulationFlag,
        triangulate_points,
        triangulation_covariance,
    )
    from seawatch.geometry.geodesy import north_east_to_geodetic
    from seawatch.io.camera_file import load_camera

    with exit_codes():
        if method not in ("homogeneous", "inhomogeneous"):
            raise BadInput(f"--method: expected homogeneous or inhomogeneous, got {method!r}")
        if not (math.isfinite(sigma_px) and sigma_px > 0):
            raise BadInput(f"--sigma-px: expected a pixel error > 0, got {sigma_px}")
        cam_l = load_camera(camera_left)
        cam_r = load_camera(camera_right)
        tab = _read_csv(pairs, "PAIRS")
        tab.require("u_left", "v_left", "u_right", "v_right")
        left = np.column_stack([tab.numbers("u_left"), tab.numbers("v_left")])
        right = np.column_stack([tab.numbers("u_right"), tab.numbers("v_right")])

        P_l, R_l, C_l = _world_projection(cam_l)
        if extrinsics is not None:
            R, T = _read_extrinsics(extrinsics)
            t_l = -R_l @ C_l
            P_r = np.asarray(cam_r.K) @ np.hstack([R @ R_l, (R @ t_l + T)[:, None]])
            C_r = -(R @ R_l).T @ (R @ t_l + T)
        else:
            P_r, _, C_r = _world_projection(cam_r)
        baseline = float(np.linalg.norm(C_r - C_l))
        if baseline < 1e-9:
            raise BadInput(
                f"{camera_left}, {camera_right}: both cameras are at the same position (zero "
                "baseline); give the cameras' positions (position/mounting keys) or --extrinsics"
            )

        res = triangulate_points(
            [P_l, P_r],
            [cam_l.undistort(left), cam_r.undistort(right)],
            method,  # type: ignore[arg-type]
        )
        X = res.points
        ok = res.flags == 0
        cov = np.full((len(X), 3, 3), np.nan)
        if np.any(ok):
            cov[ok] = triangulation_covariance([P_l, P_r], X[ok], sigma_px)
        offset = X - C_l
        rng = np.linalg.norm(offset, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            u = offset / rng[:, None]
            s_range = np.sqrt(np.einsum("ni,nij,nj->n", u, cov, u))
        cam_frame = offset @ R_l.T
        if cam_l.lat is not None:
            lat, lon = north_east_to_geodetic(
                np.nan_to_num(offset[:, :2]), cam_l.lat, cam_l.lon, up=np.nan_to_num(-X[:, 2])
            )
            lat = np.where(np.isfinite(X[:, 0]), lat, np.nan)
            lon = np.where(np.isfinite(X[:, 0]), lon, np.nan)
        else:
            lat = lon = np.full(len(X), np.nan)

        def flag_name(f: int) -> str:
            if f == 0:
                return "ok"
            if f & TriangulationFlag.INVALID:
                return "invalid"
            parts = []
            if f & TriangulationFlag.AT_INFINITY:
                parts.append("at_infinity")
            if f & TriangulationFlag.BEHIND_CAMERA:
                parts.append("behind_camera")
            return "+".join(parts)

        flags = [flag_name(int(f)) for f in res.flags]
        columns: dict[str, Sequence[Any]] = dict(tab.passthrough())
        columns.update(
            {
                "north_m": X[:, 0],
                "east_m": X[:, 1],
                "down_m": X[:, 2],
                "x_m": cam_frame[:, 0],
                "y_m": cam_frame[:, 1],
                "z_m": cam_frame[:, 2],
                "range_m": rng,
                "lat": lat,
                "lon": lon,
                "sigma_north_m": np.sqrt(cov[:, 0, 0]),
                "sigma_east_m": np.sqrt(cov[:, 1, 1]),
                "sigma_down_m": np.sqrt(cov[:, 2, 2]),
                "sigma_range_m": s_range,
                "reprojection_px": res.reprojection_error,
                "parallax_deg": np.degrees(res.parallax),
                "flag": flags,
            }
        )
        counts = {k: flags.count(k) for k in sorted(set(flags))}
        if output is not None or not json_out:
            _write_csv(columns, output)
        if json_out:
            emit_json(
                {
                    "input": str(pairs),
                    "output": None if output is None else str(output),
                    "method": method,
                    "baseline_m": baseline,
                    "rows": len(tab),
                    "counts": counts,
                    "columns": list(columns),
                    "records": _records(columns),
                }
            )
        else:
            err.print(
                f"stereo: {len(tab)} pairs, baseline {baseline * 1000:.1f} mm, "
                + ", ".join(f"{v} {k}" for k, v in counts.items())
            )
            if output is not None:
                typer.echo(f"wrote {output}")


# ----------------------------------------------------------------------------- calibrate
def _pattern(text: str) -> tuple[int, int]:
    parts = text.lower().replace("×", "x").split("x")
    try:
        cols, rows = (int(p) for p in parts)
    except ValueError:
        raise BadInput(
            f"--pattern: expected inner corners as COLUMNSxROWS like 9x6, got {text!r}"
        ) from None
    if cols < 2 or rows < 2:
        raise BadInput(f"--pattern: expected at least 2x2 inner corners, got {text!r}")
    return cols, rows


def _expand(paths: Sequence[Path]) -> list[Path]:
    """Expand quoted glob patterns (``'left*.jpg'``) in sorted order; keep other paths."""
    out: list[Path] = []
    for p in paths:
        s = str(p)
        if any(ch in s for ch in "*?[") and not p.exists():
            matches = sorted(glob.glob(s))
            if not matches:
                raise BadInput(f"{s}: no file matches this pattern")
            out.extend(Path(m) for m in matches)
        else:
            out.append(p)
    return out


def _write_extrinsics(path: Path, cal: Any) -> None:
    import cv2

    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    if not fs.isOpened():
        raise BadInput(f"cannot write {path}")
    try:
        fs.write("R", cal.R)
        fs.write("T", cal.T.reshape(3, 1))
        fs.write("E", cal.E)
        fs.write("F", cal.F)
        fs.write("baseline_m", float(cal.baseline_m))
        fs.write("stereo_rms_px", float(cal.stereo_rms_px))
        fs.write("unit", "m")
    finally:
        fs.release()


def calibrate(
    images: Annotated[
        list[Path],
        typer.Argument(
            help="Chessboard images (the left ones with --stereo); globs may be quoted."
        ),
    ],
    pattern: Annotated[
        str, typer.Option("--pattern", help="Inner corners COLUMNSxROWS of the chessboard.")
    ] = "9x6",
    square: Annotated[
        float, typer.Option("--square", help="Side of one chessboard square (m).")
    ] = 0.025,
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Camera file to write (the left with --stereo).")
    ] = Path("camera.yaml"),
    file_format: Annotated[
        str,
        typer.Option(
            "--format", help="Camera file format: seawatch (YAML/JSON) or opencv (FileStorage)."
        ),
    ] = "seawatch",
    stereo_pair: Annotated[
        bool, typer.Option("--stereo", help="Calibrate a stereo pair (IMAGES are the left ones).")
    ] = False,
    right: Annotated[
        list[Path] | None,
        typer.Option(
            "--right",
            help="Right images, in the order of the left ones: repeat --right per file or "
            "quote a glob (--right 'right*.jpg').",
        ),
    ] = None,
    output_right: Annotated[
        Path | None,
        typer.Option("--output-right", help="Right camera file (default: OUTPUT-right.SUFFIX)."),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the calibration JSON on stdout.")
    ] = False,
) -> None:
    """Calibrate a camera (or a stereo pair) from chessboard images with OpenCV.

    Finds the chessboard's inner corners (sub-pixel), calibrates the pinhole model with
    distortion (k1, k2, p1, p2, k3) and reports the RMS reprojection error, the error of
    each image, and the images rejected (pattern not found, unreadable: listed, not
    fatal). Writes the camera file (-o). With [bold]--stereo[/]: also the right camera
    (--output-right; its mounting/position hold its pose relative to the left camera,
    whose frame is the world frame: heading 0 = its optical axis; the vertical offset
    is not stored there) and OUTPUT-stereo.yml (OpenCV FileStorage: R, T (m), E, F,
    baseline_m, stereo_rms_px; X_right = R X_left + T) for [bold]seawatch stereo
    --extrinsics[/]. --json prints the calibration JSON (rms_px, fx, fy, cx, cy, dist,
    image_size, images_used, images_rejected, output; with --stereo also baseline_m, R,
    T, stereo_rms_px).

    Example: [cyan]seawatch calibrate left*.jpg --pattern 9x6 --square 0.025 -o camera.yaml[/]

    Example: [cyan]seawatch calibrate --stereo left*.jpg --right 'right*.jpg' -o left.yaml[/]
    """
    from seawatch.camera.attitude import attitude_from_rotation, rotation_nc
    from seawatch.camera.calibration import calibrate_camera, calibrate_stereo
    from seawatch.io.camera_file import save_camera

    with exit_codes():
        pat = _pattern(pattern)
        if not (math.isfinite(square) and square > 0):
            raise BadInput(f"--square: expected the square side > 0 m, got {square}")
        if file_format not in ("seawatch", "opencv"):
            raise BadInput(f"--format: expected seawatch or opencv, got {file_format!r}")
        left = _expand(images)
        if not left:
            raise BadInput("IMAGES: no images given")
        if right and not stereo_pair:
            raise BadInput("--right: only with --stereo")
        doc: dict[str, Any]
        if not stereo_pair:
            with progress_bar() as bar:
                task = bar.add_task("finding chessboards", total=len(left))
                cal = calibrate_camera(
                    left, pat, square, progress=lambda d, t: bar.update(task, completed=d)
                )
            save_camera(cal.to_camera(), output, format=file_format)  # type: ignore[arg-type]
            doc = cal.to_dict()
            doc["output"] = str(output)
            summary = [f"RMS {cal.rms_px:.3f} px, fx {cal.fx:.2f}, fy {cal.fy:.2f} px"]
            rejected = cal.images_rejected
        else:
            rights = _expand(right or [])
            if not rights:
                raise BadInput("--right: --stereo needs the right images (--right RIGHT...)")
            if len(rights) != len(left):
                raise BadInput(
                    f"--right: got {len(left)} left and {len(rights)} right images; give one "
                    "right image per left image (quote the glob, --right 'right*.jpg', or "
                    "repeat --right for each file)"
                )
            with progress_bar() as bar:
                task = bar.add_task("finding chessboards", total=2 * len(left))
                cal2 = calibrate_stereo(
                    left, rights, pat, square, progress=lambda d, t: bar.update(task, completed=d)
                )
            out_r = output_right or output.with_name(f"{output.stem}-right{output.suffix}")
            out_x = output.with_name(f"{output.stem}-stereo.yml")
            # left camera = world frame (heading/pitch/roll 0); right pose relative to it
            R_nc_l = rotation_nc(0.0, 0.0, 0.0)
            R_nc_r = R_nc_l @ cal2.R.T
            psi, theta, phi = (float(a) for a in attitude_from_rotation(R_nc_r))
            centre = R_nc_l @ (-cal2.R.T @ cal2.T)  # right centre in the left's NED [m]
            save_camera(cal2.left.to_camera(), output, format=file_format)  # type: ignore[arg-type]
            save_camera(
                cal2.right.to_camera(
                    heading=psi, pitch=theta, roll=phi, position=(centre[0], centre[1])
                ),
                out_r,
                format=file_format,  # type: ignore[arg-type]
            )
            _write_extrinsics(out_x, cal2)
            doc = cal2.to_dict()
            doc.update(
                {
                    "output": str(output),
                    "output_right": str(out_r),
                    "extrinsics": str(out_x),
                    "right_centre_ned_m": centre.tolist(),
                }
            )
            summary = [
                f"left RMS {cal2.left.rms_px:.3f} px, right RMS {cal2.right.rms_px:.3f} px, "
                f"stereo RMS {cal2.stereo_rms_px:.3f} px, baseline {cal2.baseline_m * 1000:.2f} mm"
            ]
            rejected = cal2.left.images_rejected + cal2.right.images_rejected
        if json_out:
            emit_json(doc)
            return
        for line in summary:
            err.print(line)
        for name, reason in rejected:
            err.print(f"[yellow]rejected[/] {name}: {reason}")
        for key in ("output", "output_right", "extrinsics"):
            if key in doc:
                typer.echo(f"wrote {doc[key]}")
