"""``seawatch tbd``: small-target track-before-detect on a marks file (or a video).

A plain typer-compatible function; the command line registers it with
``app.command()(tbd)``. It reads point marks, runs
:class:`seawatch.tracking.GateTBD` (ALGORITHMS.md §8.1, seed 004) and writes the
confirmed detections.

Input: a CSV of marks with columns ``frame,row,col`` (header named so, any further
columns ignored; without a header the first three columns are taken), pixel
coordinates (row down, col right), rows of one frame together and frame numbers not
decreasing. Skipped frame numbers are empty frames. A video file (``.mp4``, ``.avi``,
…) goes through mark extraction first: ``seawatch.vision.marks.extract_marks(frame)``
(CFAR defaults) on every frame, its (row, col) columns. Where that module cannot be
imported, the command exits with code 2 and says so.

Output (``-o TRACKS.csv``, or CSV on stdout without ``-o`` and ``--json``): one row
per confirmed detection, ``frame,track_id,row,col,v_row,v_col`` (px, px/frame).
``--json`` prints one summary document: parameters, frames, marks read, marks dropped
outside the frame, newly confirmed tracks, detections, and per track its first and
last frame and number of detections.
"""

from __future__ import annotations

import csv
import io
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from seawatch.cli._common import BadInput, emit_json, err, exit_codes, progress_bar

VIDEO_SUFFIXES = {".mp4", ".avi", ".mov", ".mkv", ".mpg", ".mpeg", ".m4v", ".webm", ".wmv"}
DEFAULT_FRAME_SIZE = (1080, 1920)
COLUMNS = ("frame", "track_id", "row", "col", "v_row", "v_col")


def parse_frame_size(text: str) -> tuple[int, int]:
    """``"1080x1920"`` → (1080, 1920) (rows, cols); BadInput naming ``--frame-size``."""
    parts = text.lower().replace("×", "x").split("x")
    try:
        rows, cols = (int(p) for p in parts)
    except ValueError:
        raise BadInput(f"--frame-size: expected ROWSxCOLS like 1080x1920, got {text!r}") from None
    if rows < 1 or cols < 1:
        raise BadInput(f"--frame-size: rows and cols must be >= 1, got {text!r}")
    return rows, cols


def read_marks_csv(path: Path) -> np.ndarray:
    """Rows (frame, row, col) of a marks CSV as an (K, 3) float array."""
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise BadInput(f"{path}: not a text CSV file") from None
    rows = [r for r in csv.reader(io.StringIO(text)) if r and any(c.strip() for c in r)]
    if not rows:
        return np.zeros((0, 3))
    head = [c.strip().lower() for c in rows[0]]
    try:
        [float(c) for c in head[:3]]
        cols, body, first_line = (0, 1, 2), rows, 1
    except ValueError:
        missing = [c for c in ("frame", "row", "col") if c not in head]
        if missing:
            raise BadInput(
                f"{path}: header has no column {', '.join(missing)} (expected frame,row,col)"
            ) from None
        cols = (head.index("frame"), head.index("row"), head.index("col"))
        body, first_line = rows[1:], 2
    out = np.empty((len(body), 3))
    for n, r in enumerate(body):
        try:
            out[n] = [float(r[c]) for c in cols]
        except (ValueError, IndexError):
            raise BadInput(
                f"{path}: line {n + first_line}: expected numbers in frame,row,col, got {r!r}"
            ) from None
    if not np.all(np.isfinite(out)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(out), axis=1))[0])
        raise BadInput(f"{path}: line {bad + first_line}: NaN or inf in frame,row,col")
    return out


def _video_frames(path: Path) -> tuple[Iterator[tuple[int, np.ndarray]], tuple[int, int], int]:
    """(frame number, marks (M, 2)) per video frame via ``seawatch.vision.marks``."""
    try:
        from seawatch.vision.marks import extract_marks  # type: ignore[import-not-found]
    except ImportError:
        raise BadInput(
            f"SOURCE: {path} is a video, and mark extraction (seawatch.vision.marks) is not "
            "available in this installation yet; give a marks CSV with columns frame,row,col"
        ) from None
    import cv2

    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        raise BadInput(f"SOURCE: cannot open video {path}")
    size = (int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)), int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)))
    count = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))

    def frames() -> Iterator[tuple[int, np.ndarray]]:
        k = 0
        try:
            while True:
                ok, image = cap.read()
                if not ok:
                    break
                marks = np.asarray(extract_marks(image), dtype=np.float64)
                yield k, marks.reshape(-1, marks.shape[-1] if marks.ndim == 2 else 2)[:, :2]
                k += 1
        finally:
            cap.release()

    return frames(), size, count


def _csv_frames(path: Path) -> tuple[Iterator[tuple[int, np.ndarray]], int]:
    from seawatch.tracking.gate_tbd import group_marks

    table = read_marks_csv(path)
    try:
        numbers, frames = group_marks(table)
    except ValueError as exc:
        raise BadInput(f"{path}: {exc}") from None
    return iter(zip(numbers, frames, strict=True)), len(numbers)


