"""``seawatch synth``: render footage with ground truth (seawatch.synth).

A Typer sub-application (``app``) with the ``ship-video`` and ``ais`` commands; the CLI
registers it with ``app.add_typer(synth_cmds.app, name="synth")``.
The contract of INTERFACES.md holds: ``--json`` prints exactly one JSON document on
stdout (progress on stderr); exit code 0 ok, 1 failed, 2 bad input (a message naming the
input).
"""

from __future__ import annotations

import math
from datetime import UTC, datetime
from pathlib import Path
from typing import Annotated

import typer

from seawatch.cli._common import (
    BadInput,
    emit_json,
    err,
    exit_codes,
    progress_bar,
    warnings_to_stderr,
)
from seawatch.io.nav import parse_time

__all__ = ["ais", "app", "ship_video"]

app = typer.Typer(
    name="synth",
    help="Render synthetic footage with exact ground truth (video.mp4, camera.yaml, "
    "truth.csv, horizon.csv).\n\n"
    "Examples: seawatch synth ship-video --case meeting --out out/meeting; "
    "seawatch synth ais --out out/solent",
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode="rich",
)


@app.command("ship-video")
def ship_video(
    case: Annotated[
        str,
        typer.Option(
            "--case",
            help="small, medium, large, lighting, night, meeting, overtaking or crossing.",
        ),
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")],
    duration: Annotated[float, typer.Option(help="Clip length \\[s].")] = 10.0,
    fps: Annotated[float, typer.Option(help="Frame rate [1/s].")] = 25.0,
    width: Annotated[int, typer.Option(help="Image width \\[px] (even).")] = 1920,
    height: Annotated[int, typer.Option(help="Image height \\[px] (even).")] = 1080,
    seed: Annotated[int, typer.Option(help="Random seed (waves, clouds, noise).")] = 0,
    crf: Annotated[
        int, typer.Option(help="libx264 quality: 0 (lossless) … 51; lower is better.")
    ] = 20,
    pan_deg: Annotated[
        float,
        typer.Option(
            help="Pan the camera to and fro about its heading by this amplitude \\[deg] "
            "(0: fixed camera)."
        ),
    ] = 0.0,
    pan_period: Annotated[float, typer.Option(help="Period of the pan \\[s].")] = 10.0,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print a JSON summary on stdout.")
    ] = False,
) -> None:
    """Render one [bold]ship-video[/] case (seed 001's scenes) with its ground truth.

    A 15 m shore camera (60° field of view) watching ships of several sizes — a 10 m
    boat a few pixels high, a 40 m workboat, a 150 m container ship — under day, complex
    (sun glint, cloud shadows) and thermal-night lighting, and ships meeting, overtaking
    and crossing. Writes video.mp4, camera.yaml, truth.csv (box, water-line pixel and
    world position of every ship in every frame) and horizon.csv into OUT, the CSVs as
    frames are produced.

    Example: [cyan]seawatch synth ship-video --case meeting --out out/meeting --json[/]

    Example: [cyan]seawatch synth ship-video --case large --pan-deg 4 --pan-period 6 --out
    out/pan[/] (a camera panning ±4° about its heading)
    """
    from seawatch.synth.cases import CASES, render_case, ship_video_case

    with exit_codes():
        if case not in CASES:
            raise BadInput(f"--case: unknown case {case!r}; expected one of {', '.join(CASES)}")
        if not duration > 0.0:
            raise BadInput(f"--duration: expected a positive number of seconds, got {duration}")
        if not fps > 0.0:
            raise BadInput(f"--fps: expected a positive frame rate, got {fps}")
        for name, value in (("--width", width), ("--height", height)):
            if value < 16 or value % 2:
                raise BadInput(f"{name}: expected an even number of pixels >= 16, got {value}")
        if not 0 <= crf <= 51:
            raise BadInput(f"--crf: expected an integer in 0 … 51 (libx264), got {crf}")
        if not 0.0 <= pan_deg <= 45.0:
            raise BadInput(f"--pan-deg: expected an amplitude in 0 … 45 degrees, got {pan_deg}")
        if not pan_period > 0.0:
            raise BadInput(f"--pan-period: expected a positive number of seconds, got {pan_period}")
        info = ship_video_case(case, duration=duration, width=width, height=height, seed=seed)
        with progress_bar() as bar:
            task = bar.add_task(f"synth {case}", total=max(1, round(duration * fps)))
            result = render_case(
                case,
                out,
                duration=duration,
                fps=fps,
                width=width,
                height=height,
                seed=seed,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
                crf=crf,
                pan=(math.radians(pan_deg), pan_period) if pan_deg > 0.0 else None,
            )
        doc = {
            "case": case,
            "description": info.description,
            "lighting": info.lighting.name,
            "seed": seed,
            "crf": crf,
            "pan_deg": pan_deg,
            "pan_period_s": pan_period,
            **result.to_json(),
        }
        if json_out:
            emit_json(doc)
            return
        err.print(
            f"{case}: {result.frames} frames {width}×{height} at {fps:g} fps, "
            f"{len(result.objects)} object(s), {result.rows} truth rows, "
            f"{result.frames_per_second:.1f} frames/s"
        )
        for path in (result.video, result.camera, result.truth, result.horizon):
            typer.echo(f"wrote {path}")


