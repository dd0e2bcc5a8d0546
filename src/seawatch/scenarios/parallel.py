"""Monte-Carlo runs and parameter sweeps in parallel with Dask (issue 8, "Scale").

:func:`run_experiment` splits an experiment's work into chunks, each a contiguous range
of run indices, runs them as Dask tasks — on a ``distributed.LocalCluster`` with one
single-threaded worker process per core by default, or on an existing cluster given by
its scheduler address, unchanged — and merges the per-run values into the records
exactly as a single process would: **the records are bit-identical for the same seed
whatever the number of workers or the chunking** (tests/scenarios/test_parallel.py
checks 1 worker against 2, and a ``dask scheduler`` + ``dask worker`` started on
127.0.0.1). :func:`sweep` runs an experiment at every point of a parameter grid, all
points' chunks at once; a point that fails is reported with its error and the others
are kept.

The protocol a scenario module follows to run in parallel (``air_range``, ``uav_sea``,
``stereo_ferry``, ``clutter_tbd``, ``solent_ais`` and ``ship_video`` do; a module without
it runs in one process):

``chunk(indices, runs, seed, *, progress=None, **options) -> payload``
    Computes the work units ``indices`` (a ``range``, increasing; by default the
    Monte-Carlo runs) and returns a picklable payload of *per-run* values (and sums
    over aligned blocks of runs, see ``CHUNK_ALIGN``). Unit i draws only from its own
    random stream, ``numpy.random.SeedSequence(seed, spawn_key=(…, i))``, and the
    estimators must treat the runs of a vectorised batch independently, so a unit's
    values do not depend on the chunk it is computed in. ``runs`` is the total (a
    unit may need it, e.g. clutter-tbd's frames per table row). ``progress(done,
    total)`` is the scenario's own, used when the whole experiment runs in-process.
``merge(payloads, runs, seed, out_dir=None, **options) -> ExperimentResult``
    The records (mean and standard error over runs, INTERFACES.md) and the outputs in
    ``out_dir`` from the payloads, given in chunk order. The scenario's ``run()`` is
    ``merge([chunk(range(units))])``, so both paths share the code.
``units(runs, **options) -> int`` (optional, default ``runs``)
    The number of work units when they are not the runs (clutter-tbd: Table 2 rows,
    Table 1 sequences, case sequences).
``unit_costs(runs, **options) -> array`` (optional)
    Relative cost of each unit: chunks are then cut to equal cost rather than equal
    size (clutter-tbd's Table 2 rows cost ~100× a sequence).
``CHUNK_ALIGN`` (optional, default 1)
    Sums over runs kept in a payload (means over runs of per-frame curves, the uav-sea
    bound's information) are taken over aligned blocks ``[k·A, (k+1)·A)`` and added in
    block order by ``merge``; the planner starts every chunk on a multiple of A, so
    those sums, too, do not depend on the chunking.
``CHUNK_MAX``, ``CHUNK_MIN`` (optional)
    The largest chunk the default plan makes (memory of one vectorised block) and the
    smallest (a chunk has a fixed cost: uav-sea's per-step filter loops cost as much
    as ~100 runs).
``PARALLEL_MIN_COST`` (optional, default 0)
    With ``workers`` left at its default, an experiment whose total cost (its runs, or
    the sum of ``unit_costs``) is below this runs in one process: a local cluster takes
    5–10 s to start and to import seawatch in its workers.

Options that are values of the scenario's ``run()`` (``registry.options(name)``) pass
through to ``chunk`` and ``merge`` (both accept them all).
"""

from __future__ import annotations

import contextlib
import csv
import importlib
import inspect
import itertools
import json
import logging
import math
import os
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from seawatch._validation import integer
from seawatch.scenarios import registry
from seawatch.scenarios.base import ExperimentResult, ProgressCallback

