"""The ``seawatch`` command line: a thin layer over the Python API.

Every sub-command has ``--help`` with an example and, where a machine reads the
result, ``--json`` (one JSON document on stdout). Exit codes: 0 ok, 1 failed, 2 bad
input. See INTERFACES.md for the contract.
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from seawatch import __version__
from seawatch.cli import (
    detect_cmds,
    geometry_cmds,
    horizon_cmds,
    sweep_cmds,
    synth_cmds,
    tbd_cmds,
    track_cmds,
)
from seawatch.cli._common import (
    EXIT_FAILED,
    BadInput,
    FpsOption,
    StepOption,
    emit_json,
    err,
    exit_codes,
    progress_bar,
    warnings_to_stderr,
)
from seawatch.cli.detect_cmds import (
    MaskOption,
    ModelOption,
    PolarityOption,
    TemporalOption,
    ThresholdOption,
)

app = typer.Typer(
    name="seawatch",
    help="Passive electro-optical tracking of targets at sea: video in, angles, ranges, "
    "positions and tracks out.",
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="rich",
)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"seawatch {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """seawatch — ships and small targets from ordinary cameras, without radar."""


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("out/demo"),
    json_out: Annotated[
        bool, typer.Option("--json", help="Print a JSON summary on stdout.")
    ] = False,
) -> None:
    """Run the main job on the bundled default: real Solent ship traffic, seen by a camera.

    A fixed shore camera on the Solent watches the real AIS traffic of the packaged file
    (2016-01-12): [bold]seawatch synth ais[/] renders it into a 1080p clip with ground
    truth (reused on later runs), then [bold]seawatch track[/] tracks it with the camera
    file, the AIS file and the truth. Writes everything [bold]seawatch track[/] writes
    (tracks.csv, estimates.csv, tracks.geojson, annotated.mp4, report.html) plus the
    camera.yaml it used, and prints the report's path and a three-line error summary.

    Example: [cyan]seawatch demo --out out/demo --json[/]
    """
    from seawatch.demo import run_demo
    from seawatch.pipeline import error_summary

    with exit_codes(), warnings_to_stderr():
        with progress_bar() as bar:
            tasks: dict[str, Any] = {}

            def progress(stage: str, done: int, total: int | None) -> None:
                if stage not in tasks:
                    tasks[stage] = bar.add_task(f"demo: {stage}", total=total)
                bar.update(tasks[stage], completed=done, total=total)

            result = run_demo(out, progress=progress)
        if json_out:
            emit_json(result.to_json())
            return
        for line in error_summary(result.track.errors):
            typer.echo(line)
        typer.echo(f"report: {result.report}")
        typer.echo(f"outputs in {out}/ (tracks.csv, tracks.geojson, annotated.mp4, camera.yaml)")


@app.command()
def experiment(
    name: Annotated[str, typer.Argument(help="Experiment name, e.g. air-range, clutter-tbd.")],
    runs: Annotated[
        int | None, typer.Option(help="Monte-Carlo runs (scenario default if omitted).", min=1)
    ] = None,
    seed: Annotated[int, typer.Option(help="Random seed.")] = 0,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Folder for CSV tables and PNG plots.")
    ] = None,
    table: Annotated[
        str | None,
        typer.Option(help="clutter-tbd: 1, 2, fig4, crossing, splitting or all."),
    ] = None,
    variant: Annotated[
        str | None,
        typer.Option(
            help="clutter-tbd: the linearity test, orthogonal (default: ALGORITHMS.md §8.2's "
            "alternative) or spec (§8.1's pooled LS residual); stereo-ferry: the shared P0, "
            "matched (default) or stereo-prior (speed sigma = the stereo video's accuracy)."
        ),
    ] = None,
    ais: Annotated[Path | None, typer.Option(help="solent-ais: AIS CSV or NMEA file.")] = None,
    camera_lat: Annotated[
        float | None, typer.Option(help="solent-ais: camera latitude (deg).")
    ] = None,
    camera_lon: Annotated[
        float | None, typer.Option(help="solent-ais: camera longitude (deg).")
    ] = None,
    camera_height: Annotated[
        float | None, typer.Option(help="solent-ais: camera height above the sea (m).")
    ] = None,
    camera_heading: Annotated[
        float | None, typer.Option(help="solent-ais: camera heading (deg from North).")
    ] = None,
    fov: Annotated[
        float | None, typer.Option(help="solent-ais: horizontal field of view (deg).")
    ] = None,
    crf: Annotated[
        int | None,
        typer.Option(
            help="ship-video: libx264 quality of the rendered footage, 0 (lossless) … 51 "
            "(default 20).",
        ),
    ] = None,
    case: Annotated[
        list[str] | None,
        typer.Option(
            help="ship-video: run this case only (repeatable; default every case).",
        ),
    ] = None,
    polarity: Annotated[
        str | None,
        typer.Option(
            help="ship-video: ships the detector looks for, both (default), dark (a camera "
            "facing the sun) or bright.",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(help="Dask worker processes (default: the machine's cores).", min=1),
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Existing Dask scheduler, e.g. tcp://HOST:8786.")
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print the experiment JSON.")] = False,
) -> None:
    """Run one of the papers' experiments by name and compare with the paper.

    Prints a table of every estimator and metric (mean ± standard error over runs, and
    the paper's value where it gives one); ``--json`` prints the experiment JSON of
    INTERFACES.md; ``--out`` writes CSV tables and PNG plots as they are produced.

    Example: [cyan]seawatch experiment air-range --runs 100 --out out/air-range[/]

    Example: [cyan]seawatch experiment solent-ais --camera-height 30 --fov 50 --json[/]

    Example: [cyan]seawatch experiment uav-sea --runs 4000 --workers 2[/] (Dask; the same
    records for any number of workers)
    """
    from seawatch.scenarios import registry

    with exit_codes():
        registry.runner(name)  # unknown names: exit 2 before any work
        kwargs: dict[str, object] = {"seed": seed, "out_dir": out}
        if runs is not None:
            kwargs["runs"] = runs
        scenario_options = {
            "table": table,
            "variant": variant,
            "ais": ais,
            "camera_lat": camera_lat,
            "camera_lon": camera_lon,
            "camera_height": camera_height,
            "camera_heading": camera_heading,
            "fov": fov,
            "crf": crf,
            "cases": case or None,
            "polarity": polarity,
        }
        accepted = registry.options(name)
        for key, value in scenario_options.items():
            if value is None:
                continue
            if key not in accepted:
                flag = "--" + ("case" if key == "cases" else key.replace("_", "-"))
                raise BadInput(f"{flag}: experiment {name!r} does not take this option")
            kwargs[key] = value
        with progress_bar() as bar:
            task = bar.add_task(name, total=None)
            result = sweep_cmds.experiment_parallel(
                name,
                workers=workers,
                scheduler=scheduler,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
                **kwargs,
            )
        if json_out:
            emit_json(result.to_json())
            return
        view = Table(title=f"{name}: {result.runs} runs, seed {result.seed}")
        for col in ("estimator", "metric", "params", "mean ± stderr", "unit", "paper"):
            view.add_column(col, justify="right" if col in ("mean ± stderr", "paper") else "left")
        for rec in result.results:
            se = "" if rec["stderr"] is None else f" ± {rec['stderr']:.3g}"
            params = ", ".join(f"{k}={v}" for k, v in rec["params"].items())
            paper = "" if rec["paper"] is None else f"{rec['paper']:g}"
            view.add_row(
                rec["estimator"],
                rec["metric"],
                params,
                f"{rec['mean']:.4g}{se}",
                rec["unit"],
                paper,
            )
        err.print(view)
        for path in result.outputs:
            typer.echo(f"wrote {path}")


BENCHMARKS = {
    "filters": "Kalman filter: filter(), per-step API and 10,000 batched tracks vs FilterPy and "
    "a numpy loop (4 states, 2 measurements, 100,000 steps)",
    "tbd": "gate track-before-detect: 1080x1920 frames, 300 clutter marks, N = 4, vs a naive "
    "reference implementation",
    "mtt": "ship multi-target tracker: 10 targets + 50 clutter points per scan, vs one filter "
    "object per track",
    "video": "image stage and track job at 1920x1080: decode, +horizon, +detect, +track and "
    "track_video (decode -> tracks.csv) on a rendered four-ship clip, vs decode alone",
    "world": "world-frame estimators of the track job: 10 ships, every frame, EKF alone and "
    "every estimator, vs one EKF object per track",
}


@app.command()
def bench(
    name: Annotated[str, typer.Argument(help=f"Benchmark: {', '.join(BENCHMARKS)}.")],
    size: Annotated[
        int | None,
        typer.Option(
            help="Problem length: steps (filters), frames (tbd, video, world) or scans (mtt); "
            "default: the issue's size."
        ),
    ] = None,
    repeats: Annotated[int, typer.Option(help="Timing repeats (best of).", min=1)] = 3,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the benchmark JSON on stdout.")
    ] = False,
) -> None:
    """Run a benchmark and report speeds as ratios against references run alongside.

    [bold]filters[/]: a 2-D constant-velocity Kalman filter (4 states, 2 measurements,
    100,000 steps) through seawatch's filter() and per-step API, FilterPy and a plain
    numpy loop, plus 10,000 tracks filtered at once. [bold]tbd[/]: the gate
    track-before-detect on 1080x1920 frames with 300 clutter marks. [bold]mtt[/]: the ship
    tracker on 10 targets + 50 clutter points per scan. [bold]video[/]: decode, horizon,
    detection, visual tracking and the whole track job on a rendered 1080p clip.
    [bold]world[/]: the track job's world-frame estimators on 10 ships a frame. Each fails
    (exit 1) if its fast path disagrees with its reference.

    Example: [cyan]seawatch bench filters --json[/]
    """
    with exit_codes():
        if name not in BENCHMARKS:
            raise BadInput(f"NAME: unknown benchmark {name!r}; available: {', '.join(BENCHMARKS)}")
        import importlib
        import inspect

        module = importlib.import_module(f"seawatch.bench.{name}")
        params = inspect.signature(module.run).parameters
        kwargs: dict[str, object] = {}
        if size is not None:  # a benchmark's first argument is its problem length
            kwargs[next(iter(params))] = size
        if "repeats" in params:
            kwargs["repeats"] = repeats
        with progress_bar() as bar:
            task = bar.add_task(f"bench {name}", total=None)

            def step(label: str) -> None:
                bar.update(task, description=f"bench {name}: {label}", advance=1)

            doc = module.run(progress=step, **kwargs)
        if json_out:
            emit_json(doc)
        else:
            table = Table(title=f"bench {name}")
            table.add_column("variant")
            table.add_column("speed", justify="right")
            table.add_column("unit")
            for r in doc["results"]:
                table.add_row(r["name"], f"{r['value']:,.0f}", r["unit"])
            err.print(table)
            for k, v in doc["ratios"].items():
                typer.echo(f"{k}: {v:.1f}x")
            for k, t in doc.get("targets", {}).items():
                mark = "met" if t["met"] else "NOT met"
                sign = "<=" if t.get("kind") == "upper bound" else ">="
                typer.echo(f"target {k} {sign} {t['target']:g}: {t['measured']:.3g} ({mark})")
            typer.echo(f"agreement with the reference: {doc['agreement']}")
        if not doc["agreement"]["ok"]:
            err.print(f"[bold red]failed:[/] {name}: the fast path disagrees with its reference")
            raise typer.Exit(EXIT_FAILED)


@app.command()
def batch(
    sources: Annotated[list[str], typer.Argument(help="Videos, image folders or stream URLs.")],
    camera: Annotated[
        Path | None, typer.Option(help="Camera file of the recordings (seawatch/OpenCV YAML).")
    ] = None,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("out/batch"),
    estimator: Annotated[str, typer.Option(help="ekf, ukf, diffuse-rls or geometry.")] = "ekf",
    attitude: Annotated[str, typer.Option(help="auto, horizon or file.")] = "auto",
    video: Annotated[bool, typer.Option(help="Write annotated.mp4 per recording.")] = True,
    report: Annotated[bool, typer.Option(help="Write report.html per recording.")] = True,
    model: ModelOption = None,
    threshold: ThresholdOption = None,
    polarity: PolarityOption = "both",
    mask: MaskOption = None,
    temporal: TemporalOption = False,
    step: StepOption = 1,
    fps: FpsOption = None,
    workers: Annotated[
        int | None,
        typer.Option(help="Local Dask worker processes (default: the cores; 1: no Dask).", min=1),
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Existing Dask scheduler, e.g. tcp://HOST:8786.")
    ] = None,
    json_out: Annotated[bool, typer.Option("--json", help="Print the batch JSON.")] = False,
) -> None:
    """Track many recordings in parallel, one Dask task each.

    OUT/<name>/ holds what [bold]seawatch track[/] writes for each, OUT/batch.json every
    recording's summary or error (rewritten as each ends). A failing recording is
    reported and the others go on (exit 1 if any failed).

    Example: [cyan]seawatch batch day1/*.mp4 --camera mast.yaml --out out/day1 --workers 2[/]
    """
    from seawatch.batch import track_batch
    from seawatch.pipeline import check_options

    with exit_codes(), warnings_to_stderr():
        check_options(estimator, attitude)
        with progress_bar() as bar:
            task = bar.add_task("batch", total=len(sources))
            result = track_batch(
                sources,
                out,
                camera=camera,
                workers=workers,
                scheduler=scheduler,
                estimator=estimator,
                attitude=attitude,
                annotate=video,
                report=report,
                step=step,
                fps=fps,
                detector_options={
                    "model": model,
                    "threshold": threshold,
                    "polarity": polarity,
                    "temporal": temporal,
                    "mask": mask,
                },
                progress=lambda done, total: bar.update(task, completed=done, total=total),
            )
        if json_out:
            emit_json(result.to_json())
        else:
            for item in result.items:
                state = "ok" if item.ok else f"FAILED: {item.error}"
                typer.echo(f"{item.source} -> {item.out_dir} ({state})")
            typer.echo(f"wrote {result.summary_path}")
        if result.failed:
            raise typer.Exit(EXIT_FAILED)


app.command()(geometry_cmds.locate)
app.command()(geometry_cmds.stereo)
app.command()(geometry_cmds.calibrate)
app.command()(tbd_cmds.tbd)
app.command()(horizon_cmds.horizon)
app.command()(detect_cmds.detect)
app.command()(sweep_cmds.sweep)
app.command()(track_cmds.track)
app.add_typer(synth_cmds.app, name="synth")


_NOT_MARKUP = re.compile(r"(?<!\\)\[(?!/\]|/?(?:bold|cyan|yellow|red|dim|italic)\b)(?=[a-zA-Z#@/])")
"""An opening bracket that Rich would read as a style tag but that is text: a unit such
as [s], [px] or [deg] (the markup the help uses — bold, cyan, yellow, red, [/] — stays)."""


def _literal(text: str) -> str:
    """``text`` with its unit brackets escaped for Rich markup (idempotent)."""
    return _NOT_MARKUP.sub(r"\\[", text)


def _unwrapped(doc: str | None) -> str | None:
    """A command's docstring with each paragraph on one line: Typer's rich mode keeps
    the source's line breaks, which a terminal narrower than the source then breaks
    again mid-line (paragraphs stay apart; a paragraph that starts with ``\b`` is
    kept as written)."""
    if not doc:
        return doc
    paragraphs = inspect.cleandoc(doc).split("\n\n")
    text = "\n\n".join(p if p.startswith("\b") else " ".join(p.split("\n")) for p in paragraphs)
    return _literal(text)


def _tidy_help(typer_app: typer.Typer) -> None:
    """Every command's help (and every sub-app's) set to its unwrapped docstring with
    its unit brackets escaped, so that Rich prints them (it takes ``[s]``, ``[px]`` or
    ``[deg]`` for style tags and drops them; option help strings escape their own)."""
    for info in typer_app.registered_commands:
        if info.help is None and info.callback is not None:
            info.help = _unwrapped(info.callback.__doc__)
    for group in typer_app.registered_groups:
        if group.typer_instance is not None:
            _tidy_help(group.typer_instance)


_tidy_help(app)


def main() -> None:
    """Console entry point."""
    app()
