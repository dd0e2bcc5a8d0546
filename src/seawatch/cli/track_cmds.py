"""``seawatch track``: video in, tracked ships (and, with a camera, their positions) out."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from seawatch.cli._common import emit_json, err, exit_codes, progress_bar, warnings_to_stderr


def track(
    source: Annotated[str, typer.Argument(help="Video file, stream URL, device or image folder.")],
    camera: Annotated[
        Path | None,
        typer.Option(help="Camera file (seawatch or OpenCV YAML) with height and attitude."),
    ] = None,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("out/track"),
    filter: Annotated[str, typer.Option(help="Visual tracking filter: afkf, fkf or kf.")] = "afkf",
    step: Annotated[int, typer.Option(help="Use every STEP-th frame.", min=1)] = 1,
    max_frames: Annotated[
        int | None, typer.Option(help="Stop after this many frames.", min=1)
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print a JSON summary on stdout.")
    ] = False,
) -> None:
    """Track the ships of a video and write tracks.csv (INTERFACES.md columns) as it goes.

    Without [bold]--camera[/] the tracks are in pixels only (angle, range and position
    columns empty, with a warning), so any clip can be tracked before it is calibrated.
    With a camera, every track's water-line pixel becomes azimuth, depression, curved-sea
    range, north/east (and lat/lon when the camera has a geodetic position) with 1-σ
    errors — point-wise geometry; the world-frame filters that add speed and course
    come with the next stage of the pipeline.

    Example: [cyan]seawatch synth ship-video --case medium --out clip && seawatch track
    clip/video.mp4 --camera clip/camera.yaml --out out/track --json[/]
    """
    from seawatch.io.camera_file import load_camera
    from seawatch.pipeline import track_video

    with exit_codes(), warnings_to_stderr():
        if filter not in ("afkf", "fkf", "kf"):
            raise ValueError(f"--filter: expected afkf, fkf or kf, got {filter!r}")
        cam = load_camera(camera) if camera is not None else None
        with progress_bar() as bar:
            task = bar.add_task(f"track {Path(source).name or source}", total=None)
            result = track_video(
                source,
                out,
                camera=cam,
                filter=filter,
                step=step,
                max_frames=max_frames,
                progress=lambda done, total: bar.update(task, completed=done, total=total),
            )
        if json_out:
            emit_json(result.to_json())
        else:
            err.print(f"{result.frames} frames, {result.tracks} tracks, {result.rows} rows")
            for path in result.outputs:
                typer.echo(f"wrote {path}")