__all__ = [
    "DEFAULT_TIMEOUT_S",
    "SchedulerError",
    "SweepPoint",
    "SweepResult",
    "dask_client",
    "default_workers",
    "parse_params",
    "plan_chunks",
    "run_experiment",
    "supports_parallel",
    "sweep",
]

DEFAULT_TIMEOUT_S = 5.0
"""How long to try to reach a scheduler (and to wait for its first worker) [s]."""
TASKS_PER_WORKER = 2
"""Chunks per worker in the default plan (load balance and progress granularity against
the fixed cost of a chunk)."""
SWEEP_CSV = "sweep.csv"
SWEEP_JSON = "sweep.json"


class SchedulerError(ValueError):
    """The Dask scheduler given by address does not answer or has no workers (exit 2)."""


# ------------------------------------------------------------------------------------
# scenarios
# ------------------------------------------------------------------------------------


def _module(name: str) -> ModuleType:
    registry.runner(name)  # ValueError naming an unknown experiment
    return importlib.import_module(registry.SCENARIOS[name][0])


def supports_parallel(name: str) -> bool:
    """Whether experiment *name* follows the chunk/merge protocol (module docstring)."""
    mod = _module(name)
    return callable(getattr(mod, "chunk", None)) and callable(getattr(mod, "merge", None))


def _default_runs(name: str, mod: ModuleType) -> int | None:
    param = inspect.signature(registry.runner(name)).parameters.get("runs")
    default = None if param is None else param.default
    if isinstance(default, int) and not isinstance(default, bool):
        return default
    return getattr(mod, "DEFAULT_RUNS", None)


def _check_options(name: str, options: dict[str, Any]) -> None:
    allowed = registry.options(name)
    for key in options:
        if key not in allowed:
            known = ", ".join(sorted(allowed)) or "none"
            raise ValueError(f"{key}: experiment {name!r} has no option {key!r} (options: {known})")


def _units(mod: ModuleType, runs: int | None, options: dict[str, Any]) -> int:
    if hasattr(mod, "units"):
        return int(mod.units(runs, **options))
    return integer("runs", runs, 1)


