"""Shared plumbing of the command line: stderr console, JSON on stdout, exit codes.

Contract (INTERFACES.md): ``--json`` prints exactly one JSON document on stdout,
progress and logs go to stderr; exit code 0 ok, 1 failed, 2 bad input.
"""

from __future__ import annotations

import csv
import json
import math
import sys
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any, NamedTuple, TextIO

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2

err = Console(stderr=True, soft_wrap=True)  # never break a path or message across lines


class BadInput(ValueError):
    """A user-supplied input (file, option, value) is invalid: exit code 2."""


# the source and frame-selection options of the commands that read frames
SourceArgument = Annotated[
    str,
    typer.Argument(
        help="Video file, image file, image folder, stream URL (rtsp://, http://) "
        "or camera (0, /dev/video0)."
    ),
]
StepOption = Annotated[int, typer.Option(help="Use every STEP-th frame.", min=1)]
FpsOption = Annotated[
    float | None,
    typer.Option(help="Frame rate of an image folder (times = index / fps); default 1."),
]
StartOption = Annotated[float, typer.Option(help="First time to process \\[s].", min=0.0)]
EndOption = Annotated[
    float | None, typer.Option(help="Time to stop at \\[s] (exclusive).", min=0.0)
]
MaxFramesOption = Annotated[
    int | None, typer.Option("--max-frames", help="Stop after this many frames.", min=1)
]
ReconnectOption = Annotated[
    int,
    typer.Option(
        help="Live source (URL, camera) that drops: reopen it up to N times in a row, "
        "waiting 1, 2, 4 ... s (at most 30 s); 0: stop at the drop.",
        min=0,
    ),
]
KeepUpOption = Annotated[
    bool | None,
    typer.Option(
        "--keep-up/--no-keep-up",
        help="Drop frames when the command falls behind the source, so that it stays a few "
        "frames behind instead of ever further (counted in the JSON's frames_dropped; "
        "`track` coasts its tracks over them). "
        "Default: on for a camera device or an RTSP, RTMP, UDP, SRT stream, off for a "
        "file, folder or HTTP URL.",
        show_default=False,
    ),
]


def open_reader(
    source: str,
    *,
    step: int,
    start: float,
    end: float | None,
    max_frames: int | None,
    fps: float | None,
    reconnect: int,
) -> Any:
    """The :class:`~seawatch.io.video.VideoReader` of a command's source and frame
    options (``--end`` checked against ``--start`` first)."""
    from seawatch.io.video import VideoReader

    check_span(start, end)
    return VideoReader(
        source,
        step=step,
        start=start,
        end=end,
        max_frames=max_frames,
        fps=fps,
        reconnect=reconnect,
    )


def check_span(start: float, end: float | None, first: str = "--start") -> None:
    """:class:`BadInput` naming ``--end`` unless it is after ``first`` (or absent)."""
    if end is not None and end <= start:
        raise BadInput(f"--end: must be after {first} ({start} s), got {end} s")


