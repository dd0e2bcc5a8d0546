"""Command function of the horizon stage: ``seawatch horizon SOURCE``.

A plain typer-compatible function (the CLI registers it with ``app.command()(horizon)``).
It reads frames with :class:`seawatch.io.video.VideoReader`, detects the horizon with
:func:`seawatch.vision.horizon.detect_horizon` (smoothed over time by
:class:`seawatch.vision.horizon.HorizonTracker` for video) and prints or writes one
record per frame, in the shape of INTERFACES.md ("Horizon JSON"):

    {"frames": [{"index": 0, "time": 0.0, "found": true, "x0": 0, "y0": 512.3,
                 "x1": 1919, "y1": 498.7, "confidence": 0.93}, ...]}

(plus ``"file"`` for images from a folder). When the horizon is not found, ``y0`` and
``y1`` are null. ``-o FILE.csv`` writes the same records as CSV rows (``index, file,
time, found, x0, y0, x1, y1, confidence``; empty cells for null), each row as soon as
its frame is done, so a crash or a dropped stream keeps the frames before it.

Exit codes: 0 ok; 2 bad input (a missing or undecodable source, an empty folder, a
source without frames, a bad option), with a message naming the input — if frames were
processed before the failure, they are kept in the CSV and printed (``--json``) with an
``"error"`` entry; 1 for any other failure. A live source (camera, RTSP …) is kept up
with (``--keep-up``, its default there): frames that arrive while three wait are
dropped unprocessed and counted in the JSON's ``"frames_dropped"``. Warnings (corrupt
frames skipped, a size change, a dropped stream, non-image files in a folder) go to
stderr.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from seawatch.cli._common import (
    EndOption,
    FpsOption,
    KeepUpOption,
    MaxFramesOption,
    ReconnectOption,
    SourceArgument,
    StartOption,
    StepOption,
    emit_json,
    err,
    exit_codes,
    frame_records,
    open_reader,
    reader_notes,
    run_summary,
    warnings_to_stderr,
)

__all__ = ["horizon"]

CSV_COLUMNS = ("index", "file", "time", "found", "x0", "y0", "x1", "y1", "confidence")


def _record(frame: Any, est: Any) -> dict[str, Any]:
    rec: dict[str, Any] = {"index": int(frame.index), "time": round(float(frame.time), 6)}
    if frame.file is not None:
        rec["file"] = str(frame.file)
    rec["found"] = bool(est.found)
    rec["x0"] = 0
    rec["y0"] = round(est.y0, 2) if est.found else None
    rec["x1"] = int(est.width - 1)
    rec["y1"] = round(est.y1, 2) if est.found else None
    rec["confidence"] = round(float(est.confidence), 3)
    return rec


def _csv_row(rec: dict[str, Any]) -> list[str]:
    def cell(v: Any) -> str:
        if v is None:
            return ""
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float) and not math.isfinite(v):
            return ""
        return str(v)

    return [cell(rec.get(col)) for col in CSV_COLUMNS]


def horizon(
    source: SourceArgument,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the horizon JSON on stdout.")
    ] = False,
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="CSV file, one row per frame, written as it goes."),
    ] = None,
    step: StepOption = 1,
    fps: FpsOption = None,
    start: StartOption = 0.0,
    end: EndOption = None,
    max_frames: MaxFramesOption = None,
    reconnect: ReconnectOption = 0,
    keep_up: KeepUpOption = None,
    smooth: Annotated[
        bool | None,
        typer.Option(
            "--smooth/--no-smooth",
            help="Temporal smoothing (Kalman filter); default on for video, off for images.",
        ),
    ] = None,
    max_tilt: Annotated[
        float,
        typer.Option("--max-tilt", help="Largest tilt of the horizon \\[deg].", min=1.0, max=60.0),
    ] = 25.0,
) -> None:
    """Detect the sea horizon in every frame of a video, stream or image folder.

    Prints (or writes with [bold]-o[/]) the line through (x0, y0) and (x1, y1) at the left
    and right image borders (pixels, x right, y down), whether it was found, and a
    confidence in [0, 1]. Video is smoothed over time unless [bold]--no-smooth[/].

    Example: [cyan]seawatch horizon clip.mp4 --json -o horizon.csv[/]
    """
    from seawatch.vision.horizon import HorizonTracker, detect_horizon

    with exit_codes(), warnings_to_stderr():
        reader = open_reader(
            source, step=step, start=start, end=end, max_frames=max_frames, fps=fps,
            reconnect=reconnect,
        )  # fmt: skip
        use_tracker = (reader.kind not in ("folder", "image")) if smooth is None else smooth
        tracker = HorizonTracker(max_tilt_deg=max_tilt, fps=reader.fps or 25.0)

        def process(frame: Any) -> dict[str, Any]:
            if use_tracker:
                return _record(frame, tracker.update(frame.image, frame.time))
            return _record(frame, detect_horizon(frame.image, max_tilt_deg=max_tilt))

        run = frame_records(
            reader,
            f"horizon {Path(source).name or source}",
            process,
            output=output,
            columns=CSV_COLUMNS,
            csv_rows=lambda rec: [_csv_row(rec)],
            keep_up=keep_up,
        )
        records = run.records
        found = sum(r["found"] for r in records)
        err.print(
            f"{len(records)} frame(s), horizon found in {found}"
            + reader_notes(reader, output, run.dropped)
        )
        if json_out:
            emit_json(run_summary(run))
        elif output is None:
            for rec in records:
                y = "not found" if not rec["found"] else f"y0={rec['y0']:.1f} y1={rec['y1']:.1f}"
                label = rec.get("file", f"t={rec['time']:.3f}s")
                sys.stdout.write(f"{rec['index']:6d} {label}  {y}  conf={rec['confidence']:.2f}\n")
        if run.failure is not None:
            raise run.failure
