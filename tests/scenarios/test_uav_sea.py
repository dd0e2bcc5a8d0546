"""Tests of the ``uav-sea`` scenario (SCENARIOS.md, seed 000; ALGORITHMS.md §3, §4.1, §7)."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from seawatch.scenarios import uav_sea as us
from seawatch.scenarios.base import ExperimentResult

ARCMIN = math.pi / (180 * 60)
RUNS = 60


PROGRESS: list[tuple[int, int]] = []


@pytest.fixture(scope="module")
def result(tmp_path_factory) -> ExperimentResult:
    return us.run(
        runs=RUNS,
        seed=0,
        out_dir=tmp_path_factory.mktemp("uav-sea"),
        progress=lambda done, total: PROGRESS.append((done, total)),
    )


def _rec(result, est, metric, **params):
    for r in result.results:
        if r["estimator"] == est and r["metric"] == metric and r["params"] == params:
            return r
    raise KeyError((est, metric, params))


def _independent_nominal(t):
    """SCENARIOS.md's resolved geometry, recomputed here from its numbers."""
    psi = math.radians(50.0)
    ex = 400.0 - 2.98 * t - 2.55 * t
    ey = 600.0 - 3.12 * t - 4.33 * t
    alpha = np.arctan2(
        -ex * math.sin(psi) + ey * math.cos(psi), ex * math.cos(psi) + ey * math.sin(psi)
    )
    k = np.hypot(ex, ey)
    return alpha, np.arctan2(3.0, k), k


# ------------------------------------------------------------------ resolved geometry
def test_resolved_geometry_starts_at_721_m_and_6_3_degrees_azimuth():
    nom = us.nominal_trajectory()
    assert nom.range[0] == pytest.approx(math.hypot(400.0, 600.0)) == pytest.approx(721.1, abs=0.05)
    assert math.degrees(nom.azimuth[0]) == pytest.approx(6.3, abs=0.05)
    np.testing.assert_allclose(np.diff(nom.time), 0.1, rtol=1e-12)


def test_run_ends_when_target_leaves_the_70_degree_field_of_view_at_71_2_s():
    nom = us.nominal_trajectory()
    alpha, beta, _ = _independent_nominal(nom.time)
    np.testing.assert_allclose(nom.azimuth, alpha, atol=1e-12)
    np.testing.assert_allclose(nom.elevation, beta, atol=1e-12)
    assert nom.time[-1] == pytest.approx(71.2)
    assert np.all(np.abs(nom.azimuth) <= math.radians(35.0))
    next_alpha, _, _ = _independent_nominal(np.array([nom.time[-1] + 0.1]))
    assert abs(next_alpha[0]) > math.radians(35.0)  # the next sample is outside
    assert nom.range[-1] == pytest.approx(70.0, abs=0.5)
    assert math.degrees(nom.elevation[-1]) == pytest.approx(2.5, abs=0.05)
    assert np.all(np.diff(nom.range) < 0)  # the target approaches throughout


def test_geometry_equations_3_to_5_invert_the_noise_free_angles():
    nom = us.nominal_trajectory()
    pos = us.geometry_position(nom.azimuth, nom.elevation, nom.platform)
    np.testing.assert_allclose(pos, nom.target[:, :2], atol=1e-8)


# ------------------------------------------------------------------ simulation
def test_truth_follows_the_ncv_model_with_the_stated_acceleration_noise():
    m = us.simulate(runs=40, seed=3)
    p, v = m.target[..., :2], m.target[..., 2:]
    w = np.diff(v, axis=1) / 0.1  # the accelerations w_k
    # x_{k+1} = x_k + Δ v_k + Δ²/2 w_k exactly
    np.testing.assert_allclose(np.diff(p, axis=1), 0.1 * v[:, :-1] + 0.005 * w, atol=1e-9)
    assert np.std(w) == pytest.approx(0.1, rel=0.02)  # 40 × 712 × 2 draws
    np.testing.assert_allclose(m.target[:, 0], np.tile([400.0, 600.0, -2.98, -3.12], (40, 1)))


def test_measurement_and_platform_noise_have_the_stated_levels():
    m = us.simulate(runs=40, seed=3)
    ea = (m.azimuth - m.azimuth_true) / ARCMIN
    eb = (m.elevation - m.elevation_true) / ARCMIN
    ep = m.platform - m.platform_true
    assert np.std(ea) == pytest.approx(0.88, rel=0.02)
    assert np.std(eb) == pytest.approx(1.56, rel=0.02)
    assert np.std(ep) == pytest.approx(1.0, rel=0.02)
    window = (m.time >= 40.0 - 1e-9) & (m.time <= 42.0 + 1e-9)
    assert window.sum() == 21
    assert np.all(m.impulse[:, ~window] == 0.0)
    assert np.std(m.impulse[:, window]) == pytest.approx(math.radians(1.0), rel=0.05)