def _plain(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, np.generic):
        return _plain(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None  # JSON has no NaN/inf
    if hasattr(obj, "__fspath__"):
        return str(obj)
    return obj


def emit_json(doc: dict[str, Any]) -> None:
    """Print one JSON document on stdout (NaN/inf become null)."""
    sys.stdout.write(json.dumps(_plain(doc), indent=2) + "\n")
    sys.stdout.flush()


@contextmanager
def exit_codes() -> Iterator[None]:
    """Map exceptions to the exit-code contract with a one-line message on stderr."""
    try:
        yield
    except typer.Exit:
        raise
    except (BadInput, ValueError, FileNotFoundError) as exc:
        err.print(f"[bold red]error:[/] {escape(str(exc))}")
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        err.print("[yellow]interrupted[/]")
        raise typer.Exit(130) from None
    except Exception as exc:  # any other failure is ours, not the user's input
        err.print(f"[bold red]failed:[/] {type(exc).__name__}: {escape(str(exc))}")
        raise typer.Exit(EXIT_FAILED) from None


@contextmanager
def warnings_to_stderr() -> Iterator[None]:
    """Show each warning at once as one line on stderr (not Python's two-line form)."""
    previous = warnings.showwarning

    def show(message: Warning | str, category: type[Warning], *args: Any, **kw: Any) -> None:
        err.print(f"[yellow]warning:[/] {escape(str(message))}")

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = show
        try:
            yield
        finally:
            warnings.showwarning = previous


def open_csv(output: Path | None, columns: Sequence[str]) -> tuple[TextIO | None, Any]:
    """Open ``-o/--output`` for row-by-row CSV writing with its header already flushed.

    Returns ``(file, csv_writer)``, both None without an output; an unwritable path is
    bad input (exit 2) before any work starts.
    """
    if output is None:
        return None, None
    try:
        sink = output.open("w", newline="", encoding="utf-8")
    except OSError as exc:
        raise BadInput(f"--output {output}: cannot write ({exc.strerror})") from None
    writer = csv.writer(sink)
    writer.writerow(columns)
    sink.flush()
    return sink, writer


class FrameRecords(NamedTuple):
    """What :func:`frame_records` returns: the records of the frames processed, the
    source's failure that ended the loop (None when it ran to the end), whether it kept
    up with its source and the frames it dropped to."""

    records: list[dict[str, Any]]
    failure: Exception | None
    kept_up: bool
    dropped: int


def frame_records(
    reader: Any,
    label: str,
    process: Callable[[Any], dict[str, Any]],
    *,
    output: Path | None,
    columns: Sequence[str],
    csv_rows: Callable[[dict[str, Any]], list[list[str]]],
    keep_up: bool | None = None,
) -> FrameRecords:
    """Run ``process(frame) -> record`` over a :class:`~seawatch.io.video.VideoReader`.

    Shared loop of the per-frame commands (``horizon``, ``detect``): a progress bar on
    stderr (out of the reader's ``expected_frames``), the records kept in memory,
    ``csv_rows(record)`` appended to ``output`` and flushed frame by frame. A source that
    fails mid-stream ends the loop and is returned as the failure with the frames before
    it kept; a failure before the first frame is raised (bad input).

    With ``keep_up`` the frames are read in a background thread
    (:func:`seawatch.io.prefetch.prefetch`) and one that arrives while
    :data:`seawatch.io.prefetch.DEPTH` frames already wait is dropped unprocessed and
    counted (as in :meth:`seawatch.vision.tracker.VisualTracker.stream`): a
    live camera does not wait for a command slower than its frame rate, and without
    dropping the backlog (and the delay of every record) grows without bound. A warning
    names the first frame dropped. ``keep_up=None`` (default): when the reader's source
    is real-time (:attr:`seawatch.io.video.VideoReader.realtime`).
    """
    from seawatch.io.prefetch import Skipped, prefetch
    from seawatch.io.video import VideoError

    records: list[dict[str, Any]] = []
    failure: Exception | None = None
    late = Skipped()
    if keep_up is None:
        keep_up = bool(getattr(reader, "realtime", False))
    frames: Iterable[Any] = reader
    if keep_up:
        frames = prefetch(reader, name="seawatch-read", skip=late)
    sink, writer = open_csv(output, columns)
    try:
        with progress_bar() as bar:
            task = bar.add_task(label, total=reader.expected_frames)
            try:
                for frame in frames:
                    late.warn_once()
                    rec = process(frame)
                    records.append(rec)
                    if writer is not None and sink is not None:
                        writer.writerows(csv_rows(rec))
                        sink.flush()
                    bar.advance(task)
            except VideoError as exc:
                if not records:
                    raise
                failure = exc
    finally:
        if sink is not None:
            sink.close()
    return FrameRecords(records, failure, keep_up, late.count)


def run_summary(run: FrameRecords) -> dict[str, Any]:
    """The JSON document of a per-frame command: ``{"frames": records}``, with
    ``"frames_dropped"`` when it kept up with its source and ``"error"`` when the source
    failed mid-stream."""
    doc: dict[str, Any] = {"frames": run.records}
    if run.kept_up:
        doc["frames_dropped"] = run.dropped
    if run.failure is not None:
        doc["error"] = str(run.failure)
    return doc


def reader_notes(reader: Any, output: Path | None, dropped: int = 0) -> str:
    """The end of a per-frame command's summary line: the frames dropped to keep up, the
    reader's corrupt frames skipped and images with NaN/inf pixels filled, and the CSV
    written (empty when none)."""
    return (
        (f", {dropped} dropped to keep up" if dropped else "")
        + (f", {reader.skipped} corrupt frame(s) skipped" if reader.skipped else "")
        + (f", {reader.filled} with NaN/inf pixels filled" if reader.filled else "")
        + (f"; wrote {output}" if output is not None else "")
    )


def progress_bar() -> Progress:
    """A progress bar on stderr (silent when stderr is not a terminal)."""
    return Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=err,
        transient=True,
    )
