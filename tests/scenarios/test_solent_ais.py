"""Tests of the ``solent-ais`` scenario: real AIS tracks through a virtual shore camera.

Data: ``../shared/data/ais/solent_2016-01-12_1302-1344.csv`` (Stone Soup
``docs/demos/SolentAIS_20160112_130211.csv``, MIT). Independent references: the
curved-sea depression written out here from ALGORITHMS.md §4.2, pymap3d's ENU
conversion of linearly interpolated fixes, a synthetic constant-velocity vessel, and the
single-measurement information of §7(a).
"""

from __future__ import annotations

import csv
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pymap3d
import pytest

from seawatch.geometry import north_east_to_geodetic
from seawatch.io import ais
from seawatch.scenarios import solent_ais as sa
from seawatch.scenarios.base import ExperimentResult

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "ais"
SOLENT = DATA / "solent_2016-01-12_1302-1344.csv"
RE = 6_371_000.0 / (1.0 - 0.14)  # effective earth radius, k = 0.14
SMALL = (235013375, 235069877)  # two vessels leaving Portsmouth Harbour (short passes)


def _solent() -> Path:
    if not SOLENT.exists():
        pytest.skip(f"Solent AIS file not found at {SOLENT} (../shared/data/ais)")
    return SOLENT


@pytest.fixture(scope="module")
def table() -> ais.AisTable:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ais.AisWarning)
        return ais.read_ais_csv(_solent())


@pytest.fixture(scope="module")
def scene(table) -> sa.Scene:
    return sa.build_scene(table)


PROGRESS: list[tuple[int, int]] = []


@pytest.fixture(scope="module")
def small(table, tmp_path_factory) -> tuple[ExperimentResult, Path]:
    out = tmp_path_factory.mktemp("solent-ais")
    res = sa.run(
        runs=3,
        seed=0,
        out_dir=out,
        progress=lambda d, n: PROGRESS.append((d, n)),
        ais=table,
        camera_heading=175.0,
        vessels=SMALL,
    )
    return res, out


def _depression(D: np.ndarray, h: float) -> np.ndarray:
    """Curved-sea depression below the horizontal (ALGORITHMS.md §4.2), written out."""
    phi = D / RE
    return np.arctan2(h + RE * (1.0 - np.cos(phi)), RE * np.sin(phi))


def _cv_csv(path: Path, *, extra_rows: tuple[str, ...] = ()) -> tuple[float, float]:
    """A vessel 1.5 km east of a camera at (50.5 N, -1.0), going north at 5 m/s for 10 min."""
    lat0, lon0 = 50.5, -1.0
    t = np.arange(0.0, 601.0, 3.0)
    ne = np.stack([-1500.0 + 5.0 * t, np.full_like(t, 1500.0)], -1)
    lat, lon = north_east_to_geodetic(ne, lat0, lon0)
    rows = ["Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots"]
    for ti, la, lo in zip(t, lat, lon, strict=True):
        rows.append(f"{1.45e9 + ti:.3f},987654321,{la:.9f},{lo:.9f},0.0,{5.0 / (1852 / 3600):.6f}")
    rows.extend(extra_rows)
    path.write_text("\n".join(rows) + "\n")
    return lat0, lon0


# ------------------------------------------------------------------ the scene
def test_default_camera_looks_down_the_harbour_approach_at_175_degrees(scene):
    cam = scene.camera
    assert (cam.lat, cam.lon, cam.height) == (50.7903, -1.1070, 20.0)
    assert math.degrees(cam.heading) == pytest.approx(175.0)  # the busiest direction
    assert math.degrees(cam.fov) == pytest.approx(60.0)
    assert cam.sigma == pytest.approx(0.5 / (960.0 / math.tan(math.radians(30.0))))
    assert scene.passes >= 10 and scene.samples > 9000
    assert np.all(scene.length >= sa.MIN_PASS)


def test_passes_are_in_view_and_their_angles_are_the_curved_sea_angles(scene):
    m = scene.mask
    n, e = scene.truth[..., 0][m], scene.truth[..., 1][m]
    D = np.hypot(n, e)
    assert np.all((D >= 100.0) & (D <= 5000.0))
    rel = np.angle(np.exp(1j * (np.arctan2(e, n) - scene.camera.heading)))
    assert np.all(np.abs(rel) <= math.radians(30.0) + 1e-12)
    np.testing.assert_allclose(scene.azimuth[m], rel, atol=1e-12)
    np.testing.assert_allclose(scene.depression[m], _depression(D, 20.0), rtol=1e-9)
    np.testing.assert_allclose(np.diff(scene.time, axis=1)[m[:, 1:]], 1.0)