def default_workers() -> int:
    """The machine's cores available to this process."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


# ------------------------------------------------------------------------------------
# chunk planning
# ------------------------------------------------------------------------------------


def plan_chunks(
    units: int,
    tasks: int,
    *,
    chunk: int | None = None,
    align: int = 1,
    max_size: int | None = None,
    min_size: int | None = None,
    costs: Sequence[float] | np.ndarray | None = None,
) -> list[range]:
    """Split units 0 … units − 1 into contiguous chunks.

    Args:
        units: number of work units (≥ 1).
        tasks: the number of chunks wanted (the default plan: 2 per worker).
        chunk: fixed chunk size instead (rounded up to a multiple of ``align``).
        align: every chunk starts on a multiple of this (module docstring,
            ``CHUNK_ALIGN``).
        max_size, min_size: largest and smallest chunk of the default plan.
        costs: relative cost per unit: cut to equal cost instead of equal size.

    Returns:
        The chunks as ranges, in order, covering every unit once.
    """
    n = integer("units", units, 1)
    a = integer("align", align, 1)
    if chunk is not None:
        size = -(-integer("chunk", chunk, 1) // a) * a
        return [range(lo, min(lo + size, n)) for lo in range(0, n, size)]
    want = integer("tasks", tasks, 1)
    if costs is not None:
        c = np.asarray(costs, dtype=np.float64)
        if c.shape != (n,) or not np.all(np.isfinite(c)) or np.any(c < 0):
            raise ValueError(f"costs: expected {n} finite non-negative costs, got {c.shape}")
        target = c.sum() / want
        out: list[range] = []
        lo, acc = 0, 0.0
        for i in range(n):
            acc += c[i]
            end = i + 1
            if acc >= target and end % a == 0 and end < n:
                out.append(range(lo, end))
                lo, acc = end, 0.0
        out.append(range(lo, n))
        return out
    size = -(-n // want)
    if min_size is not None:
        size = max(size, int(min_size))
    if max_size is not None:
        size = min(size, max(a, int(max_size) // a * a))
    size = -(-size // a) * a
    return [range(lo, min(lo + size, n)) for lo in range(0, n, size)]


def _cost(mod: ModuleType, units: int, runs: int | None, options: dict[str, Any]) -> float:
    if hasattr(mod, "unit_costs"):
        return float(np.sum(mod.unit_costs(runs, **options)))
    return float(units)


def _plan(
    mod: ModuleType,
    units: int,
    runs: int | None,
    options: dict[str, Any],
    tasks: int,
    chunk: int | None,
) -> list[range]:
    costs = mod.unit_costs(runs, **options) if hasattr(mod, "unit_costs") else None
    return plan_chunks(
        units,
        tasks,
        chunk=chunk,
        align=int(getattr(mod, "CHUNK_ALIGN", 1)),
        max_size=getattr(mod, "CHUNK_MAX", None),
        min_size=getattr(mod, "CHUNK_MIN", None),
        costs=None if chunk is not None else costs,
    )


# ------------------------------------------------------------------------------------
# Dask
# ------------------------------------------------------------------------------------


def _chunk_task(
    name: str, indices: range, runs: int | None, seed: int, options: dict[str, Any]
) -> Any:
    """What a Dask worker runs: one chunk of experiment *name*."""
    return _module(name).chunk(indices, runs, seed, **options)


@contextlib.contextmanager
def _local_client(workers: int) -> Iterator[Any]:
    """A LocalCluster of ``workers`` single-threaded processes (numba on one thread each)."""
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",  # a free port: no clash with a cluster already running
        silence_logs=logging.CRITICAL,  # failures are reported by the caller, once
        env={"NUMBA_NUM_THREADS": "1"},
    )
    try:
        client = Client(cluster, set_as_default=False)
        try:
            yield client
        finally:
            client.close()
    finally:
        cluster.close()


@contextlib.contextmanager
def _remote_client(scheduler: Any, timeout: float) -> Iterator[Any]:
    """A client of the scheduler at address *scheduler* (or *scheduler* itself when it
    is already a ``distributed.Client``); SchedulerError if it does not answer within
    *timeout* seconds or has no worker."""
    from distributed import Client

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise SchedulerError(
            f"scheduler: expected an address like tcp://HOST:8786, got {scheduler!r}"
        )
    address = scheduler.strip()
    try:
        client = Client(address, timeout=timeout, set_as_default=False)
    except Exception as exc:  # OSError, TimeoutError, ValueError (bad address), ...
        raise SchedulerError(
            f"scheduler: no Dask scheduler answered at {address!r} within {timeout:g} s "
            f"({type(exc).__name__}: {exc})"
        ) from None
    try:
        try:
            client.wait_for_workers(1, timeout=timeout)
        except Exception:
            raise SchedulerError(
                f"scheduler: the Dask scheduler at {address!r} has no workers "
                f"(waited {timeout:g} s); start some with `dask worker {address}`"
            ) from None
        yield client
    finally:
        client.close()


@contextlib.contextmanager
def dask_client(
    workers: int | None = None, scheduler: Any = None, timeout: float = DEFAULT_TIMEOUT_S
) -> Iterator[Any]:
    """A Dask client: of the scheduler at ``scheduler`` (SchedulerError within ``timeout``
    seconds if it does not answer or has no worker), else of a local cluster of
    ``workers`` single-threaded processes (default: the machine's cores)."""
    if scheduler is not None:
        with _remote_client(scheduler, timeout) as client:
            yield client
    else:
        n = default_workers() if workers is None else integer("workers", workers, 1)
        with _local_client(n) as client:
            yield client


def _client_workers(client: Any) -> int:
    return max(1, int(sum(client.nthreads().values())))


def _gather_in_order(
    client: Any,
    tasks: list[tuple[str, range, int | None, int, dict[str, Any]]],
    progress: ProgressCallback | None,
) -> list[Any]:
    """Run the chunk tasks on the cluster; results in task order; the first failure
    cancels the rest and is raised (with its original type)."""
    from distributed import as_completed

    futures = [client.submit(_chunk_task, *t, pure=False) for t in tasks]
    where = {f.key: i for i, f in enumerate(futures)}
    out: list[Any] = [None] * len(futures)
    try:
        for done, fut in enumerate(as_completed(futures, loop=client.loop), start=1):
            out[where[fut.key]] = fut.result()
            if progress is not None:
                progress(done, len(futures))
    except BaseException:
        client.cancel(futures)
        raise
    return out


# ------------------------------------------------------------------------------------
# one experiment
# ------------------------------------------------------------------------------------


def run_experiment(
    name: str,
    runs: int | None = None,
    seed: int = 0,
    out_dir: str | Path | None = None,
    progress: ProgressCallback | None = None,
    workers: int | None = None,
    scheduler: Any = None,
    chunk: int | None = None,
    *,
    timeout: float = DEFAULT_TIMEOUT_S,
    **options: Any,
) -> ExperimentResult:
    """Run experiment *name* with its Monte-Carlo work spread over Dask workers.

    Args:
        name: experiment name (``seawatch.scenarios.registry``).
        runs: Monte-Carlo runs (the scenario's default if None).
        seed: random seed.
        out_dir: folder for the scenario's CSV tables and PNG plots (written by the
            merge, in this process).
        progress: ``progress(done, total)``: chunks completed / chunks (in-process
            without ``chunk``: the scenario's own steps).
        workers: worker processes of the local cluster (default: the machine's cores).
            ``workers=1`` without a scheduler, or a plan of a single chunk, runs
            in-process without Dask.
        scheduler: address of an existing Dask scheduler, ``"tcp://HOST:8786"``, or a
            ``distributed.Client``; the work is sent there unchanged (its workers must
            be able to import this version of seawatch). ``workers`` is then ignored.
        chunk: units per chunk (default: about 2 chunks per worker, aligned to the
            scenario's ``CHUNK_ALIGN``; the records do not depend on it).
        timeout: seconds to reach the scheduler and see its first worker.
        **options: the scenario's own options (``registry.options(name)``).

    Returns:
        The same ExperimentResult a single-process run gives (bit-identical records).

    Raises:
        ValueError: unknown experiment or option, bad ``workers``/``chunk``;
            SchedulerError (a ValueError) when the scheduler does not answer within
            ``timeout``; the scenario's own exceptions, with their type, from a chunk.
    """
    mod = _module(name)
    _check_options(name, options)
    if workers is not None:
        workers = integer("workers", workers, 1)
    if chunk is not None:
        chunk = integer("chunk", chunk, 1)
    if not supports_parallel(name):
        if scheduler is None and workers in (None, 1):
            kwargs: dict[str, Any] = {"seed": seed, "out_dir": out_dir, "progress": progress}
            if runs is not None:
                kwargs["runs"] = runs
            return registry.runner(name)(**kwargs, **options)
        raise ValueError(
            f"workers: experiment {name!r} runs in one process only (no chunk/merge); "
            "leave out --workers and --scheduler"
        )
    if runs is None:
        runs = _default_runs(name, mod)
    units = _units(mod, runs, options)
    if scheduler is None:
        w = default_workers() if workers is None else workers
        if workers is None and _cost(mod, units, runs, options) < getattr(
            mod, "PARALLEL_MIN_COST", 0
        ):
            w = 1  # too small to pay for a cluster
        chunks = _plan(mod, units, runs, options, TASKS_PER_WORKER * w, chunk)
        if w == 1 or len(chunks) == 1:
            if not chunk:  # one process, one chunk: the scenario's own run(), which may
                # write more as it goes (ship-video keeps its footage)
                return registry.runner(name)(
                    runs=runs, seed=seed, out_dir=out_dir, progress=progress, **options
                )
            return _in_process(mod, chunks, runs, seed, out_dir, progress, options)
        with _local_client(w) as client:
            return _on_cluster(mod, name, client, chunks, runs, seed, out_dir, progress, options)
    with _remote_client(scheduler, timeout) as client:
        tasks = TASKS_PER_WORKER * _client_workers(client)
        chunks = _plan(mod, units, runs, options, tasks, chunk)
        return _on_cluster(mod, name, client, chunks, runs, seed, out_dir, progress, options)


def _in_process(
    mod: ModuleType,
    chunks: list[range],
    runs: int | None,
    seed: int,
    out_dir: str | Path | None,
    progress: ProgressCallback | None,
    options: dict[str, Any],
) -> ExperimentResult:
    payloads = []
    for i, c in enumerate(chunks, start=1):
        payloads.append(mod.chunk(c, runs, seed, **options))
        if progress is not None:
            progress(i, len(chunks))
    return mod.merge(payloads, runs, seed, out_dir, **options)


def _on_cluster(
    mod: ModuleType,
    name: str,
    client: Any,
    chunks: list[range],
    runs: int | None,
    seed: int,
    out_dir: str | Path | None,
    progress: ProgressCallback | None,
    options: dict[str, Any],
) -> ExperimentResult:
    tasks = [(name, c, runs, seed, options) for c in chunks]
    payloads = _gather_in_order(client, tasks, progress)
    return mod.merge(payloads, runs, seed, out_dir, **options)


# ------------------------------------------------------------------------------------
# sweeps
# ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepPoint:
    """One grid point of a sweep.

    Attributes:
        index: position in the grid (row-major over the parameters in the order given).
        params: the grid parameters' values at this point.
        result: the experiment's result, or None if the point failed.
        error: ``"ExceptionType: message"`` if the point failed, else None.
    """

    index: int
    params: dict[str, Any]
    result: ExperimentResult | None = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        """Whether the point ran."""
        return self.error is None


@dataclass(frozen=True)
class SweepResult:
    """Outcome of :func:`sweep`.

    Attributes:
        scenario: experiment name.
        runs: runs per point (None: the scenario's default).
        seed: the seed of every point (unless swept).
        grid: the swept parameters and their values, in the order given.
        points: every grid point in grid order, failed ones with their error.
        outputs: ``sweep.csv`` (all records with the grid parameters as columns,
            written as points complete) and ``sweep.json``, when ``out_dir`` was given.
    """

    scenario: str
    runs: int | None
    seed: int
    grid: dict[str, list[Any]]
    points: list[SweepPoint]
    outputs: list[Path] = field(default_factory=list)

    @property
    def failed(self) -> list[SweepPoint]:
        """The points that failed."""
        return [p for p in self.points if not p.ok]

    def rows(self) -> list[dict[str, Any]]:
        """One row per record of every point (grid parameters first); one row with the
        error for a failed point."""
        out: list[dict[str, Any]] = []
        for p in self.points:
            out += _point_rows(p)
        return out

    def to_json(self) -> dict[str, Any]:
        """The JSON printed by ``seawatch sweep --json``."""
        return {
            "scenario": self.scenario,
            "runs": self.runs,
            "seed": self.seed,
            "grid": self.grid,
            "points": [
                {
                    "index": p.index,
                    "params": p.params,
                    "status": "ok" if p.ok else "failed",
                    "error": p.error,
                    "runs": None if p.result is None else p.result.runs,
                    "results": [] if p.result is None else p.result.results,
                }
                for p in self.points
            ],
            "failed": len(self.failed),
            "outputs": [str(p) for p in self.outputs],
        }


ROW_FIELDS = ("point", "status", "error", "estimator", "metric", "params", "unit", "mean",
              "stderr", "paper")  # fmt: skip
"""Columns of ``sweep.csv`` after the grid parameters."""


def _point_rows(p: SweepPoint) -> list[dict[str, Any]]:
    base = {**p.params, "point": p.index, "status": "ok" if p.ok else "failed", "error": p.error}
    if p.result is None:
        return [{**base, **dict.fromkeys(ROW_FIELDS[3:])}]
    return [{**base, **{k: rec[k] for k in ROW_FIELDS[3:]}} for rec in p.result.results]


class _SweepWriter:
    """``sweep.csv``, a row per record, appended as points complete."""

    def __init__(self, path: Path, grid_keys: list[str]) -> None:
        self.path = path
        path.parent.mkdir(parents=True, exist_ok=True)
        self.fh = path.open("w", newline="")
        self.writer = csv.writer(self.fh)
        self.columns = [*grid_keys, *ROW_FIELDS]
        self.writer.writerow(self.columns)
        self.fh.flush()

    def add(self, point: SweepPoint) -> None:
        for row in _point_rows(point):
            self.writer.writerow([_cell(row.get(c)) for c in self.columns])
        self.fh.flush()

    def close(self) -> None:
        self.fh.close()


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, dict | list):
        return json.dumps(v, sort_keys=True)
    if isinstance(v, float):
        return "" if not math.isfinite(v) else repr(v)
    return str(v)


