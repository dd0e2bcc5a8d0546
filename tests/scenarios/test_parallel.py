"""Monte-Carlo runs on Dask (seawatch.scenarios.parallel; issue 8, "Scale").

The records must be bit-identical for the same seed whatever the number of workers or
the chunking: one process against a 2-worker LocalCluster (one cluster for the module),
against a ``dask scheduler`` + ``dask worker`` started here on 127.0.0.1, and chunk by
chunk for every scenario of the protocol. An unreachable scheduler fails within 10 s;
a sweep keeps the points that run and reports the one that fails.
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import socket
import subprocess
import sys
import time

import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.scenarios import air_range, clutter_tbd, parallel, stereo_ferry, uav_sea
from seawatch.scenarios.base import ExperimentResult, record

pytest.importorskip("distributed")

UAV = {"impulse": False}  # the impulse case adds nothing to the parallel machinery
UAV_RUNS = 25  # an aligned block of 20 and a last one of 5


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def cluster():
    """One 2-worker LocalCluster for the module (start-up costs a few seconds)."""
    with parallel._local_client(2) as client:
        yield client


@pytest.fixture(scope="module")
def air_single():
    return parallel.run_experiment("air-range", runs=7, seed=3, workers=1)


# ------------------------------------------------------------------ chunk planning
@given(
    units=st.integers(1, 500),
    tasks=st.integers(1, 40),
    align=st.sampled_from([1, 7, 20, 50]),
    chunk=st.one_of(st.none(), st.integers(1, 60)),
)
def test_plan_covers_every_unit_once_in_order_with_aligned_starts(units, tasks, align, chunk):
    chunks = parallel.plan_chunks(units, tasks, chunk=chunk, align=align, max_size=100)
    assert [i for c in chunks for i in c] == list(range(units))
    assert all(len(c) > 0 and c.start % align == 0 for c in chunks)
    if chunk is None:
        assert len(chunks) <= max(tasks, -(-units // max(align, 100 // align * align)))


def test_cost_plan_gives_expensive_units_their_own_chunks():
    costs = [100.0, 100.0, *([1.0] * 200)]
    chunks = parallel.plan_chunks(len(costs), 4, costs=costs)
    assert chunks[0] == range(0, 1) and chunks[1] == range(1, 2)
    assert [i for c in chunks for i in c] == list(range(202))


# ------------------------------------------------------------------ chunking invariance
def test_air_range_records_do_not_depend_on_the_chunking():
    whole = air_range.merge([air_range.chunk(range(5), 5, 11)], 5, 11)
    parts = [air_range.chunk(c, 5, 11) for c in (range(0, 1), range(1, 2), range(2, 5))]
    assert air_range.merge(parts, 5, 11).results == whole.results
    # and the runs are the scenario's own: the same as its single-process run()
    assert air_range.run(5, 11).records == whole.results


@pytest.mark.parametrize("variant", ["matched", "stereo-prior"])
def test_stereo_ferry_records_and_diagnostics_do_not_depend_on_the_chunking(variant):
    opts = {"experiment": 2, "variant": variant}
    whole = stereo_ferry.merge([stereo_ferry.chunk(range(4), 4, 2, **opts)], 4, 2, **opts)
    parts = [stereo_ferry.chunk(c, 4, 2, **opts) for c in (range(0, 1), range(1, 4))]
    split = stereo_ferry.merge(parts, 4, 2, **opts)
    assert split.results == whole.results
    assert split.extra == whole.extra


def test_clutter_tbd_units_are_rows_and_sequences_and_do_not_depend_on_the_chunking():
    opts = {"table": "all", "clutter_levels": [100]}
    n = clutter_tbd.units(20, **opts)
    assert n == 1 + 2 + 3 * 2  # one Table 2 row, 2 Table 1 sequences, 3 cases × 2
    whole = clutter_tbd.merge([clutter_tbd.chunk(range(n), 20, 4, **opts)], 20, 4, **opts)
    parts = [clutter_tbd.chunk(c, 20, 4, **opts) for c in (range(0, 2), range(2, 5), range(5, n))]
    assert clutter_tbd.merge(parts[::-1], 20, 4, **opts).results == whole.results
    with pytest.raises(ValueError, match="missing"):
        clutter_tbd.merge(parts[:2], 20, 4, **opts)


# ------------------------------------------------------------------ workers
def test_air_range_one_worker_and_two_workers_give_identical_records(cluster, air_single):
    calls = []
    two = parallel.run_experiment(
        "air-range",
        runs=7,
        seed=3,
        scheduler=cluster,
        chunk=2,
        progress=lambda d, t: calls.append((d, t)),
    )
    assert two.results == air_single.results
    assert two.runs == 7 and two.seed == 3
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]  # chunks completed / total


def test_uav_sea_two_local_workers_match_one_process(cluster, monkeypatch, tmp_path):
    started = []

    def local_client(workers):  # the module's cluster stands in for a new LocalCluster
        started.append(workers)
        return contextlib.nullcontext(cluster)

    monkeypatch.setattr(parallel, "_local_client", local_client)
    one = parallel.run_experiment("uav-sea", runs=UAV_RUNS, seed=2, workers=1, **UAV)
    assert started == []  # one worker: in this process, no Dask
    # chunks [0, 20) and [20, 25): sums over runs are kept per aligned block of 20
    two = parallel.run_experiment(
        "uav-sea", runs=UAV_RUNS, seed=2, workers=2, chunk=20, out_dir=tmp_path, **UAV
    )
    assert started == [2]
    assert two.results == one.results
    assert two.extra == one.extra
    assert {p.name for p in two.outputs} >= {"table2.csv", "position_error.png"}
    assert one.find("geometry", "rmse_x")["paper"] == 20.7


def test_a_scenario_error_on_a_worker_is_raised_with_its_type(cluster):
    with pytest.raises(ValueError, match="height"):
        parallel.run_experiment("uav-sea", runs=2, seed=0, scheduler=cluster, height=-1.0)


def test_dask_scheduler_and_worker_started_here_give_the_same_records(tmp_path, air_single):
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    procs = []
    try:
        procs.append(
            subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "distributed.cli.dask_scheduler",
                    "--host",
                    "127.0.0.1",
                    "--port",
                    str(port),
                    "--no-dashboard",
                ],
                cwd=tmp_path,
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        procs.append(
            subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "distributed.cli.dask_worker",
                    address,
                    "--nworkers",
                    "1",
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                    "--local-directory",
                    str(tmp_path),
                ],
                cwd=tmp_path,
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        try:
            res = parallel.run_experiment(
                "air-range", runs=7, seed=3, scheduler=address, chunk=3, timeout=30.0
            )
        except parallel.SchedulerError as exc:
            if any(p.poll() is not None for p in procs):
                pytest.skip(f"dask scheduler/worker could not start: {exc}")
            raise
        assert res.results == air_single.results
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def test_unreachable_scheduler_fails_within_10_s_with_a_clear_message():
    address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
    t0 = time.monotonic()
    with pytest.raises(parallel.SchedulerError, match="no Dask scheduler answered") as info:
        parallel.run_experiment("air-range", runs=3, scheduler=address)
    assert time.monotonic() - t0 < 10.0
    assert address in str(info.value)
    assert isinstance(info.value, ValueError)  # exit code 2 on the command line


def test_bad_names_options_and_worker_counts_raise_value_errors_naming_them():
    with pytest.raises(ValueError, match="NAME"):
        parallel.run_experiment("no-such-experiment", runs=2)
    with pytest.raises(ValueError, match="bogus"):
        parallel.run_experiment("uav-sea", runs=2, bogus=1)
    with pytest.raises(ValueError, match="workers"):
        parallel.run_experiment("air-range", runs=2, workers=0)
    with pytest.raises(ValueError, match="runs"):
        parallel.run_experiment("air-range", runs=0, workers=1)
    with pytest.raises(ValueError, match="scheduler"):
        parallel.run_experiment("air-range", runs=2, scheduler="")


# ------------------------------------------------------------------ sweeps
def test_sweep_keeps_the_good_points_and_reports_the_failing_ones(cluster, tmp_path):
    seen = []
    res = parallel.sweep(
        "uav-sea",
        {"height": [3.0, -1.0], "sigma_azimuth_arcmin": [0.88, 2.0]},
        runs=2,
        seed=5,
        scheduler=cluster,
        out_dir=tmp_path,
        on_point=seen.append,
        **UAV,
    )
    assert [p.params for p in res.points] == [
        {"height": 3.0, "sigma_azimuth_arcmin": 0.88},
        {"height": 3.0, "sigma_azimuth_arcmin": 2.0},
        {"height": -1.0, "sigma_azimuth_arcmin": 0.88},
        {"height": -1.0, "sigma_azimuth_arcmin": 2.0},
    ]
    assert [p.ok for p in res.points] == [True, True, False, False]
    assert all("ValueError" in p.error and "height" in p.error for p in res.failed)
    assert sorted(p.index for p in seen) == [0, 1, 2, 3]
    # a good point is exactly the experiment run alone with those options
    alone = uav_sea.run(runs=2, seed=5, sigma_azimuth_arcmin=2.0, **UAV)
    assert res.points[1].result.results == alone.results
    # the paper's values go with the paper's set-up only
    assert res.points[0].result.find("geometry", "rmse_x")["paper"] == 20.7
    assert res.points[1].result.find("geometry", "rmse_x")["paper"] is None
    with (tmp_path / "sweep.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0])[:3] == ["height", "sigma_azimuth_arcmin", "point"]
    good = [r for r in rows if r["status"] == "ok"]
    assert len(good) == 2 * len(alone.results)
    bad = [r for r in rows if r["status"] == "failed"]
    assert len(bad) == 2 and all("height" in r["error"] for r in bad)
    rec = next(r for r in good if r["point"] == "1" and r["estimator"] == "ekf"
               and r["metric"] == "rmse_x")  # fmt: skip
    assert float(rec["mean"]) == alone.find("ekf", "rmse_x")["mean"]
    doc = json.loads((tmp_path / "sweep.json").read_text())
    assert doc["failed"] == 2 and doc["grid"]["height"] == [3.0, -1.0]


def test_sweep_in_one_process_gives_the_same_points_as_on_the_cluster(cluster):
    grid = {"seed": [1], "runs": [2, 0]}
    local = parallel.sweep("air-range", grid, workers=1)
    remote = parallel.sweep("air-range", grid, scheduler=cluster)
    for a, b in zip(local.points, remote.points, strict=True):
        assert a.params == b.params and a.ok == b.ok
    assert [p.ok for p in local.points] == [True, False]
    assert local.points[0].result.results == remote.points[0].result.results
    assert local.points[0].result.results == air_range.experiment(2, 1).results
    for p in (local.points[1], remote.points[1]):
        assert p.error.startswith("ValueError: runs")


def test_sweep_rejects_an_empty_grid_and_unknown_parameters():
    with pytest.raises(ValueError, match="params"):
        parallel.sweep("air-range", {})
    with pytest.raises(ValueError, match="height"):
        parallel.sweep("air-range", {"height": [1.0]})
    with pytest.raises(ValueError, match="impulse"):
        parallel.sweep("uav-sea", {"impulse": []})


def test_parse_params_types_values_from_the_scenario_defaults():
    grid = parallel.parse_params(
        "uav-sea", ["height=3,10", "impulse=false,true", "filtered=fitted", "seed=1,2"]
    )
    assert grid == {
        "height": [3.0, 10.0],
        "impulse": [False, True],
        "filtered": ["fitted"],
        "seed": [1, 2],
    }
    assert all(isinstance(v, float) for v in grid["height"])
    assert parallel.parse_params("clutter-tbd", ["table=1,2"]) == {"table": ["1", "2"]}
    assert parallel.parse_params("uav-sea", ["sigma-azimuth-arcmin=1"]) == {
        "sigma_azimuth_arcmin": [1.0]
    }
    for bad in ("height", "height=", "=3", "height=3,,4", "height=abc", "nope=1", "seed=1.5"):
        with pytest.raises(ValueError, match="--param"):
            parallel.parse_params("uav-sea", [bad])
    with pytest.raises(ValueError, match="twice"):
        parallel.parse_params("uav-sea", ["height=1", "height=2"])


def test_rows_hold_every_record_with_the_grid_columns():
    recs = [record("kf", "rmse_x", "m", [1.0, 3.0]), record("kf", "rmse_y", "m", [2.0])]
    point = parallel.SweepPoint(0, {"seed": 1}, result=ExperimentResult("x", 2, 1, recs))
    failed = parallel.SweepPoint(1, {"seed": 2}, error="ValueError: x")
    res = parallel.SweepResult("x", 2, 0, {"seed": [1, 2]}, [point, failed])
    rows = res.rows()
    assert len(rows) == 3
    assert rows[0] == {
        "seed": 1, "point": 0, "status": "ok", "error": None, "estimator": "kf",
        "metric": "rmse_x", "params": {}, "unit": "m", "mean": 2.0, "stderr": 1.0, "paper": None,
    }  # fmt: skip
    assert rows[-1] == {
        "seed": 2, "point": 1, "status": "failed", "error": "ValueError: x", "estimator": None,
        "metric": None, "params": None, "unit": None, "mean": None, "stderr": None, "paper": None,
    }  # fmt: skip
    doc = res.to_json()
    assert doc["failed"] == 1 and doc["points"][1]["status"] == "failed"
    assert doc["points"][0]["results"] == recs
