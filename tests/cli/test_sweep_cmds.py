"""``seawatch sweep`` (seawatch.cli.sweep_cmds on a tiny Typer app) and the
``experiment_parallel`` helper of ``seawatch experiment --workers/--scheduler``: grids in,
one CSV row per record out, a failing point reported and the others kept; malformed
``--param`` and an unreachable scheduler exit 2 (INTERFACES.md exit codes)."""

from __future__ import annotations

import csv
import json
import socket
import time

import pytest
import typer
from typer.testing import CliRunner

from seawatch.cli._common import exit_codes
from seawatch.cli.sweep_cmds import experiment_parallel, sweep
from seawatch.scenarios import air_range, parallel

app = typer.Typer()
app.command("sweep")(sweep)


@app.command("experiment")
def _experiment(
    name: str,
    runs: int = 2,
    workers: int | None = None,
    scheduler: str | None = None,
) -> None:
    """The wiring described in experiment_parallel's docstring, reduced to the essentials."""
    with exit_codes():
        res = experiment_parallel(name, runs=runs, workers=workers, scheduler=scheduler)
        typer.echo(json.dumps(res.to_json()))


runner = CliRunner()


def said(result) -> str:
    """stderr with rich's line wrapping undone."""
    return " ".join(result.stderr.split())


def free_address() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp://127.0.0.1:{s.getsockname()[1]}"


@pytest.mark.parametrize(
    ("spec", "named"),
    [
        ("height", "height"),
        ("height=", "height="),
        ("=3", "=3"),
        ("height=3,,4", "height=3,,4"),
        ("height=abc", "abc"),
        ("bogus=1,2", "bogus"),
        ("impulse=maybe", "maybe"),
    ],
)
def test_malformed_param_exits_2_naming_it(spec, named):
    res = runner.invoke(app, ["sweep", "uav-sea", "--param", spec, "--workers", "1"])
    assert res.exit_code == 2, res.output
    assert "--param" in said(res) and named in said(res)


def test_missing_param_and_unknown_experiment_exit_2():
    res = runner.invoke(app, ["sweep", "uav-sea"])
    assert res.exit_code == 2 and "--param" in said(res)
    res = runner.invoke(app, ["sweep", "no-such", "--param", "seed=1"])
    assert res.exit_code == 2 and "no-such" in said(res)


def test_sweep_reports_the_failing_point_keeps_the_others_and_writes_the_csv(tmp_path):
    out = tmp_path / "sweep"
    res = runner.invoke(
        app,
        ["sweep", "air-range", "--param", "runs=2,0", "--param", "seed=4", "--workers", "1",
         "--out", str(out), "--json"],
    )  # fmt: skip
    assert res.exit_code == 1, res.output  # one point failed: the sweep did not fully succeed
    doc = json.loads(res.stdout)
    assert doc["grid"] == {"runs": [2, 0], "seed": [4]}
    ok, bad = doc["points"]
    assert ok["status"] == "ok" and ok["params"] == {"runs": 2, "seed": 4}
    assert bad["status"] == "failed" and "runs" in bad["error"] and bad["results"] == []
    assert doc["failed"] == 1
    alone = air_range.experiment(2, 4)
    assert ok["results"] == json.loads(json.dumps(alone.results))
    assert "point 1" in said(res) and "failed" in said(res)
    with (out / "sweep.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0])[:2] == ["runs", "seed"]
    assert len(rows) == len(alone.results) + 1
    first = next(r for r in rows if r["estimator"] == "ancv" and r["metric"] == "rmse_range")
    assert first["runs"] == "2" and first["status"] == "ok"
    assert float(first["mean"]) == alone.find("ancv", "rmse_range")["mean"]
    assert sorted(doc["outputs"]) == sorted([str(out / "sweep.csv"), str(out / "sweep.json")])


def test_sweep_table_output_without_json(tmp_path):
    res = runner.invoke(app, ["sweep", "air-range", "-p", "seed=1,2", "--runs", "2",
                              "--workers", "1", "--out", str(tmp_path)])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "wrote" in res.stdout and "sweep.csv" in res.stdout
    assert "seed" in said(res) and "ok" in said(res)


def test_sweep_to_an_unreachable_scheduler_exits_2_within_10_s():
    address = free_address()
    t0 = time.monotonic()
    res = runner.invoke(app, ["sweep", "air-range", "-p", "seed=1", "--scheduler", address])
    assert time.monotonic() - t0 < 10.0
    assert res.exit_code == 2, res.output
    assert address in said(res) and "scheduler" in said(res)


def test_experiment_helper_runs_in_one_process_and_rejects_a_silent_scheduler():
    res = runner.invoke(app, ["experiment", "air-range", "--runs", "2", "--workers", "1"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["results"] == json.loads(json.dumps(air_range.experiment(2, 0).results))
    t0 = time.monotonic()
    with pytest.raises(parallel.SchedulerError, match="no Dask scheduler answered"):
        experiment_parallel("air-range", runs=2, scheduler=free_address(), timeout=1.0)
    assert time.monotonic() - t0 < 10.0
    res = runner.invoke(app, ["experiment", "air-range", "--workers", "0"])
    assert res.exit_code == 2 and "workers" in said(res)