def _jsonable(obj: Any) -> Any:
    """Plain JSON values (NaN/inf → None, numpy → Python, paths → str)."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def _error(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def sweep(
    name: str,
    params: dict[str, Sequence[Any]],
    runs: int | None = None,
    seed: int = 0,
    workers: int | None = None,
    scheduler: Any = None,
    out_dir: str | Path | None = None,
    progress: ProgressCallback | None = None,
    chunk: int | None = None,
    *,
    on_point: Callable[[SweepPoint], None] | None = None,
    timeout: float = DEFAULT_TIMEOUT_S,
    **options: Any,
) -> SweepResult:
    """Run experiment *name* at every point of the grid *params*, all points in parallel.

    Every chunk of every point is submitted at once; a point is merged as soon as its
    last chunk completes, its records appended to ``sweep.csv``, and ``on_point``
    called. A point whose chunk or merge raises is reported with its error (its other
    chunks are cancelled) and the others are kept.

    Args:
        name: experiment name.
        params: grid, ``{option: [values]}`` (e.g. ``{"height": [3.0, 10.0],
            "sigma_azimuth_arcmin": [0.5, 0.88, 2.0]}`` for uav-sea); ``runs`` and
            ``seed`` may be swept too.
        runs, seed, workers, scheduler, chunk, timeout: as in :func:`run_experiment`.
        out_dir: folder for ``sweep.csv`` and ``sweep.json``.
        progress: ``progress(done, total)`` over all chunks of all points (in-process:
            over points).
        on_point: called with each :class:`SweepPoint` as it completes or fails.
        **options: fixed scenario options for every point.

    Returns:
        SweepResult with every point in grid order.
    """
    mod = _module(name)
    allowed = registry.options(name) | {"runs", "seed"}
    if not isinstance(params, dict) or not params:
        raise ValueError("params: expected a non-empty {option: [values]} grid")
    grid: dict[str, list[Any]] = {}
    for key, values in params.items():
        if key not in allowed:
            known = ", ".join(sorted(allowed))
            raise ValueError(f"{key}: experiment {name!r} has no option {key!r} (options: {known})")
        if key in options:
            raise ValueError(f"{key}: given both as a fixed option and as a swept parameter")
        vals = list(values) if isinstance(values, list | tuple | range | np.ndarray) else None
        if not vals:
            raise ValueError(f"{key}: expected a non-empty list of values, got {values!r}")
        grid[key] = vals
    _check_options(name, options)
    if workers is not None:
        workers = integer("workers", workers, 1)
    if chunk is not None:
        chunk = integer("chunk", chunk, 1)
    points = [dict(zip(grid, combo, strict=True)) for combo in itertools.product(*grid.values())]
    results: dict[int, SweepPoint] = {}
    writer = _SweepWriter(Path(out_dir) / SWEEP_CSV, list(grid)) if out_dir is not None else None

    def finish(point: SweepPoint) -> None:
        results[point.index] = point
        if writer is not None:
            writer.add(point)
        if on_point is not None:
            on_point(point)

    def settings(i: int) -> tuple[int | None, int, dict[str, Any]]:
        p = points[i]
        opts = {**options, **{k: v for k, v in p.items() if k not in ("runs", "seed")}}
        r = p.get("runs", runs)
        return (_default_runs(name, mod) if r is None else r), p.get("seed", seed), opts

    parallel = supports_parallel(name)
    try:
        if scheduler is None:
            w = default_workers() if workers is None else workers
            if w == 1 or not parallel:
                _sweep_in_process(name, mod, parallel, points, settings, finish, progress)
            else:
                with _local_client(w) as client:
                    _sweep_on_cluster(name, mod, client, w, points, settings, finish, progress,
                                      chunk)  # fmt: skip
        else:
            if not parallel:
                raise ValueError(f"scheduler: experiment {name!r} runs in one process only")
            with _remote_client(scheduler, timeout) as client:
                w = _client_workers(client)
                _sweep_on_cluster(name, mod, client, w, points, settings, finish, progress,
                                  chunk)  # fmt: skip
    finally:
        if writer is not None:
            writer.close()
    out = SweepResult(
        scenario=name,
        runs=runs,
        seed=seed,
        grid=grid,
        points=[results[i] for i in range(len(points))],
    )
    if out_dir is not None:
        js = Path(out_dir) / SWEEP_JSON
        js.write_text(json.dumps(_jsonable(out.to_json()), indent=2) + "\n")
        out = SweepResult(out.scenario, out.runs, out.seed, out.grid, out.points,
                          outputs=[Path(out_dir) / SWEEP_CSV, js])  # fmt: skip
    return out


def _sweep_in_process(
    name: str,
    mod: ModuleType,
    parallel: bool,
    points: list[dict[str, Any]],
    settings: Callable[[int], tuple[int | None, int, dict[str, Any]]],
    finish: Callable[[SweepPoint], None],
    progress: ProgressCallback | None,
) -> None:
    for i, p in enumerate(points):
        r, s, opts = settings(i)
        try:
            if parallel:
                units = _units(mod, r, opts)
                res = mod.merge([mod.chunk(range(units), r, s, **opts)], r, s, **opts)
            else:
                extra = {} if r is None else {"runs": r}
                res = registry.runner(name)(seed=s, **extra, **opts)
            finish(SweepPoint(i, p, result=res))
        except Exception as exc:
            finish(SweepPoint(i, p, error=_error(exc)))
        if progress is not None:
            progress(i + 1, len(points))


def _sweep_on_cluster(
    name: str,
    mod: ModuleType,
    client: Any,
    workers: int,
    points: list[dict[str, Any]],
    settings: Callable[[int], tuple[int | None, int, dict[str, Any]]],
    finish: Callable[[SweepPoint], None],
    progress: ProgressCallback | None,
    chunk: int | None,
) -> None:
    from distributed import as_completed

    per_point = max(1, math.ceil(TASKS_PER_WORKER * workers / len(points)))
    futures: list[Any] = []
    owner: dict[str, tuple[int, int]] = {}  # future key -> (point, chunk position)
    payloads: dict[int, list[Any]] = {}
    pending: dict[int, int] = {}
    by_point: dict[int, list[Any]] = {}
    for i, p in enumerate(points):
        r, s, opts = settings(i)
        try:
            _check_options(name, opts)
            chunks = _plan(mod, _units(mod, r, opts), r, opts, per_point, chunk)
        except Exception as exc:  # a point whose options are already wrong
            finish(SweepPoint(i, p, error=_error(exc)))
            continue
        payloads[i] = [None] * len(chunks)
        pending[i] = len(chunks)
        by_point[i] = []
        for j, c in enumerate(chunks):
            fut = client.submit(_chunk_task, name, c, r, s, opts, pure=False)
            owner[fut.key] = (i, j)
            futures.append(fut)
            by_point[i].append(fut)
    failed: set[int] = set()
    done = 0
    try:
        for fut in as_completed(futures, loop=client.loop):
            done += 1
            i, j = owner[fut.key]
            if i not in failed:
                try:
                    payloads[i][j] = fut.result()
                except Exception as exc:
                    failed.add(i)
                    client.cancel([f for f in by_point[i] if f.key != fut.key])
                    finish(SweepPoint(i, points[i], error=_error(exc)))
                else:
                    pending[i] -= 1
                    if pending[i] == 0:
                        r, s, opts = settings(i)
                        try:
                            res = mod.merge(payloads.pop(i), r, s, **opts)
                            finish(SweepPoint(i, points[i], result=res))
                        except Exception as exc:
                            finish(SweepPoint(i, points[i], error=_error(exc)))
            if progress is not None:
                progress(done, len(futures))
    except BaseException:
        client.cancel(futures)
        raise


# ------------------------------------------------------------------------------------
# command-line parameters
# ------------------------------------------------------------------------------------

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_-]*$")
_TRUE = {"true", "yes", "on", "1"}
_FALSE = {"false", "no", "off", "0"}


def parse_params(name: str, specs: Sequence[str]) -> dict[str, list[Any]]:
    """``["height=3,10,30", "sigma_azimuth_arcmin=0.5,0.88"]`` → a typed grid.

    Each spec is ``NAME=v1,v2,…`` (dashes in NAME read as underscores). Values take
    the type of the option's default in the scenario's ``run()`` (bool: true/false,
    int, float, str); an option whose default is None takes int, float, bool, ``none``
    or text, whichever reads first. ``runs`` and ``seed`` are integers.

    Raises:
        ValueError: naming the malformed spec (``--param …``), an unknown option, a
            repeated one or a value of the wrong type.
    """
    allowed = registry.options(name) | {"runs", "seed"}
    sig = inspect.signature(registry.runner(name)).parameters
    grid: dict[str, list[Any]] = {}
    for spec in specs:
        text = str(spec)
        key, sep, rest = text.partition("=")
        key = key.strip().replace("-", "_")
        values = [v.strip() for v in rest.split(",")]
        if not sep or not _NAME.match(key) or not rest.strip() or any(v == "" for v in values):
            raise ValueError(f"--param {text!r}: expected NAME=v1,v2,… (e.g. height=3,10,30)")
        if key not in allowed:
            known = ", ".join(sorted(allowed))
            raise ValueError(f"--param {text!r}: experiment {name!r} has no option {key!r} "
                             f"(options: {known})")  # fmt: skip
        if key in grid:
            raise ValueError(f"--param {text!r}: {key} is given twice")
        default = 0 if key in ("runs", "seed") else sig[key].default
        grid[key] = [_coerce(text, v, default) for v in values]
    return grid


def _coerce(spec: str, value: str, default: Any) -> Any:
    def bad(kind: str) -> ValueError:
        return ValueError(f"--param {spec!r}: {value!r} is not {kind}")

    if isinstance(default, bool):
        low = value.lower()
        if low in _TRUE | _FALSE:
            return low in _TRUE
        raise bad("true or false")
    if isinstance(default, int):
        try:
            return int(value)
        except ValueError:
            raise bad("an integer") from None
    if isinstance(default, float):
        try:
            return float(value)
        except ValueError:
            raise bad("a number") from None
    if isinstance(default, str):
        return value
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    low = value.lower()
    if low in ("true", "false"):
        return low == "true"
    if low in ("none", "null"):
        return None
    return value