def test_truth_follows_the_ais_fixes(scene, table):
    """Scene truth against pymap3d ENU of linearly interpolated fixes (Hermite differs by m)."""
    cam = scene.camera
    for p in range(scene.passes):
        sel = table.mmsi == scene.mmsi[p]
        t = table.time[sel]
        order = np.argsort(t, kind="stable")
        t, la, lo = t[order], table.lat[sel][order], table.lon[sel][order]
        tq = scene.epoch + scene.time[p, : scene.length[p]]
        e, n, _ = pymap3d.geodetic2enu(np.interp(tq, t, la), np.interp(tq, t, lo), 0.0,
                                       cam.lat, cam.lon, 0.0)  # fmt: skip
        err = np.hypot(
            n - scene.truth[p, : scene.length[p], 0], e - scene.truth[p, : scene.length[p], 1]
        )
        assert np.percentile(err, 99) < 15.0, (scene.mmsi[p], err.max())


def test_angle_noise_has_the_stated_standard_deviation(scene):
    az, de = sa.simulate(scene, [0], seed=0)
    m = scene.mask
    ea = np.angle(np.exp(1j * (az[0][m] - scene.azimuth[m]))) / scene.camera.sigma
    eb = (de[0][m] - scene.depression[m]) / scene.camera.sigma
    for e in (ea, eb):
        assert abs(e.mean()) < 4.0 / math.sqrt(e.size)
        assert e.std() == pytest.approx(1.0, abs=0.03)
    assert abs(np.corrcoef(ea, eb)[0, 1]) < 0.04
    assert np.all(np.isnan(az[0][~m]))


def test_runs_do_not_depend_on_how_they_are_grouped(scene):
    sub = scene.subset([list(scene.mmsi).index(SMALL[0])])
    together = sa.evaluate(sub, [0, 1, 2], seed=7)
    apart = [sa.evaluate(sub, [0], seed=7), sa.evaluate(sub, [1, 2], seed=7)]
    for name, metrics in together.items():
        for metric, values in metrics.items():
            joined = np.concatenate([apart[0][name][metric], apart[1][name][metric]])
            np.testing.assert_array_equal(values, joined)
    a1, _ = sa.simulate(sub, [2], seed=7)
    a3, _ = sa.simulate(sub, [0, 1, 2], seed=7)
    np.testing.assert_array_equal(a1[0], a3[2])


def test_records_do_not_depend_on_the_chunking_of_the_parallel_protocol(table, tmp_path):
    opts = {"ais": table, "camera_heading": 175.0, "vessels": SMALL}
    n = sa.CHUNK + 2  # two blocks
    whole = sa.merge([sa.chunk(range(n), n, 4, **opts)], n, 4, **opts)
    parts = [sa.chunk(c, n, 4, **opts) for c in (range(0, sa.CHUNK), range(sa.CHUNK, n))]
    split = sa.merge(parts, n, 4, tmp_path, **opts)
    assert split.results == whole.results
    assert {p.name for p in split.outputs} >= {"plan.png", "results.csv"}
    with pytest.raises(ValueError, match="payloads"):
        sa.merge(parts[::-1], n, 4, **opts)
    with pytest.raises(ValueError, match="indices"):
        sa.chunk([2, 1], n, 4, **opts)


# ------------------------------------------------------------------ the target
def test_filters_are_at_least_30_percent_better_than_geometry_in_position(scene):
    res = sa.evaluate(scene, [0, 1, 2], seed=0)
    geo = res["geometry"]["rmse_position"]
    for name in ("ekf", "ukf"):
        ratio = res[name]["rmse_position"] / geo
        assert np.all(ratio <= 0.7), (name, ratio)
    # seed 000's claim carries over: algorithm 2 beats algorithm 1
    assert np.all(res["diffuse-rls"]["rmse_position"] < geo)
    # and only a model gives usable speeds
    assert np.all(res["ekf"]["rmse_speed"] < 0.1 * res["geometry"]["rmse_speed"])


