"""``seawatch bench world``: the benchmark JSON at a small size and its agreement check.

Speed is measured by the benchmark (it replaced a timed unit test of the per-frame cost),
never asserted here; the checks are the documented JSON shape, the batched EKF equal to one
library ExtendedKalmanFilter per track, and the scenario's angles against the geometry.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from seawatch.bench import world
from seawatch.cli import app
from seawatch.geometry import sea_position


@pytest.fixture(scope="module")
def small():
    labels: list[str] = []
    doc = world.run(80, tracks=4, reference_frames=70, repeats=1, progress=labels.append)
    return doc, labels


def test_small_run_returns_the_benchmark_json_with_positive_speeds(small):
    doc, labels = small
    assert doc["benchmark"] == "world"
    names = [r["name"] for r in doc["results"]]
    assert names == ["seawatch.world.ekf", "seawatch.world.all", "per_track_ekf"]
    assert labels == names
    speed = {r["name"]: r["value"] for r in doc["results"]}
    assert all(math.isfinite(v) and v > 0 for v in speed.values())
    for k in ("seawatch.world.ekf", "seawatch.world.all"):
        assert doc["ratios"][f"{k}/per_track_ekf"] == pytest.approx(
            speed[k] / speed["per_track_ekf"]
        )
        assert doc["ms_per_frame"][k] == pytest.approx(1000.0 / speed[k])
    for t in doc["targets"].values():
        assert t["kind"] == "upper bound" and t["met"] == (t["measured"] <= t["target"])
    assert doc["problem"]["tracks"] == 4 and doc["problem"]["reference_frames"] == 70


def test_batched_ekf_equals_one_library_filter_per_track(small):
    doc, _ = small
    agree = doc["agreement"]
    assert agree["ok"] and agree["max_rel_diff"] <= world.AGREEMENT_RTOL
    assert agree["max_rel_diff_between_variants"] <= world.AGREEMENT_RTOL


def test_scenario_angles_invert_to_the_truth_within_the_noise():
    t, truth, az, dep = world.scenario(40, 5, seed=3)
    assert t.shape == (40,) and truth.shape == (40, 5, 2) and az.shape == dep.shape == (40, 5)
    fix = sea_position((0.0, 0.0), 0.0, az, dep, world.HEIGHT, curved=True)
    rng = np.hypot(truth[..., 0], truth[..., 1])
    # 1 px of depression noise at 0.5-3 km from 10 m: a few % of range, never 30 %
    rel = np.abs(fix.range - rng) / rng
    assert np.median(rel) < 0.1 and np.all(np.isfinite(fix.xy))
    np.testing.assert_allclose(
        np.cos(az - np.arctan2(truth[..., 1], truth[..., 0])), 1.0, atol=1e-5
    )


def test_too_few_frames_is_a_value_error_naming_frames():
    with pytest.raises(ValueError, match="frames"):
        world.run(world.WARMUP)


def test_cli_prints_the_json_and_upper_bound_targets():
    res = CliRunner().invoke(app, ["bench", "world", "--size", "60", "--repeats", "1", "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["benchmark"] == "world" and doc["problem"]["frames"] == 60
