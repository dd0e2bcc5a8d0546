"""``seawatch track``: a camera video in, geo-referenced ship tracks out (the main job)."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer

from seawatch.cli._common import (
    EXIT_FAILED,
    BadInput,
    EndOption,
    FpsOption,
    KeepUpOption,
    MaxFramesOption,
    ReconnectOption,
    StepOption,
    check_span,
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


@contextmanager
def _terminate_as_interrupt() -> Iterator[None]:
    """SIGTERM ends the run like Ctrl-C: outputs closed, report written for frames done."""

    def handler(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt

    try:
        old = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread (e.g. inside a test runner's thread)
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def _load_inputs(
    camera: Path | None,
    platform: Path | None,
    ais: Path | None,
    truth: Path | None,
    start: str | None,
) -> dict[str, Any]:
    """Read every input file before any work: bad input is exit 2 naming the option."""
    from seawatch.io.ais import read_ais
    from seawatch.io.camera_file import load_camera
    from seawatch.io.nav import parse_time, read_nav

    def read(option: str, path: Path | None, reader: Any) -> Any:
        if path is None:
            return None
        try:
            return reader(path)
        except FileNotFoundError:
            raise BadInput(f"{option} {path}: no such file") from None
        except ValueError as exc:
            raise BadInput(f"{option}: {exc}") from None

    out: dict[str, Any] = {
        "camera": read("--camera", camera, load_camera),
        "platform": read("--platform", platform, read_nav),
        "ais": read("--ais", ais, read_ais),
        "start": None,
    }
    if out["ais"] is not None and len(out["ais"]) == 0:
        raise BadInput(f"--ais {ais}: no position report could be decoded")
    if truth is not None and not truth.is_file():
        raise BadInput(f"--truth {truth}: no such file")
    if start is not None:
        try:
            out["start"] = parse_time(start, "--start")
        except ValueError as exc:
            raise BadInput(str(exc)) from None
    return out


def track(
    source: Annotated[str, typer.Argument(help="Video file, stream URL, device or image folder.")],
    camera: Annotated[
        Path | None,
        typer.Option(help="Camera file (seawatch or OpenCV YAML): intrinsics, height, attitude."),
    ] = None,
    platform: Annotated[
        Path | None,
        typer.Option(
            help="NAV of a moving platform: CSV (time, lat/lon or x/y, heading[, pitch, roll, "
            "height]) or NMEA (GGA/RMC/HDT/VTG)."
        ),
    ] = None,
    ais: Annotated[
        Path | None,
        typer.Option(help="AIS to cross-check with: raw NMEA (!AIVDM) or decoded CSV."),
    ] = None,
    truth: Annotated[
        Path | None,
        typer.Option(
            help="truth.csv of `seawatch synth`, or boxes annotated on a real clip "
            "(CSV: frame, object_id, x, y, w, h; pixel scores only): score the run."
        ),
    ] = None,
    start: Annotated[
        str | None,
        typer.Option(
            help="UTC time of the first frame (ISO-8601 or epoch s) for NAV/AIS; default: "
            "clip.json beside the video, else the NAV's first time."
        ),
    ] = None,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("out/track"),
    estimator: Annotated[
        str,
        typer.Option(help="World estimator of tracks.csv: ekf, ukf, diffuse-rls or geometry."),
    ] = "ekf",
    attitude: Annotated[
        str,
        typer.Option(
            help="horizon: pitch/roll refined by the detected horizon each frame (a swaying "
            "mast); file: the camera file's (and NAV's) attitude; auto: horizon on a moving "
            "platform, file for a fixed camera."
        ),
    ] = "auto",
    filter: Annotated[str, typer.Option(help="Visual tracking filter: afkf, fkf or kf.")] = "afkf",
    model: ModelOption = None,
    threshold: ThresholdOption = None,
    polarity: PolarityOption = "both",
    mask: MaskOption = None,
    temporal: TemporalOption = False,
    pixel_sigma: Annotated[
        float, typer.Option(help="1-sigma of the water-line pixel \\[px].", min=0.01)
    ] = 1.0,
    step: StepOption = 1,
    max_frames: MaxFramesOption = None,
    begin: Annotated[
        float,
        typer.Option(
            help="First video time to track \\[s from the video's start] (--start is the UTC "
            "time of the video's frame 0).",
            min=0.0,
        ),
    ] = 0.0,
    end: EndOption = None,
    fps: FpsOption = None,
    reconnect: ReconnectOption = 0,
    keep_up: KeepUpOption = None,
    video: Annotated[bool, typer.Option(help="Write annotated.mp4.")] = True,
    report: Annotated[bool, typer.Option(help="Write report.html.")] = True,
    parquet: Annotated[bool, typer.Option(help="Also write tracks.parquet (pyarrow).")] = False,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print a JSON summary on stdout.")
    ] = False,
) -> None:
    """Track the ships of a video and geo-reference them.

    Writes tracks.csv, estimates.csv, tracks.geojson, annotated.mp4 and report.html, each
    as it is produced.

    Per frame: horizon, ship boxes and visual tracks; with [bold]--camera[/], each track's
    water-line pixel becomes azimuth and depression (attitude refined by the horizon),
    then point-wise curved-sea geometry, diffuse-RLS AR smoothing with forecasts and a
    world-frame EKF/UKF give position, speed, course, their 1-sigma and +10 s/+30 s
    forecasts (tracks.csv holds --estimator's; estimates.csv all of them). Without a
    camera the tracks are in pixels only (with a warning). [bold]--platform[/] places a
    camera on a moving boat; [bold]--ais[/] labels tracks with MMSIs and lists "dark"
    tracks and unseen AIS vessels; [bold]--truth[/] adds the errors to the summary.
    Ctrl-C or SIGTERM stops cleanly: every frame done is in the outputs.

    Example: [cyan]seawatch synth ship-video --case medium --out clip && seawatch track
    clip/video.mp4 --camera clip/camera.yaml --truth clip/truth.csv --out out/track --json[/]
    """
    from seawatch.pipeline import check_options, error_summary, track_video
    from seawatch.vision.external import make_detector

    with exit_codes(), warnings_to_stderr():
        if filter not in ("afkf", "fkf", "kf"):
            raise BadInput(f"--filter: expected afkf, fkf or kf, got {filter!r}")
        check_options(estimator, attitude)
        check_span(begin, end, "--begin")
        detector = make_detector(
            model, threshold=threshold, polarity=polarity, temporal=temporal, mask=mask
        )
        inputs = _load_inputs(camera, platform, ais, truth, start)
        live = "://" in source or source.isdigit() or source.startswith("/dev/")
        with progress_bar() as bar, _terminate_as_interrupt():
            task = bar.add_task(f"track {Path(source).name or source}", total=None)

            def progress(done: int, total: int | None) -> None:
                if total is None and live:
                    bar.update(task, completed=done, description=f"track {source}: {done} frames")
                else:
                    bar.update(task, completed=done, total=total)

            result = track_video(
                source,
                out,
                camera=inputs["camera"],
                platform=inputs["platform"],
                ais=inputs["ais"],
                truth=truth,
                start=inputs["start"],
                filter=filter,
                detector=detector,
                estimator=estimator,
                attitude=attitude,  # type: ignore[arg-type]
                sigma_px=pixel_sigma,
                step=step,
                max_frames=max_frames,
                begin=begin,
                end=end,
                fps=fps,
                reconnect=reconnect,
                keep_up=keep_up,
                annotate=video,
                report=report,
                parquet=parquet,
                progress=progress,
            )
        if json_out:
            emit_json(result.to_json())
        else:
            dropped = (
                f" ({result.frames_dropped} dropped to keep up)" if result.frames_dropped else ""
            )
            err.print(
                f"{result.frames} frames{dropped}, {result.tracks} tracks, {result.rows} rows"
            )
            for line in error_summary(result.errors):
                err.print(line)
            for path in result.outputs:
                typer.echo(f"wrote {path}")
        if result.interrupted:
            err.print("[bold red]interrupted:[/] the outputs hold every frame done")
            raise typer.Exit(EXIT_FAILED)
