"""A camera that does not wait: the track job on the 1080p benchmark clip sent in real time.

    .venv/bin/python docs/results/live/measure.py [--runs 2] [--speed 1] [--results live.json]

The clip of ``seawatch bench video`` (1920×1080, 25 frames/s, four ships; rendered once
into the system's temporary folder, as the benchmark does) is read by a reader that
sends frame k at its presentation time after the first, as a camera would: a job that
is late finds the frames waiting and reads them at once, a job that is early waits.
:func:`seawatch.pipeline.track_video` tracks it (camera file, truth, no annotated video
or report) with ``keep_up`` off and on, alternately, ``--runs`` times each. For each
run: the frames tracked and dropped, the lag of each frame tracked (when the job takes
it up, after its presentation time) — median, 95th percentile, largest, and its growth
over the run's second half [s per s] —, and the track job's own ``errors`` against the
truth (frames dropped are not scored). Writes ``live.json`` beside this script.

``--speed S`` sends the clip S times faster than real time (frame k at ``time_k / S``):
a camera of S × 25 frames/s, for a host on which the job keeps up with 25 (the lag and
its growth are then in seconds of the wall clock).
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from seawatch.bench.video import render_clip
from seawatch.io.camera_file import load_camera
from seawatch.io.video import VideoReader
from seawatch.pipeline import track_video
from seawatch.vision import tracker as tracker_module

HERE = Path(__file__).resolve().parent


class Camera(VideoReader):
    """A video file sent in real time: frame k exists from ``t0 + time_k`` on."""

    t0: float | None = None  # the wall-clock time of the clip's time 0 [s]
    speed: float = 1.0  # the clip's seconds sent per second of the wall clock

    @property
    def realtime(self) -> bool:
        return True

    def __iter__(self):  # type: ignore[override]
        for frame in super().__iter__():
            if Camera.t0 is None:
                Camera.t0 = time.perf_counter() - frame.time / Camera.speed
            wait = Camera.t0 + frame.time / Camera.speed - time.perf_counter()
            if wait > 0:
                time.sleep(wait)
            yield frame


def _run(clip: Any, keep_up: bool, out: Path) -> dict[str, Any]:
    """One track job on the clip sent in real time; the lag of each frame taken up."""
    lags: list[tuple[int, float, float]] = []  # (index, time, lag)
    stream = tracker_module.VisualTracker.stream

    def timed(self: Any, frames: Any, **kw: Any) -> Any:
        for item in stream(self, frames, **kw):
            fr = item[0]
            sent = Camera.t0 + fr.time / Camera.speed
            lags.append((fr.index, fr.time / Camera.speed, time.perf_counter() - sent))
            yield item

    Camera.t0 = None
    tracker_module.VisualTracker.stream = timed  # type: ignore[method-assign]
    import seawatch.pipeline as pipeline

    reader_class, pipeline.VideoReader = pipeline.VideoReader, Camera  # type: ignore[misc]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t = time.perf_counter()
            run = track_video(
                clip.video,
                out,
                camera=load_camera(clip.camera),
                truth=clip.truth,
                keep_up=keep_up,
                annotate=False,
                report=False,
            )
            wall = time.perf_counter() - t
    finally:
        tracker_module.VisualTracker.stream = stream  # type: ignore[method-assign]
        pipeline.VideoReader = reader_class  # type: ignore[misc]
    arr = np.array(lags)
    half = arr[arr[:, 1] >= arr[-1, 1] / 2]
    growth = float(np.polyfit(half[:, 1], half[:, 2], 1)[0]) if len(half) > 2 else float("nan")
    errors = run.errors or {}
    return {
        "keep_up": keep_up,
        "frames_tracked": run.frames,
        "frames_dropped": run.frames_dropped,
        "wall_s": wall,
        "lag_s": {
            "median": float(np.median(arr[:, 2])),
            "p95": float(np.percentile(arr[:, 2], 95)),
            "max": float(arr[:, 2].max()),
            "last": float(arr[-1, 2]),
            "growth_s_per_s": growth,
        },
        "errors": {k: errors.get(k) for k in ("cle_px", "mota", "idf1", "id_switches")},
        "rmse_position_m": errors.get("rmse_position_m"),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--speed", type=float, default=1.0, help="times real time (default 1)")
    ap.add_argument("--results", type=Path, default=HERE / "live.json")
    ap.add_argument("--out", type=Path, default=Path("out/live"))
    args = ap.parse_args()
    Camera.speed = args.speed
    clip = render_clip()
    runs = []
    for k in range(args.runs):
        for keep_up in (False, True):
            r = _run(clip, keep_up, args.out / f"{'on' if keep_up else 'off'}{k}")
            lag = r["lag_s"]
            print(
                f"keep_up {'on ' if keep_up else 'off'}: {r['frames_tracked']} tracked, "
                f"{r['frames_dropped']} dropped, lag median {lag['median']:.3f} s, "
                f"p95 {lag['p95']:.3f}, max {lag['max']:.3f}, growth "
                f"{lag['growth_s_per_s']:.3f} s/s; CLE {r['errors']['cle_px']:.3f} px, "
                f"MOTA {r['errors']['mota']:.3f}, position {r['rmse_position_m']:.1f} m",
                flush=True,
            )
            runs.append(r)
    doc = {
        "clip": {"frames": clip.frames, "size": [clip.width, clip.height], "fps": clip.fps},
        "speed": args.speed,
        "runs": runs,
    }
    args.results.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.results}")


if __name__ == "__main__":
    main()
