"""Tests of the ``air-range`` scenario (SCENARIOS.md, seed 002)."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from seawatch.scenarios import air_range as ar

G = 9.80665
ESTIMATORS = [
    "raw", "ncv-1", "ncv-5", "ncv-10", "nca-0.001", "nca-0.01", "nca-0.1", "ancv", "anca",
]  # fmt: skip
FIXED = [e for e in ESTIMATORS if e.startswith(("ncv", "nca"))]


@pytest.fixture(scope="module")
def truth() -> ar.AirRangeTrajectory:
    return ar.trajectory()


@pytest.fixture(scope="module")
def result() -> ar.AirRangeResult:
    return ar.run(runs=100, seed=0)


def _mean(result: ar.AirRangeResult, est: str, metric: str) -> tuple[float, float]:
    rec = result.record(est, metric)
    return rec["mean"], rec["stderr"]


# ------------------------------------------------------------------ geometry
def test_trajectory_starts_at_5_km_range_with_25_frames_per_second(truth):
    assert truth.range[0] == pytest.approx(5000.0, abs=1e-9)
    np.testing.assert_allclose(np.diff(truth.time), 0.04, rtol=1e-12)


def test_level_flight_has_1000_m_miss_distance_300_m_height_and_200_m_per_s(truth):
    level = truth.time < truth.pullup_time
    p = truth.position[level]
    np.testing.assert_allclose(p[:, 1], 1000.0)  # horizontal offset of the flight line
    np.testing.assert_allclose(p[:, 2], 300.0)  # height
    # the straight line's closest horizontal approach to the camera is the miss distance
    np.testing.assert_allclose(np.diff(p[:, 0]) / 0.04, 200.0, rtol=1e-10)
    assert np.min(np.hypot(p[:, 0], p[:, 1])) > 1000.0
    assert np.all(p[:, 0] < 0.0)  # not yet past the camera


def test_pullup_starts_at_2500_m_range(truth):
    t_p = truth.pullup_time
    # independent recomputation: straight line at 200 m/s from the 5 km start point
    x_start = -math.sqrt(5000.0**2 - 1000.0**2 - 300.0**2)
    x = x_start + 200.0 * t_p
    assert math.sqrt(x * x + 1000.0**2 + 300.0**2) == pytest.approx(2500.0, abs=1e-6)
    level = truth.time < t_p
    assert truth.range[level][-1] > 2500.0 > truth.range[~level][0]


def test_pullup_acceleration_is_3_g_from_second_differences_of_positions(truth):
    p, dt = truth.position, truth.dt
    acc = (p[2:] - 2.0 * p[1:-1] + p[:-2]) / dt**2  # central differences of the sampled path
    t_mid = truth.time[1:-1]
    arc = t_mid > truth.pullup_time + dt
    level = t_mid < truth.pullup_time - dt
    np.testing.assert_allclose(np.linalg.norm(acc[arc], axis=1), 3.0 * G, rtol=1e-4)
    np.testing.assert_allclose(acc[level], 0.0, atol=1e-6)
    assert np.all(acc[arc, 2] > 0.0)  # upwards: a pull-up in the vertical plane
    np.testing.assert_allclose(np.linalg.norm(truth.velocity, axis=1), 200.0, rtol=1e-12)


def _independent_range(t: float) -> float:
    """Slant range of the resolved path, recomputed from SCENARIOS.md's description."""
    closest2 = 1000.0**2 + 300.0**2
    x_start, x_pull = -math.sqrt(5000.0**2 - closest2), -math.sqrt(2500.0**2 - closest2)
    t_pull = (x_pull - x_start) / 200.0
    if t < t_pull:
        x, z = x_start + 200.0 * t, 300.0
    else:
        rho, w = 200.0**2 / (3 * G), 3 * G / 200.0
        x = x_pull + rho * math.sin(w * (t - t_pull))
        z = 300.0 + rho * (1.0 - math.cos(w * (t - t_pull)))
    return math.sqrt(x * x + 1000.0**2 + z * z)