def test_bound_at_a_pass_start_is_the_single_measurement_bound(scene):
    """With a diffuse position prior, J_0 = Hᵀ R⁻¹ H: σ²(D² + (dD/dβ)²) (§7(a), curved)."""
    bound = sa.pcrb(scene)
    D = scene.range[:, 0]
    h, s = scene.camera.height, scene.camera.sigma
    dD = 1e-3 * D
    dbeta = (_depression(D + dD, h) - _depression(D - dD, h)) / (2 * dD)
    expect = s**2 * (D**2 + 1.0 / dbeta**2)
    np.testing.assert_allclose(bound.position[:, 0], expect, rtol=1e-5)
    assert np.all(bound.position[scene.mask] > 0)


# ------------------------------------------------------------------ a known vessel
def test_a_constant_velocity_vessel_gets_the_busiest_heading_and_is_tracked_near_the_bound(
    tmp_path,
):
    lat0, lon0 = _cv_csv(tmp_path / "cv.csv")
    sc = sa.build_scene(tmp_path / "cv.csv", camera_lat=lat0, camera_lon=lon0)
    assert sc.passes == 1 and list(sc.mmsi) == [987654321]
    # brute force: seconds in view (100 m-5 km, +-30 deg) for every 5-degree heading
    t = np.arange(0.0, 601.0)
    bearing = np.degrees(np.arctan2(1500.0, -1500.0 + 5.0 * t))
    counts = [np.sum(np.abs((bearing - c + 180) % 360 - 180) <= 30) for c in range(0, 360, 5)]
    chosen = math.degrees(sc.camera.heading)
    assert counts[round(chosen / 5) % 72] == max(counts) == sc.samples
    np.testing.assert_allclose(sc.speed[sc.mask], 5.0, atol=1e-6)
    # a truth the NCV model can hold: after the start-up, the EKF sits near the bound
    az, de = sa.simulate(sc, range(8), seed=0)
    est = sa.estimate("ekf", sc, az, de)
    bound = sa.pcrb(sc)
    late = slice(sc.samples // 2, sc.samples)
    ep = np.sum((est.position - sc.truth[None, ..., :2]) ** 2, -1)[:, 0, late]
    ev = np.sum((est.velocity - sc.truth[None, ..., 2:]) ** 2, -1)[:, 0, late]
    assert np.sqrt(ep.mean()) < 1.3 * np.sqrt(bound.position[0, late].mean())
    assert np.sqrt(ev.mean()) < 1.3 * np.sqrt(bound.speed[0, late].mean() * 2)  # 2 axes
    assert np.sqrt(bound.position[0, late].mean()) < 0.5 * np.sqrt(
        np.sum((sa.estimate("geometry", sc, az, de).position - sc.truth[None, ..., :2]) ** 2, -1)[
            :, 0, late
        ].mean()
    )


# ------------------------------------------------------------------ the experiment
def test_run_reports_every_estimator_and_metric_of_interfaces_md(small):
    res, _ = small
    doc = json.loads(json.dumps(res.to_json()))
    assert doc["scenario"] == "solent-ais" and doc["runs"] == 3 and doc["seed"] == 0
    units = {"rmse_position": "m", "rmse_speed": "m/s", "rmse_course": "deg"}
    for est in ("geometry", "diffuse-rls", "ekf", "ukf", "crlb"):
        for metric, unit in units.items():
            rec = res.find(est, metric)
            assert rec["unit"] == unit and math.isfinite(rec["mean"]) and rec["paper"] is None
            assert rec["params"] == {}
            assert (rec["stderr"] is None) == (est == "crlb")
    crlb = res.find("crlb", "rmse_position")["mean"]
    for est in ("geometry", "ekf"):
        ratio = res.find(est, "rmse_position_over_crlb")["mean"]
        assert ratio == pytest.approx(res.find(est, "rmse_position")["mean"] / crlb, rel=1e-12)
    assert doc["camera"]["heading_deg"] == pytest.approx(175.0)
    assert sorted(doc["vessels"]) == sorted(SMALL)
    assert PROGRESS[-1][0] == PROGRESS[-1][1] and len(PROGRESS) == PROGRESS[-1][1]


def test_run_writes_tables_and_plots(small):
    res, out = small
    names = {p.name for p in res.outputs}
    assert names == {
        "plan.png",
        "error_vs_range.png",
        "error_vs_range.csv",
        "results.csv",
        "table.csv",
    }
    for p in res.outputs:
        assert p.parent == out and p.stat().st_size > 0
    for png in ("plan.png", "error_vs_range.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with (out / "table.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["estimator"] for r in rows] == ["geometry", "diffuse-rls", "ekf", "ukf", "crlb"]
    ekf = next(r for r in rows if r["estimator"] == "ekf")
    assert float(ekf["rmse_position_m"]) == pytest.approx(
        res.find("ekf", "rmse_position")["mean"], rel=1e-3
    )
    with (out / "error_vs_range.csv").open() as fh:
        bins = list(csv.DictReader(fh))
    assert sum(int(b["samples"]) for b in bins) == res.extra["samples"]


# ------------------------------------------------------------------ bad input
def test_missing_ais_file_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"nothing\.csv"):
        sa.run(runs=1, ais=tmp_path / "nothing.csv")


