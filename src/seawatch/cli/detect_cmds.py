"""Command function of the detection stage: ``seawatch detect SOURCE``.

A plain typer-compatible function (the CLI registers it with ``app.command()(detect)``).
It reads frames with :class:`seawatch.io.video.VideoReader`, finds the sea region with
the horizon detector (:class:`seawatch.vision.horizon.HorizonTracker` for video,
:func:`seawatch.vision.horizon.detect_horizon` for images; ``--no-horizon`` searches the
whole frame), runs a ship detector (:class:`seawatch.vision.detect.ClassicalShipDetector`,
or an ONNX model with ``--model``) and prints or writes the boxes of every frame in the
shape of INTERFACES.md ("Detection JSON"):

    {"frames": [{"index": 0, "time": 0.0, "boxes": [{"x": 412.0, "y": 233.5, "w": 18.0,
                 "h": 9.0, "score": 0.87, "u_wl": 421.0, "v_wl": 242.5}, ...]}, ...]}

(plus ``"file"`` for images from a folder). ``-o BOXES.csv`` writes one row per box —
``index, file, time, x, y, w, h, score, u_wl, v_wl`` — each frame's rows as soon as the
frame is done, so a crash or a dropped stream keeps the frames before it.

Exit codes: 0 ok; 2 bad input (a missing or undecodable source, an empty folder, a
source without frames, a missing model file, a bad option), with a message naming the
input — if frames were processed before the failure, they are kept in the CSV and
printed (``--json``) with an ``"error"`` entry; 1 for any other failure. A live source
(camera, RTSP …) is kept up with (``--keep-up``, its default there): frames that arrive
while three wait are dropped unprocessed and counted in the JSON's
``"frames_dropped"``. Warnings
(corrupt frames skipped, a size change, a dropped stream, non-image files in a folder)
go to stderr.
"""

from __future__ import annotations

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
    check_span,
    emit_json,
    err,
    exit_codes,
    frame_records,
    open_reader,
    reader_notes,
    run_summary,
    warnings_to_stderr,
)

__all__ = [
    "CSV_COLUMNS",
    "MaskOption",
    "ModelOption",
    "PolarityOption",
    "TemporalOption",
    "ThresholdOption",
    "detect",
]

CSV_COLUMNS = ("index", "file", "time", "x", "y", "w", "h", "score", "u_wl", "v_wl")
"""Columns of ``-o BOXES.csv`` (INTERFACES.md), one row per box."""

_BOX_KEYS = ("x", "y", "w", "h", "score", "u_wl", "v_wl")

# the detector's options (seawatch.vision.external.make_detector), shared by
# `seawatch detect`, `track` and `batch`
ModelOption = Annotated[
    Path | None,
    typer.Option(
        "--model",
        help="A YOLO-style ONNX model to use instead of the classical detector "
        "(needs onnxruntime).",
    ),
]
ThresholdOption = Annotated[
    float | None,
    typer.Option(
        help="Detection threshold: noise units for the classical detector (default 6), "
        "a score in [0, 1] for --model (default 0.25).",
        min=0.0,
    ),
]
PolarityOption = Annotated[
    str,
    typer.Option(
        help="Ships the classical detector looks for in luma: both, dark (darker than the "
        "sea: looking into the sun, where hulls are silhouettes and the bright boxes sun "
        "glitter) or bright (brighter than the sea); a hull of another colour than the "
        "sea is found by its chroma either way.",
    ),
]
MaskOption = Annotated[
    Path | None,
    typer.Option(
        "--mask",
        help="Search region: an image of the frame's size, white where ships may be, black "
        "where not (the own bow, a pier, the camera's text overlay).",
    ),
]
TemporalOption = Annotated[
    bool,
    typer.Option(
        "--temporal/--no-temporal",
        help="Temporal clutter model across frames (suppresses flicker and static "
        "clutter in video; off by default).",
    ),
]


