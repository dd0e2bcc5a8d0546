"""``seawatch synth``: render footage with ground truth (seawatch.synth).

A Typer sub-application (``app``) with the ``ship-video`` command; the CLI registers it
with ``app.add_typer(synth_cmds.app, name="synth")``. Issue 7 adds ``synth ais`` here.
The contract of INTERFACES.md holds: ``--json`` prints exactly one JSON document on
stdout (progress on stderr); exit code 0 ok, 1 failed, 2 bad input (a message naming the
input).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from seawatch.cli._common import BadInput, emit_json, err, exit_codes, progress_bar

__all__ = ["app", "ship_video"]

app = typer.Typer(
    name="synth",
    help="Render synthetic footage with exact ground truth (video.mp4, camera.yaml, "
    "truth.csv, horizon.csv).\n\n"
    "Example: seawatch synth ship-video --case meeting --out out/meeting",
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
    duration: Annotated[float, typer.Option(help="Clip length [s].")] = 10.0,
    fps: Annotated[float, typer.Option(help="Frame rate [1/s].")] = 25.0,
    width: Annotated[int, typer.Option(help="Image width [px] (even).")] = 1920,
    height: Annotated[int, typer.Option(help="Image height [px] (even).")] = 1080,
    seed: Annotated[int, typer.Option(help="Random seed (waves, clouds, noise).")] = 0,
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
            )
        doc = {
            "case": case,
            "description": info.description,
            "lighting": info.lighting.name,
            "seed": seed,
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