def tbd(
    source: Annotated[
        Path, typer.Argument(help="Marks CSV (frame,row,col) or a video (needs mark extraction).")
    ],
    frame_size: Annotated[
        str | None,
        typer.Option(
            "--frame-size",
            help="Frame size ROWSxCOLS in px (default: the video's, or 1080x1920 for a CSV).",
        ),
    ] = None,
    large_gate: Annotated[
        int, typer.Option("--large-gate", help="Big (initiation) gate side, odd, px.")
    ] = 161,
    small_gate: Annotated[
        int, typer.Option("--small-gate", help="Small (confirmation) gate side, odd, px.")
    ] = 23,
    n_frames: Annotated[
        int, typer.Option("--n-frames", "-N", help="N: consecutive frames with a mark to confirm.")
    ] = 4,
    max_misses: Annotated[
        int, typer.Option("--max-misses", "-L", help="L: misses that delete a confirmed track.")
    ] = 1,
    eps: Annotated[
        float, typer.Option("--eps", help="Linearity threshold: RMS residual of the line, px.")
    ] = 2.55,
    literal: Annotated[
        bool,
        typer.Option(
            "--no-seed-exclusion", help="Seed with every mark (the paper's literal rule)."
        ),
    ] = False,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write the detections to this CSV.")
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print a JSON summary on stdout.")
    ] = False,
) -> None:
    """Detect and track many small targets in point marks (gate track-before-detect).

    Every mark of the previous frame opens a big gate; marks inside start tentative
    tracks, which a small gate around the constant-velocity prediction and a straight-
    line test extend frame by frame. A track with a mark in each of N consecutive frames
    is confirmed and reported (delay N−1 frames); a miss deletes it (seed 004,
    ALGORITHMS.md §8). Output rows: frame, track_id, row, col, v_row, v_col (px,
    px/frame).

    SOURCE is a CSV with columns frame,row,col, or a video: marks are then extracted
    from every frame first (seawatch.vision.marks, CFAR defaults).

    Example: [cyan]seawatch tbd marks.csv --frame-size 1080x1920 --large-gate 161
    --small-gate 23 -N 4 -o tracks.csv[/]
    """
    from seawatch.tracking.gate_tbd import GateTBD

    with exit_codes():
        if not source.exists():
            raise BadInput(f"SOURCE: no such file {source}")
        is_video = source.suffix.lower() in VIDEO_SUFFIXES
        if is_video:
            frames, video_size, total = _video_frames(source)
            size = parse_frame_size(frame_size) if frame_size else video_size
            if size != video_size:
                raise BadInput(
                    f"--frame-size: {size[0]}x{size[1]} differs from the video's "
                    f"{video_size[0]}x{video_size[1]}"
                )
        else:
            frames, total = _csv_frames(source)
            size = parse_frame_size(frame_size) if frame_size else DEFAULT_FRAME_SIZE
        detector = GateTBD(
            size,
            large_gate=large_gate,
            small_gate=small_gate,
            n_frames=n_frames,
            max_misses=max_misses,
            linearity_threshold=eps,
            seed_exclusion=not literal,
        )
        dets: list[np.ndarray] = []
        n_frames_done = marks_total = dropped = new_tracks = capped_frames = 0
        with warnings.catch_warnings(record=True) as caught, progress_bar() as bar:
            warnings.simplefilter("always", RuntimeWarning)
            task = bar.add_task("tbd", total=total or None)
            for number, marks in frames:
                out = detector.push(marks, frame=number)
                st = detector.last_stats
                assert st is not None
                n_frames_done += 1
                marks_total += st.marks
                dropped += st.dropped
                new_tracks += st.new_tracks
                capped_frames += bool(st.capped_branches or st.capped_pairs)
                if out.shape[0]:
                    dets.append(np.column_stack((np.full(out.shape[0], number), out)))
                bar.update(task, advance=1)
        det = np.concatenate(dets) if dets else np.zeros((0, 6))
        if dropped:
            err.print(f"[yellow]warning:[/] dropped {dropped} mark(s) outside the frame")
        if capped_frames:
            err.print(
                f"[yellow]warning:[/] branch/pair caps bound in {capped_frames} frame(s) "
                "(dense clutter); tracking there is incomplete"
            )
        for w in caught:
            if not issubclass(w.category, RuntimeWarning):
                err.print(f"[yellow]warning:[/] {w.message}")

        if output is not None:
            _write_csv(det, output)
        elif not json_out:
            _write_csv(det, sys.stdout)
        summary = _summary(det)
        if json_out:
            emit_json(
                {
                    "source": str(source),
                    "frame_size": list(size),
                    "parameters": {
                        "large_gate": large_gate,
                        "small_gate": small_gate,
                        "n_frames": n_frames,
                        "max_misses": max_misses,
                        "linearity_threshold": eps,
                        "seed_exclusion": not literal,
                    },
                    "frames": n_frames_done,
                    "marks": marks_total + dropped,
                    "dropped": dropped,
                    "new_tracks": new_tracks,
                    "detections": int(det.shape[0]),
                    "tracks": summary,
                    "output": None if output is None else str(output),
                }
            )
            return
        err.print(
            f"tbd: {n_frames_done} frames, {det.shape[0]} detections in {len(summary)} "
            f"confirmed track(s)"
        )
        if output is not None:
            typer.echo(f"wrote {output}")


def _write_csv(det: np.ndarray, target: Path | Any) -> None:
    def rows(w: Any) -> None:
        w.writerow(COLUMNS)
        for r in det:
            w.writerow([int(r[0]), int(r[1]), f"{r[2]:.6g}", f"{r[3]:.6g}", f"{r[4]:.6g}",
                        f"{r[5]:.6g}"])  # fmt: skip

    if isinstance(target, Path):
        with target.open("w", newline="") as fh:
            rows(csv.writer(fh))
    else:
        rows(csv.writer(target, lineterminator="\n"))


def _summary(det: np.ndarray) -> list[dict[str, int]]:
    out = []
    for tid in np.unique(det[:, 1]).astype(int):
        f = det[det[:, 1] == tid, 0]
        out.append(
            {
                "track_id": int(tid),
                "first_frame": int(f.min()),
                "last_frame": int(f.max()),
                "detections": int(f.size),
            }
        )
    return out