def _record(frame: Any, boxes: Any) -> dict[str, Any]:
    """The Detection-JSON record of one frame."""
    rec: dict[str, Any] = {"index": int(frame.index), "time": round(float(frame.time), 6)}
    if frame.file is not None:
        rec["file"] = str(frame.file)
    rec["boxes"] = [
        {k: round(float(v), 3 if k == "score" else 2) for k, v in zip(_BOX_KEYS, row, strict=True)}
        for row in boxes.boxes
    ]
    return rec


def _csv_rows(rec: dict[str, Any]) -> list[list[str]]:
    file = rec.get("file", "")
    return [
        [str(rec["index"]), file, str(rec["time"])] + [str(b[k]) for k in _BOX_KEYS]
        for b in rec["boxes"]
    ]


def detect(
    source: SourceArgument,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print the detection JSON on stdout.")
    ] = False,
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="BOXES.csv, one row per box, written frame by frame."),
    ] = None,
    model: ModelOption = None,
    threshold: ThresholdOption = None,
    polarity: PolarityOption = "both",
    mask: MaskOption = None,
    use_horizon: Annotated[
        bool,
        typer.Option(
            "--horizon/--no-horizon",
            help="Look for ships on the sea below the detected horizon (default) or in the "
            "whole frame.",
        ),
    ] = True,
    temporal: TemporalOption = False,
    step: StepOption = 1,
    fps: FpsOption = None,
    start: StartOption = 0.0,
    end: EndOption = None,
    max_frames: MaxFramesOption = None,
    reconnect: ReconnectOption = 0,
    keep_up: KeepUpOption = None,
) -> None:
    """Detect ships in every frame of a video, stream or image folder.

    Prints (or writes with [bold]-o[/]) each ship's box — top-left corner (x, y), width
    and height in pixels — its score in [0, 1] and its water-line point (u_wl, v_wl),
    where the hull meets the water. Ships are searched on the sea below the detected
    horizon unless [bold]--no-horizon[/].

    Example: [cyan]seawatch detect clip.mp4 --json -o boxes.csv[/]
    """
    from seawatch.vision.external import make_detector

    with exit_codes(), warnings_to_stderr():
        check_span(start, end)
        detector = make_detector(
            model, threshold=threshold, polarity=polarity, temporal=temporal, mask=mask
        )
        reader = open_reader(
            source, step=step, start=start, end=end, max_frames=max_frames, fps=fps,
            reconnect=reconnect,
        )  # fmt: skip
        horizon_of = _horizon_source(reader, use_horizon)
        run = frame_records(
            reader,
            f"detect {Path(source).name or source}",
            lambda frame: _record(frame, detector(frame.image, horizon=horizon_of(frame))),
            output=output,
            columns=CSV_COLUMNS,
            csv_rows=_csv_rows,
            keep_up=keep_up,
        )
        records = run.records
        n_boxes = sum(len(rec["boxes"]) for rec in records)
        err.print(
            f"{len(records)} frame(s), {n_boxes} box(es)"
            + reader_notes(reader, output, run.dropped)
        )
        if json_out:
            emit_json(run_summary(run))
        elif output is None:
            for rec in records:
                label = rec.get("file", f"t={rec['time']:.3f}s")
                boxes_txt = "  ".join(
                    f"[{b['x']:.0f},{b['y']:.0f} {b['w']:.0f}x{b['h']:.0f} {b['score']:.2f}]"
                    for b in rec["boxes"]
                )
                sys.stdout.write(
                    f"{rec['index']:6d} {label}  {len(rec['boxes'])} box(es)  {boxes_txt}\n"
                )
        if run.failure is not None:
            raise run.failure


def _horizon_source(reader: Any, use_horizon: bool) -> Any:
    """A function frame → horizon estimate (or None): tracked over time for video,
    per image for images and folders, None with ``--no-horizon``."""
    if not use_horizon:
        return lambda frame: None
    from seawatch.vision.horizon import HorizonTracker, detect_horizon

    if reader.kind in ("folder", "image"):
        return lambda frame: detect_horizon(frame.image)
    tracker = HorizonTracker(fps=reader.fps or 25.0)
    return lambda frame: tracker.update(frame.image, frame.time)