def test_a_camera_with_no_vessel_in_view_is_a_clear_error(table):
    with pytest.raises(ValueError, match=r"camera \(camera_lat=51\.5.*no vessel"):
        sa.build_scene(table, camera_lat=51.5, camera_lon=-0.12)  # London
    with pytest.raises(ValueError, match="no vessel"):
        sa.build_scene(table, camera_lat=50.0, camera_lon=-1.1)  # mid-Channel, 80 km south


def test_bad_rows_in_the_ais_file_are_counted_skipped_and_the_run_goes_on(tmp_path):
    bad = (
        "1450000300.000,987654321,50.49,54.83,0,9.7",  # impossible jump
        "garbage,987654321,50.49,-1.0,0,9.7",
        "1450000301.000,987654321,95.0,-1.0,0,9.7",
    )
    lat0, lon0 = _cv_csv(tmp_path / "bad.csv", extra_rows=bad)
    with pytest.warns(ais.AisWarning, match=r"line 20[345]"):
        res = sa.run(runs=2, ais=tmp_path / "bad.csv", camera_lat=lat0, camera_lon=lon0)
    assert res.extra["passes"] == 1 and res.extra["samples"] == 381
    assert res.find("ekf", "rmse_position")["mean"] < res.find("geometry", "rmse_position")["mean"]


def test_bad_arguments_name_themselves(table):
    with pytest.raises(ValueError, match="camera_lat/camera_lon"):
        sa.build_scene(table, camera_lat=50.79)
    with pytest.raises(ValueError, match="runs"):
        sa.run(runs=0, ais=table)
    with pytest.raises(ValueError, match="seed"):
        sa.run(runs=1, seed=-1, ais=table)
    for kw, name in (
        ({"fov": 0.0}, "fov"),
        ({"camera_height": -5.0}, "camera_height"),
        ({"rate": 0.0}, "rate"),
        ({"sigma_px": float("nan")}, "sigma_px"),
        ({"camera_lat": 95.0, "camera_lon": 0.0}, "camera_lat"),
    ):
        with pytest.raises(ValueError, match=name):
            sa.build_scene(table, **kw)
    sc = sa.build_scene(table, vessels=SMALL)
    z = np.zeros((1, *sc.mask.shape))
    with pytest.raises(ValueError, match="name: unknown estimator 'kalman'"):
        sa.estimate("kalman", sc, z, z)
    with pytest.raises(ValueError, match="azimuth: expected shape"):
        sa.estimate("ekf", sc, z[:, :1], z[:, :1])


def test_depressions_above_the_horizon_give_no_point_position_but_filters_carry_on(table):
    sc = sa.build_scene(table, vessels=SMALL, camera_heading=175.0, sigma_px=30.0)  # 1°
    res = sa.evaluate(sc, [0, 1], seed=0, keep=("ekf", "ukf"))
    assert np.all(res["geometry"]["valid_fraction"] < 0.95)
    for name in ("ekf", "ukf"):
        est = res[name]["_estimates"]
        assert np.all(np.isfinite(est.position[:, sc.mask]))
        assert np.all(res[name]["valid_fraction"] == 1.0)
    with pytest.raises(ValueError, match=r"vessels: none of \[1\]"):
        sa.build_scene(table, vessels=[1])