def test_run_ends_at_the_last_frame_before_the_range_starts_to_grow(truth):
    assert np.all(np.diff(truth.range) < 0.0)
    h = 1e-4
    t_last = truth.time[-1]
    slope_last = _independent_range(t_last + h) - _independent_range(t_last - h)
    slope_next = _independent_range(t_last + 0.04 + h) - _independent_range(t_last + 0.04 - h)
    assert slope_last < 0.0 < slope_next  # the range minimum lies within the next frame
    for k in (0, 100, 327, 400, truth.time.size - 1):
        assert truth.range[k] == pytest.approx(_independent_range(truth.time[k]), rel=1e-12)
    assert truth.range[-1] == pytest.approx(1764.37, abs=0.01)


def test_analytic_range_derivatives_match_finite_differences(truth):
    d, dt = truth.range, truth.dt
    rate_fd = (d[2:] - d[:-2]) / (2 * dt)
    acc_fd = (d[2:] - 2 * d[1:-1] + d[:-2]) / dt**2
    smooth = np.abs(truth.time[1:-1] - truth.pullup_time) > 2 * dt
    # central differences are exact to O(dt² · d''') ≈ 0.0016 · 10 / 6 m/s here
    np.testing.assert_allclose(truth.range_rate[1:-1][smooth], rate_fd[smooth], atol=5e-3)
    np.testing.assert_allclose(
        truth.range_acceleration[1:-1][smooth], acc_fd[smooth], rtol=1e-3, atol=5e-3
    )


def test_bad_geometry_raises_value_error_naming_the_argument():
    with pytest.raises(ValueError, match="pullup_range"):
        ar.trajectory(pullup_range=6000.0)
    with pytest.raises(ValueError, match="dt"):
        ar.trajectory(dt=0.0)
    with pytest.raises(ValueError, match="runs"):
        ar.simulate(runs=0)


# -------------------------------------------------------------- measurements
def test_raw_range_error_std_matches_sigma_d_at_5_and_2_5_km(truth):
    meas = ar.simulate(runs=4000, seed=1234)
    err = meas.range - truth.range
    k25 = int(np.argmin(np.abs(truth.range - 2500.0)))
    for k in (0, k25):
        sigma_d = truth.range[k] ** 2 * 1.0 / (40_000.0 * 10.0)
        # standard error of a std estimate from 4000 samples is ~1.1 %
        assert np.std(err[:, k]) == pytest.approx(sigma_d, rel=0.05)
    assert truth.range[0] ** 2 / 400_000.0 == pytest.approx(62.5)
    assert 2500.0**2 / 400_000.0 == pytest.approx(15.625)


def test_simulation_is_reproducible_from_its_seed():
    a, b, c = ar.simulate(3, seed=7), ar.simulate(3, seed=7), ar.simulate(3, seed=8)
    np.testing.assert_array_equal(a.range, b.range)
    assert not np.array_equal(a.range, c.range)
    np.testing.assert_allclose(a.range * a.image_size, 40_000.0 * 10.0, rtol=1e-12)


# ------------------------------------------------------------------- results
def test_records_have_every_interfaces_name_and_field(result):
    names = {(r["estimator"], r["metric"]) for r in result.records}
    assert names == {(e, m) for e in ESTIMATORS for m in ar.METRICS}
    for r in result.records:
        assert set(r) == {"estimator", "metric", "unit", "mean", "stderr", "paper", "params"}
        assert r["unit"] == "m"
        assert r["mean"] > 0.0
        assert 0.0 < r["stderr"] < 0.1 * r["mean"]
    assert result.errors["raw"].shape == (100, result.truth.range.size)


def test_rms_errors_are_recomputed_from_the_per_frame_errors(result):
    e = result.errors["ancv"]
    far = result.truth.range > 2500.0
    per_run = np.sqrt(np.mean(e[:, far] ** 2, axis=1))
    mean, se = _mean(result, "ancv", "rmse_range_far")
    assert mean == pytest.approx(per_run.mean(), rel=1e-12)
    assert se == pytest.approx(per_run.std(ddof=1) / 10.0, rel=1e-12)


@pytest.mark.parametrize("est", ESTIMATORS[1:])
def test_every_filter_beats_raw_range_far_from_the_camera(result, est):
    raw, raw_se = _mean(result, "raw", "rmse_range_far")
    m, se = _mean(result, est, "rmse_range_far")
    assert m + 3 * se < raw - 3 * raw_se


