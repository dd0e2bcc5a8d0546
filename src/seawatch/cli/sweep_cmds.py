"""``seawatch sweep`` and the Dask options of ``seawatch experiment`` (issue 8, "Scale").

Plain typer-compatible functions; the lead registers them in ``cli/__init__.py``.
:func:`experiment_parallel` is what ``seawatch experiment NAME --workers W --scheduler
ADDR`` calls (see its docstring for the wiring).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.table import Table

from seawatch.cli._common import (
    EXIT_FAILED,
    BadInput,
    emit_json,
    err,
    exit_codes,
    progress_bar,
)
from seawatch.scenarios.base import ExperimentResult, ProgressCallback

__all__ = ["experiment_parallel", "sweep"]


def experiment_parallel(
    name: str,
    *,
    runs: int | None = None,
    seed: int = 0,
    out_dir: Path | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: ProgressCallback | None = None,
    **options: Any,
) -> ExperimentResult:
    """Run experiment *name* with its Monte-Carlo chunks on Dask (``--workers``,
    ``--scheduler``); the records are bit-identical to a single-process run.

    For ``seawatch experiment``: add the two options and replace its ``run(...)`` call::

        workers: Annotated[int | None, typer.Option(
            help="Dask worker processes (default: the machine's cores).", min=1)] = None,
        scheduler: Annotated[str | None, typer.Option(
            help="Existing Dask scheduler, e.g. tcp://HOST:8786.")] = None,
        ...
        result = sweep_cmds.experiment_parallel(
            name, workers=workers, scheduler=scheduler,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
            **kwargs,   # seed, out_dir, runs and table as now
        )

    (``registry.runner(name)`` and ``registry.options(name)`` stay as they are for the
    ``--table`` check.) A scheduler that does not answer raises SchedulerError, a
    ValueError, within ``DEFAULT_TIMEOUT_S`` (5 s): ``exit_codes()`` turns it into exit
    2 with the message. ``workers`` None: a local cluster on the machine's cores when
    the experiment is large enough (``PARALLEL_MIN_UNITS`` of the scenario), else one
    process; ``workers=1``: one process, no Dask. Experiments without the chunk/merge
    protocol run in one process (``--workers``/``--scheduler`` then exit 2).

    Args:
        name: experiment name.
        runs, seed, out_dir, progress: as for the scenario's ``run``; ``progress(done,
            total)`` counts chunks on a cluster.
        workers: local worker processes.
        scheduler: address of an existing Dask scheduler.
        **options: the scenario's options (e.g. ``table`` for clutter-tbd).
    """
    from seawatch.scenarios import parallel

    return parallel.run_experiment(
        name,
        runs,
        seed,
        out_dir,
        progress,
        workers=workers,
        scheduler=scheduler,
        **options,
    )


def sweep(
    name: Annotated[str, typer.Argument(help="Experiment name, e.g. uav-sea, air-range.")],
    param: Annotated[
        list[str] | None,
        typer.Option(
            "--param",
            "-p",
            help="Grid parameter NAME=v1,v2,… (repeatable; an option of the experiment, or "
            "runs / seed).",
        ),
    ] = None,
    runs: Annotated[
        int | None, typer.Option(help="Monte-Carlo runs per point (scenario default).", min=1)
    ] = None,
    seed: Annotated[int, typer.Option(help="Random seed of every point.")] = 0,
    workers: Annotated[
        int | None,
        typer.Option(help="Dask worker processes (default: the machine's cores).", min=1),
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Existing Dask scheduler, e.g. tcp://HOST:8786.")
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Folder for sweep.csv (written as points complete)."),
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print the sweep JSON.")] = False,
) -> None:
    """Run an experiment at every point of a parameter grid, all points in parallel.

    Every combination of the ``--param`` values is one point; all points' Monte-Carlo
    chunks run at once on a local Dask cluster (``--workers``) or an existing one
    (``--scheduler``). ``sweep.csv`` in ``--out`` gets every record (estimator, metric,
    mean ± standard error, the paper's value) with the grid parameters as columns, as
    each point completes. A point that fails is reported with its error and the others
    are kept; the exit code is then 1.

    Example: [cyan]seawatch sweep uav-sea --param height=3,10,30 --param
    sigma_azimuth_arcmin=0.5,0.88,2 --runs 100 --out out/sweep[/]
    """
    from seawatch.scenarios import parallel, registry

    with exit_codes():
        registry.runner(name)  # NAME: unknown experiment
        if not param:
            raise BadInput("--param: give at least one grid parameter, e.g. --param height=3,10")
        grid = parallel.parse_params(name, param)
        done_points: list[parallel.SweepPoint] = []
        with progress_bar() as bar:
            task = bar.add_task(f"sweep {name}", total=None)

            def on_point(point: parallel.SweepPoint) -> None:
                done_points.append(point)
                bar.update(task, description=f"sweep {name}: {len(done_points)} points done")
                if not point.ok:
                    err.print(
                        f"[yellow]point {point.index} {_fmt_params(point.params)} failed:[/] "
                        f"{escape(point.error or '')}"
                    )

            result = parallel.sweep(
                name,
                grid,
                runs=runs,
                seed=seed,
                workers=workers,
                scheduler=scheduler,
                out_dir=out,
                progress=lambda d, t: bar.update(task, completed=d, total=t),
                on_point=on_point,
            )
        if json_out:
            emit_json(result.to_json())
        else:
            view = Table(title=f"sweep {name}: {len(result.points)} points")
            for key in grid:
                view.add_column(key, justify="right")
            view.add_column("status")
            view.add_column("records / error")
            for p in result.points:
                detail = (
                    str(len(p.result.results)) if p.result is not None else escape(p.error or "")
                )
                view.add_row(*(str(p.params[k]) for k in grid), "ok" if p.ok else "failed", detail)
            err.print(view)
            for path in result.outputs:
                typer.echo(f"wrote {path}")
        if result.failed:
            err.print(
                f"[bold red]failed:[/] {len(result.failed)} of {len(result.points)} points "
                "(the others are kept)"
            )
            raise typer.Exit(EXIT_FAILED)


def _fmt_params(params: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v}" for k, v in params.items())