def test_a_run_is_the_same_whatever_block_it_is_simulated_in():
    a = us.simulate(runs=3, seed=7)
    b = us.simulate(runs=2, seed=7, start=1)
    np.testing.assert_array_equal(a.azimuth[1:], b.azimuth)
    np.testing.assert_array_equal(a.target[1:], b.target)
    assert not np.array_equal(a.azimuth[0], a.azimuth[1])


# ------------------------------------------------------------------ Table 2
def test_algorithm_1_angle_rmse_equals_the_noise_levels(result):
    for metric, sigma in (("rmse_azimuth", 0.88), ("rmse_elevation", 1.56)):
        r = _rec(result, "geometry", metric)
        assert abs(r["mean"] - sigma) < 4 * r["stderr"] + 1e-3, (metric, r)


def test_algorithm_1_position_rmse_reproduces_the_paper_within_5_percent(result):
    assert _rec(result, "geometry", "rmse_x")["mean"] == pytest.approx(20.7, rel=0.05)
    assert _rec(result, "geometry", "rmse_y")["mean"] == pytest.approx(31.0, rel=0.05)


def test_target_algorithm_2_cuts_the_x_and_y_rmse_of_algorithm_1_by_10_percent(result):
    for metric in ("rmse_x", "rmse_y"):
        a1 = _rec(result, "geometry", metric)["mean"]
        a2 = _rec(result, "diffuse-rls", metric)["mean"]
        assert a2 <= 0.9 * a1, (metric, a1, a2)


def test_target_best_estimator_within_1_5_of_the_crlb_and_better_than_paper_algorithm_2(result):
    best = min(("ekf", "ukf"), key=lambda e: _rec(result, e, "rmse_position")["mean"])
    ratio = _rec(result, best, "rmse_position_over_crlb")
    assert ratio["mean"] + 3 * ratio["stderr"] < 1.5
    assert ratio["mean"] > 1.0 - 3 * ratio["stderr"]  # a bound: nothing beats it
    paper_alg2 = math.hypot(16.9, 25.2)  # Table 2: RMSE x, y of algorithm 2
    ours = _rec(result, best, "rmse_position")["mean"]
    assert ours < paper_alg2
    assert ours < _rec(result, "diffuse-rls", "rmse_position")["mean"]
    for metric in ("rmse_x", "rmse_y"):
        assert _rec(result, best, metric)["mean"] < _rec(result, "diffuse-rls", metric)["paper"]


def test_algorithm_2_improves_the_elevation_like_the_paper(result):
    r = _rec(result, "diffuse-rls", "rmse_elevation")
    assert r["mean"] < 1.14  # paper: 1.56′ → 1.14′


@pytest.mark.xfail(
    strict=True,
    reason="not reproduced: with 1000 runs algorithm 2's azimuth RMSE is 0.943′ ± 0.001′, "
    "above the 0.88′ noise (paper: 0.57′); below the noise only beyond ~350 m range, "
    "then its AR(5) fit lags the accelerating azimuth (bias +0.59′)",
)
def test_paper_claim_algorithm_2_cuts_the_azimuth_rmse_below_the_noise(result):
    assert _rec(result, "diffuse-rls", "rmse_azimuth")["mean"] < 0.88


def test_fitted_form_is_the_default_and_the_model_form_drifts(result):
    assert result.to_json()["filtered"] == "fitted"
    fitted = _rec(result, "diffuse-rls", "rmse_azimuth")["mean"]
    model = _rec(result, "diffuse-rls", "rmse_azimuth", filtered="model")["mean"]
    assert model > 20 * fitted
    assert (
        _rec(result, "diffuse-rls", "rmse_x", filtered="model")["mean"]
        > _rec(result, "geometry", "rmse_x")["mean"]
    )


def test_crlb_below_every_estimator_and_looser_when_the_platform_is_known(result):
    bound = _rec(result, "crlb", "rmse_position")["mean"]
    known = _rec(result, "crlb", "rmse_position", platform="known")["mean"]
    assert known < bound
    for est in us.ESTIMATORS:
        assert _rec(result, est, "rmse_position")["mean"] > bound * 0.95
    # the bound of x and y combine to the position bound
    bx, by = _rec(result, "crlb", "rmse_x")["mean"], _rec(result, "crlb", "rmse_y")["mean"]
    assert math.hypot(bx, by) == pytest.approx(bound, rel=1e-9)


# ------------------------------------------------------------------ Figs. 5 and 6
def test_impulse_algorithm_3_recovers_sooner_than_algorithm_2(result):
    a2 = _rec(result, "diffuse-rls", "recovery_time", case="impulse")["mean"]
    a3 = _rec(result, "sliding-diffuse-rls", "recovery_time", case="impulse")["mean"]
    assert a3 < a2
    # the window is 120 steps = 12 s; the paper: about 20 s sooner
    assert a3 == pytest.approx(12.0 + 0.5, abs=1.0)
    assert a2 - a3 > 10.0