@pytest.mark.parametrize(
    "est",
    [
        pytest.param(
            "ncv-1",
            marks=pytest.mark.xfail(
                strict=True,
                reason="σ_v = 1 m/s² cannot follow the 3 g pull-up (range acceleration up to "
                "47 m/s²): near RMS 68.7 m, whole-run 40.6 m against raw 32.1 m (100 runs, seed 0)",
            ),
        ),
        *ESTIMATORS[2:],
    ],
)
def test_filter_beats_raw_range_over_the_whole_run(result, est):
    raw, raw_se = _mean(result, "raw", "rmse_range")
    m, se = _mean(result, est, "rmse_range")
    assert m + 3 * se < raw - 3 * raw_se


@pytest.mark.parametrize(("small", "large"), [("ncv-1", "ncv-10"), ("nca-0.001", "nca-0.1")])
def test_paper_claim_large_sigma_is_better_late(result, small, large):
    m_small, se_small = _mean(result, small, "rmse_range_near")
    m_large, se_large = _mean(result, large, "rmse_range_near")
    assert m_large + 3 * se_large < m_small - 3 * se_small


@pytest.mark.xfail(
    strict=True,
    reason="not reproduced with the resolved trajectory: the first seconds are limited by the "
    "diffuse start (all σ_v agree to 0.1 m), and the range acceleration of the 1000 m miss "
    "distance (0.35 → 2.6 m/s² over the level flight) already makes σ_v = 1 lag; far RMS "
    "ncv-1 11.82 ± 0.24 m vs ncv-10 11.43 ± 0.24 m, nca-0.001 12.04 vs nca-0.1 12.04 m "
    "(100 runs, seed 0)",
)
@pytest.mark.parametrize(("small", "large"), [("ncv-1", "ncv-10"), ("nca-0.001", "nca-0.1")])
def test_paper_claim_small_sigma_is_better_early(result, small, large):
    m_small, se_small = _mean(result, small, "rmse_range_far")
    m_large, se_large = _mean(result, large, "rmse_range_far")
    assert m_small + 2 * se_small < m_large - 2 * se_large


@pytest.mark.parametrize("adaptive", ["ancv", "anca"])
@pytest.mark.parametrize("fixed", FIXED)
def test_each_adaptive_filter_beats_every_fixed_noise_filter_over_the_whole_run(
    result, adaptive, fixed
):
    # seawatch's own target (SCENARIOS.md air-range): paired comparison over the same runs
    a = np.sqrt(np.mean(result.errors[adaptive] ** 2, axis=1))
    f = np.sqrt(np.mean(result.errors[fixed] ** 2, axis=1))
    diff = f - a
    assert diff.mean() > 3 * diff.std(ddof=1) / math.sqrt(diff.size)


def test_adaptive_sigma_starts_at_the_papers_values_and_then_adapts(result):
    s_ancv, s_anca = result.sigma_v["ancv"], result.sigma_v["anca"]
    assert np.all(s_ancv[:, 1:51] == 1.0)  # σ_v² = 1 until the 50-frame window is full
    assert np.all(s_anca[:, 1:51] == 0.01)  # σ_v² = 1e-4
    assert np.all(s_ancv[:, -1] != 1.0)
    assert np.all(s_anca[:, -1] != 0.01)
    assert np.all(np.isnan(s_ancv[:, 0]))


# ----------------------------------------------------------------------- demo
def test_run_demo_writes_the_table_and_the_plot(tmp_path):
    calls = []
    demo = ar.run_demo(tmp_path / "out", runs=3, seed=0, progress=lambda d, t: calls.append((d, t)))
    assert demo.table_path == tmp_path / "out" / "errors.csv"
    assert demo.plot_path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with demo.table_path.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["estimator"] for r in rows] == ESTIMATORS
    assert float(rows[0]["rmse_range_m"]) == pytest.approx(demo.rows[0]["rmse_range_m"], abs=1e-4)
    assert calls[-1] == (len(ESTIMATORS), len(ESTIMATORS))
    assert [d for d, _ in calls] == list(range(1, len(ESTIMATORS) + 1))