@app.command("ais")
def ais(
    ais_file: Annotated[
        Path | None,
        typer.Argument(
            metavar="AIS",
            help="AIS file: CSV with the columns of the Solent file (Time, MMSI, "
            "Latitude_degrees, Longitude_degrees, COG_degrees, SOG_knots) or raw NMEA with "
            "times. Default: the packaged Solent file.",
        ),
    ] = None,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path(
        "out/synth-ais"
    ),
    camera: Annotated[
        Path | None,
        typer.Option(
            help="Camera file with a geodetic position (lat/lon), height and attitude. "
            "Default: the demo camera (Southsea Castle) and the demo clip's start, "
            "duration and frame rate."
        ),
    ] = None,
    start: Annotated[
        str | None,
        typer.Option(
            help="AIS time of video time 0: ISO 8601 UTC (2016-01-12T13:23:14Z) or "
            "seconds since the epoch. Default: the busiest window in view (the demo "
            "clip's start without --camera)."
        ),
    ] = None,
    duration: Annotated[float | None, typer.Option(help="Clip length \\[s] (default 30).")] = None,
    fps: Annotated[float | None, typer.Option(help="Frame rate [1/s] (default 10).")] = None,
    seed: Annotated[int, typer.Option(help="Random seed (waves, clouds, noise).")] = 0,
    lighting: Annotated[str, typer.Option(help="day, dusk or night (thermal-like).")] = "day",
    coastline: Annotated[bool, typer.Option(help="Draw a coastline band on the horizon.")] = False,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print a JSON summary on stdout.")
    ] = False,
) -> None:
    """Render the real ship traffic of an [bold]AIS[/] file as seen by a camera.

    Every vessel of the file is interpolated along its reports into the camera's view
    (hull size from the file's length/type columns when it has them, else from its
    speed: fast craft → ferries, slow → boats) and rendered with exact ground truth:
    video.mp4, camera.yaml, truth.csv (object_id = MMSI), horizon.csv and clip.json
    (the AIS time of video time 0, so AIS time = start_epoch + video time). Without
    [bold]--camera[/]: the demo — a shore camera at Southsea Castle watching the
    Portsmouth Harbour approach, 30 s from 13:23:14 UTC of the packaged Solent file.
    With a camera and no [bold]--start[/], the busiest window of the clip's length.
    Track it with [cyan]seawatch track OUT/video.mp4 --camera OUT/camera.yaml --truth
    OUT/truth.csv[/].

    Example: [cyan]seawatch synth ais data/solent.csv --camera mast.yaml --start
    2016-01-12T13:23:14Z --duration 30 --out out/solent --json[/]
    """
    from seawatch.io.ais import read_ais, tracks
    from seawatch.io.camera_file import load_camera
    from seawatch.synth.ais_scene import (
        DEFAULT_DURATION,
        DEFAULT_FPS,
        DEMO,
        demo_camera,
        render_ais,
    )

    with exit_codes(), warnings_to_stderr():
        if lighting not in ("day", "dusk", "night"):
            raise BadInput(f"--lighting: expected day, dusk or night, got {lighting!r}")
        if duration is not None and not (math.isfinite(duration) and duration > 0.0):
            raise BadInput(f"--duration: expected a positive number of seconds, got {duration}")
        if fps is not None and not (math.isfinite(fps) and fps > 0.0):
            raise BadInput(f"--fps: expected a positive frame rate, got {fps}")
        try:
            t0 = None if start is None else parse_time(start, "--start")
        except ValueError as exc:
            raise BadInput(str(exc)) from None
        if ais_file is None:
            from seawatch.scenarios.solent_ais import default_ais_path

            ais_file = default_ais_path()
        if not ais_file.is_file():
            raise BadInput(f"AIS {ais_file}: file not found")
        try:
            table = read_ais(ais_file)
        except (ValueError, UnicodeDecodeError) as exc:
            raise BadInput(f"AIS {ais_file}: cannot read it as AIS ({exc})") from None
        vessels = tracks(table)
        if not vessels:
            raise BadInput(f"AIS {ais_file}: no timed position reports ({table.summary()})")
        first = min(tr.time[0] for tr in vessels.values())
        last = max(tr.time[-1] for tr in vessels.values())
        if camera is None:
            cam = demo_camera()
            if t0 is None and first <= DEMO.start < last:
                t0 = DEMO.start  # the demo clip (otherwise: the busiest window)
            duration = DEMO.duration if duration is None else duration
            fps = DEMO.fps if fps is None else fps
            err.print("no --camera: the demo camera (Southsea Castle, 10 m, heading 250°)")
        else:
            cam = load_camera(camera)
            if cam.lat is None or cam.lon is None:
                raise BadInput(
                    f"--camera {camera}: the camera has no geodetic position; add "
                    "position: {lat_deg: …, lon_deg: …} (seawatch-camera/1) or lat_deg/lon_deg "
                    "(OpenCV FileStorage) so the AIS vessels can be placed in its view"
                )
            if cam.height is None:
                raise BadInput(
                    f"--camera {camera}: the camera has no height above the sea; add "
                    "mounting: {height_m: …} (seawatch-camera/1) or height_m (OpenCV)"
                )
        duration = DEFAULT_DURATION if duration is None else duration
        fps = DEFAULT_FPS if fps is None else fps
        if t0 is not None and not (first <= t0 < last):
            raise BadInput(
                f"--start: {_utc(t0)} is outside the time span of {ais_file.name} "
                f"({_utc(first)} .. {_utc(last)})"
            )
        with progress_bar() as bar:
            task = bar.add_task(f"synth ais {ais_file.name}", total=max(1, round(duration * fps)))
            result = render_ais(
                table,
                cam,
                out_dir=out,
                start=t0,
                duration=duration,
                fps=fps,
                lighting=lighting,
                seed=seed,
                coastline=coastline,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
            )
        doc = {"lighting": lighting, "seed": seed, **result.to_json()}
        if json_out:
            emit_json(doc)
            return
        w, h = result.image_size
        err.print(
            f"{ais_file.name} from {doc['start_utc']}: {result.frames} frames {w}×{h} at "
            f"{result.fps:g} fps, {len(result.objects)} vessel(s) in the truth, "
            f"{result.rows} truth rows, {result.frames_per_second:.1f} frames/s"
        )
        for path in (result.video, result.camera, result.truth, result.horizon, result.clip):
            typer.echo(f"wrote {path}")


def _utc(epoch: float) -> str:
    return datetime.fromtimestamp(epoch, UTC).isoformat(timespec="seconds").replace("+00:00", "Z")