def test_close_range_algorithm_2_loses_track_at_a_larger_range_than_algorithm_3(result):
    a2 = _rec(result, "diffuse-rls", "loss_of_track_range", case="close-range")
    a3 = _rec(result, "sliding-diffuse-rls", "loss_of_track_range", case="close-range")
    assert a2["mean"] > a3["mean"] + 3 * (a2["stderr"] + a3["stderr"])
    assert a2["paper"] == 200.0 and a3["paper"] == 90.0
    assert 150.0 < a2["mean"] < 350.0  # paper: ~200 m


def test_recovery_time_counts_from_the_end_of_the_impulse():
    t = np.arange(713) * 0.1
    clean = np.zeros((2, 713))
    imp = clean.copy()
    imp[0, 400:460] = ARCMIN  # last above threshold at t = 45.9 s
    assert us.recovery_time(clean, imp, t) == pytest.approx([4.0, 0.0])


def test_loss_of_track_range_is_the_first_range_above_1_5_sigma():
    t = np.arange(713) * 0.1
    r = 721.0 - t * 9.0
    e2 = np.where(t > 50.0, (2.0 * 0.88 * ARCMIN) ** 2, (0.5 * ARCMIN) ** 2)
    got = us.loss_of_track_range(e2, r, t)
    assert got == pytest.approx(721.0 - 9.0 * 50.0, abs=9.0 * 0.6)
    assert us.loss_of_track_range(np.full(713, (0.5 * ARCMIN) ** 2), r, t) == r[-1]


# ------------------------------------------------------------------ forecasts, records, outputs
def test_forecast_errors_grow_with_the_horizon(result):
    for est in ("diffuse-rls", "sliding-diffuse-rls", "ekf", "ukf"):
        for metric in ("forecast_error_azimuth", "forecast_error_elevation"):
            e = [_rec(result, est, metric, steps=k)["mean"] for k in (1, 10, 30)]
            assert e[0] < e[1] < e[2], (est, metric, e)


def test_every_estimator_and_metric_has_a_record_with_paper_values_from_table_2(result):
    for est in us.ESTIMATORS:
        for metric, unit in us.TABLE_METRICS:
            assert _rec(result, est, metric)["unit"] == unit
        assert _rec(result, est, "rmse_position_over_crlb")["stderr"] is not None
    assert _rec(result, "geometry", "rmse_y")["paper"] == 31.0
    assert _rec(result, "diffuse-rls", "bias_x")["paper"] == -0.74
    assert _rec(result, "diffuse-rls", "rmse_azimuth")["paper"] == 0.57
    assert _rec(result, "ekf", "rmse_x")["paper"] is None
    doc = json.loads(json.dumps(result.to_json()))
    assert doc["scenario"] == "uav-sea" and doc["runs"] == RUNS and doc["seed"] == 0
    assert {"estimator", "metric", "unit", "mean", "stderr", "paper", "params"} <= set(
        doc["results"][0]
    )


def test_bias_is_truth_minus_estimate():
    m = us.simulate(runs=1, seed=0)
    est = us.estimate("geometry", m.azimuth, m.elevation, m.platform)
    shifted = us.Estimates(est.position + np.array([1.0, -2.0]), est.azimuth, est.elevation)
    a = us._table_metrics(est, m)
    b = us._table_metrics(shifted, m)
    assert b["bias_x"][0] == pytest.approx(a["bias_x"][0] - 1.0)
    assert b["bias_y"][0] == pytest.approx(a["bias_y"][0] + 2.0)


def test_outputs_table2_and_plots_are_written(result):
    names = {p.name for p in result.outputs}
    assert {"table2.csv", "position_error.png", "impulse.png", "close_range.png"} <= names
    for p in result.outputs:
        assert p.stat().st_size > 0
    table = next(p for p in result.outputs if p.name == "table2.csv")
    rows = {r["estimator"]: r for r in csv.DictReader(table.open())}
    assert float(rows["geometry"]["rmse_x_paper"]) == 20.7
    assert float(rows["diffuse-rls"]["rmse_elevation_paper"]) == 1.14
    assert float(rows["geometry"]["rmse_x_m"]) == pytest.approx(
        _rec(result, "geometry", "rmse_x")["mean"], abs=1e-4
    )
    assert "crlb" in rows and "diffuse-rls (model)" in rows


def test_progress_is_reported_up_to_completion(result):
    assert len(PROGRESS) > 5
    assert [d for d, _ in PROGRESS] == list(range(1, len(PROGRESS) + 1))
    assert PROGRESS[-1][0] == PROGRESS[-1][1]


# ------------------------------------------------------------------ bad input
def test_bad_inputs_raise_value_errors_naming_the_argument():
    with pytest.raises(ValueError, match="runs"):
        us.run(runs=0)
    with pytest.raises(ValueError, match="filtered"):
        us.run(runs=1, filtered="bogus")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="seed"):
        us.simulate(runs=1, seed=-1)
    m = us.simulate(runs=1, seed=0)
    with pytest.raises(ValueError, match="name"):
        us.estimate("kalman", m.azimuth, m.elevation, m.platform)
    with pytest.raises(ValueError, match="platform"):
        us.estimate("geometry", m.azimuth, m.elevation, m.platform[:, :5])
