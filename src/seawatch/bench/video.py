"""``seawatch bench video``: the image stage and the whole track job at 1080p (issues 6, 7).

Clip: ``frames`` frames (default 250: 10 s at 25 frames/s) of 1920×1080 footage rendered
once with :func:`seawatch.synth.render` and kept (a cache folder): the ship-video cases'
shore camera (:func:`seawatch.synth.cases.case_camera`: 15 m above the sea, 60° field of
view, mast sway) watching four ships spread across the view — a 30 m workboat 1.25 km
out, a 60 m ferry at 900 m, a 120 m container ship at 2 km whose superstructure rises
above the horizon and a 14 m boat at 700 m — each crossing at a few m/s.

Variants, in the same process and run, each over the whole clip (best of ``repeats``):

* ``decode`` — :class:`~seawatch.io.video.VideoReader` frames (BGR) alone;
* ``decode+horizon`` — plus :meth:`~seawatch.vision.horizon.HorizonTracker.update`;
* ``decode+horizon+detect`` — plus the
  :class:`~seawatch.vision.detect.ClassicalShipDetector` given that horizon;
* ``decode+horizon+detect+track`` — the image stage of issue 6 as the track job runs it:
  :meth:`~seawatch.vision.tracker.VisualTracker.stream` (frames decoded and their
  horizons found in one thread, ships detected in another, a few frames ahead) and
  :meth:`~seawatch.vision.tracker.VisualTracker.update` (the visual multi-target tracker)
  in the calling thread;
* ``track_video`` — :func:`seawatch.pipeline.track_video` with the clip's camera:
  decode → ``tracks.csv`` rows (issue 7; no annotated video, no HTML report).

The first three variants run in one thread, so the differences of their frame times
are the per-frame costs of decoding, the horizon and detection; the last two overlap
those stages on the machine's cores, and ``pipeline`` is what the track job adds to its
image stage. Speeds are frames per second of wall-clock time, with their ratios to
decode alone in the same run. Each result also gives the rate in process CPU time
(every thread of the process), and, where ``/proc`` tells them (Linux), the share of
the machine's CPU time the hypervisor gave to other guests during the run (``steal``:
on a shared virtual machine the wall-clock rates fall with it while the code is the
same) and the CPU time per frame of each thread by name (the track job's
``MainThread``, ``seawatch-read`` and ``seawatch-detect``, and the decoder's
:data:`NATIVE_THREADS`): the busiest thread and the total over the cores bound the
frame rate the machine could reach. Targets (issues 6 and 7): ``track_video`` ≥ 25 frames/s and
``decode+horizon+detect+track`` ≥ 25 frames/s.

``agreement`` — speed must not be bought with wrong answers: the ``tracks.csv`` of the
timed ``track_video`` run is scored against the rendered truth (``truth.csv``, from
frame :data:`SCORED_FROM` on): every ship is covered by a track in at least
:data:`COVERAGE_MIN` of its frames (the CLE matching of
:func:`seawatch.metrics.cle.centre_location_error`), CLEAR-MOT MOTA and IDF1 (box
IoU ≥ 0.5, :func:`seawatch.metrics.mot_metrics`) reach :data:`QUALITY_MIN`, and the
mean centre location error stays under :data:`CLE_PERCENT_MAX` % of the truth box
diagonal; and the image-stage variant's pixel tracks must be ``track_video``'s (same
frames, ids and boxes within :data:`SAME_TRACKS_TOL` px: the pipeline runs the stage
unchanged).
"""

from __future__ import annotations

import csv
import inspect
import math
import os
import tempfile
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seawatch._validation import FloatArray, integer
from seawatch.synth.render import RENDER_VERSION

__all__ = [
    "CLE_PERCENT_MAX",
    "COVERAGE_MIN",
    "QUALITY_MIN",
    "SCORED_FROM",
    "SPEED_TARGET",
    "VARIANTS",
    "Clip",
    "quality",
    "render_clip",
    "run",
    "scene",
]

SPEED_TARGET = 25.0
"""Frames per second at 1920×1080, end to end and for the image stage (issues 6 and 7)."""
COVERAGE_MIN = 0.8
"""Least fraction of a ship's truth frames covered by a track (the rest: the tracker's
confirmation delay at the start and a lost frame now and then)."""
QUALITY_MIN = {"mota": 0.85, "idf1": 0.85}
"""Least CLEAR-MOT accuracy and identity F1 (box IoU ≥ 0.5) of the tracks."""
CLE_PERCENT_MAX = 5.0
"""Largest mean centre location error [% of the truth box diagonal] (issue 6 asks < 2 %
of a large ship; 5 % here covers the 14 m boat a few pixels high)."""
SCORED_FROM = 5
"""First frame scored: the tracker confirms a track after 3 detections in 5 frames, so
no track can exist in the first frames (a fixed cost of any clip, not an error)."""
SAME_TRACKS_TOL = 1e-3
"""Largest difference [px] between the image-stage variant's boxes and ``tracks.csv``'s
(written with 10 significant digits)."""
SCENE_VERSION = 1
"""Changes with the scene, so that a cached clip of an older scene is not reused."""

Progress = Callable[[str], None]

_SHIPS: tuple[tuple[float, float, float, float, float, str], ...] = (
    # forward [m], right [m] of the camera axis at mid-clip, course relative to the camera
    # heading [deg] (+90: moving right in the image), speed [m/s], length [m], kind
    (1250.0, -480.0, 90.0, 4.0, 30.0, "workboat"),
    (900.0, -140.0, 90.0, 5.0, 60.0, "ferry"),
    (2000.0, 300.0, -90.0, 6.0, 120.0, "cargo"),
    (700.0, 300.0, -90.0, 3.0, 14.0, "boat"),
)
_SWAY = (math.radians(0.25), math.radians(0.18), 6.5)  # roll, pitch amplitude [rad], period [s]


@dataclass(frozen=True)
class Clip:
    """A rendered benchmark clip.

    Attributes:
        folder: where it lies (``video.mp4``, ``camera.yaml``, ``truth.csv``,
            ``horizon.csv``).
        frames: frames in the video.
        width, height: frame size [px].
        fps: frame rate [1/s].
        render_seconds: wall-clock time spent rendering it now [s] (0 when it was cached).
    """

    folder: Path
    frames: int
    width: int
    height: int
    fps: float
    render_seconds: float

    @property
    def video(self) -> Path:
        """The H.264 video."""
        return self.folder / "video.mp4"

    @property
    def camera(self) -> Path:
        """The camera file (seawatch-camera/1 YAML)."""
        return self.folder / "camera.yaml"

    @property
    def truth(self) -> Path:
        """The per-frame truth boxes (INTERFACES.md "Synthetic footage")."""
        return self.folder / "truth.csv"


def scene(duration: float) -> list[Any]:
    """The benchmark's four ships for a clip of ``duration`` [s] (module docstring); each
    passes its mid-clip position at ``duration / 2``."""
    from seawatch.synth.cases import CAMERA_HEADING
    from seawatch.synth.world import make_ship, through

    c, s = math.cos(CAMERA_HEADING), math.sin(CAMERA_HEADING)
    ships = []
    for i, (forward, right, rel, speed, length, kind) in enumerate(_SHIPS, start=1):
        north, east = forward * c - right * s, forward * s + right * c
        course = CAMERA_HEADING + math.radians(rel)
        traj = through(north, east, course, speed, duration / 2, start=0.0, end=duration)
        ships.append(make_ship(i, traj, length, kind=kind))
    return ships


def _default_folder(frames: int, width: int, height: int, fps: float, seed: int) -> Path:
    name = f"{width}x{height}-{frames}f-{fps:g}fps-s{seed}-v{SCENE_VERSION}.{RENDER_VERSION}"
    return Path(tempfile.gettempdir()) / "seawatch-bench-video" / name


def render_clip(
    frames: int = 250,
    *,
    width: int = 1920,
    height: int = 1080,
    fps: float = 25.0,
    seed: int = 0,
    folder: str | Path | None = None,
) -> Clip:
    """The benchmark clip, rendered into ``folder`` unless a complete one is there.

    Args:
        frames: frames to render (``frames / fps`` seconds).
        width, height: frame size [px].
        fps: frame rate [1/s].
        seed: render seed (sea texture, noise).
        folder: the clip's folder; None: a folder per parameter set under the system's
            temporary directory, kept between runs.
    """
    frames = integer("frames", frames, 2)
    for name, value in (("width", width), ("height", height)):
        integer(name, value, 64)  # [px]
    if not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
        raise ValueError(f"fps: expected a positive frame rate, got {fps!r}")
    out = Path(folder) if folder is not None else _default_folder(frames, width, height, fps, seed)
    done = out / "bench-video.done"
    key = f"{frames} {width} {height} {fps!r} {seed} v{SCENE_VERSION}.{RENDER_VERSION}"
    if done.is_file() and done.read_text(encoding="utf-8").strip() == key:
        return Clip(out, frames, width, height, float(fps), 0.0)
    from seawatch.synth.cases import case_camera
    from seawatch.synth.render import lighting_preset, render

    out.mkdir(parents=True, exist_ok=True)
    done.unlink(missing_ok=True)
    duration = frames / fps
    t0 = time.perf_counter()
    res = render(
        case_camera(width, height),
        scene(duration),
        duration,
        fps,
        out_dir=out,
        lighting=lighting_preset("day"),
        sway=_SWAY,
        seed=seed,
        description="seawatch bench video: four ships crossing a shore camera's view",
    )
    seconds = time.perf_counter() - t0
    done.write_text(key + "\n", encoding="utf-8")
    return Clip(out, int(res.frames), width, height, float(fps), seconds)


# --------------------------------------------------------------------------------------
# the timed variants
# --------------------------------------------------------------------------------------


def _frames(clip: Clip) -> Iterator[Any]:
    from seawatch.io.video import VideoReader

    with VideoReader(clip.video) as reader:
        yield from reader


def _decode(clip: Clip) -> int:
    n = 0
    for _ in _frames(clip):
        n += 1
    return n


def _horizon(clip: Clip) -> int:
    from seawatch.vision.horizon import HorizonTracker

    ht = HorizonTracker(fps=clip.fps)
    n = 0
    for fr in _frames(clip):
        ht.update(fr.image, fr.time)
        n += 1
    return n


def _detect(clip: Clip) -> int:
    from seawatch.vision.detect import ClassicalShipDetector
    from seawatch.vision.horizon import HorizonTracker

    ht = HorizonTracker(fps=clip.fps)
    det = ClassicalShipDetector()
    n = 0
    for fr in _frames(clip):
        det(fr.image, horizon=ht.update(fr.image, fr.time))
        n += 1
    return n


def _stage(clip: Clip, keep: list[FloatArray] | None = None) -> int:
    from seawatch.vision.tracker import VisualTracker

    vt = VisualTracker(fps=clip.fps, stabilise=False)  # as the track job runs it (pipeline)
    n = 0
    for fr, _, detections in vt.stream(_frames(clip)):
        rows = vt.update(detections)
        if keep is not None:
            keep.append(np.column_stack([np.full(rows.shape[0], fr.index), rows[:, :5]]))
        n += 1
    return n


def _track_video(clip: Clip, out_dir: Path) -> int:
    from seawatch.io.camera_file import load_camera
    from seawatch.pipeline import track_video

    options: dict[str, Any] = {"camera": load_camera(clip.camera)}
    accepted = inspect.signature(track_video).parameters
    for name in ("annotate", "report"):  # decode → tracks.csv only
        if name in accepted:
            options[name] = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = track_video(clip.video, out_dir, **options)
    return int(run.frames)


def _cpu_ticks() -> tuple[int, int] | None:
    """(steal, total) ticks of all CPUs so far (``/proc/stat``), None where unknown."""
    try:
        with open("/proc/stat", encoding="ascii") as fh:
            f = fh.readline().split()
        ticks = [int(x) for x in f[1:9]]  # user nice system idle iowait irq softirq steal
    except (OSError, ValueError, IndexError):
        return None
    return (ticks[7], sum(ticks)) if f[0] == "cpu" and len(ticks) == 8 else None


NATIVE_THREADS = "native"
"""Label of the process's threads that Python did not start (the video decoder's)."""


def _task_cpu() -> dict[int, float]:
    """CPU seconds so far of each thread of this process (``/proc/self/task``; empty
    where there is none)."""
    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    out = {}
    try:
        tids = os.listdir("/proc/self/task")
    except OSError:
        return out
    for tid in tids:
        try:
            with open(f"/proc/self/task/{tid}/stat", encoding="ascii") as fh:
                stat = fh.read()
        except OSError:  # the thread ended meanwhile
            continue
        f = stat[stat.rindex(")") + 2 :].split()
        out[int(tid)] = (int(f[11]) + int(f[12])) / tick  # utime + stime
    return out


class _ThreadClock:
    """CPU seconds per thread name of what runs between ``start`` and ``stop``: the
    threads are sampled every 20 ms (a thread that ends between two samples loses its
    last CPU time here, not in the process total) and named
    by :mod:`threading` (others: :data:`NATIVE_THREADS`)."""

    def __init__(self) -> None:
        self._base = _task_cpu()
        self._last: dict[int, float] = {}
        self._names: dict[int, str] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="seawatch-bench-clock")
        self._thread.start()

    def _sample(self) -> None:
        self._last.update(_task_cpu())
        for t in threading.enumerate():
            if t.native_id is not None:
                self._names.setdefault(t.native_id, t.name)

    def _run(self) -> None:
        while not self._stop.wait(0.02):
            self._sample()

    def stop(self) -> dict[str, float]:
        self._stop.set()
        self._thread.join()
        self._sample()
        own = self._thread.native_id
        out: dict[str, float] = {}
        for tid, cpu in self._last.items():
            if tid == own:
                continue
            name = self._names.get(tid, NATIVE_THREADS)
            out[name] = out.get(name, 0.0) + cpu - self._base.get(tid, 0.0)
        return {k: v for k, v in out.items() if v > 0.0}


@dataclass(frozen=True)
class _Run:
    """One timed run: wall-clock and process CPU seconds, the frames done, the percentage
    of the machine's CPU time stolen by the hypervisor meanwhile (None where unknown) and
    the CPU seconds per thread name (empty where unknown)."""

    wall: float
    cpu: float
    frames: int
    steal: float | None
    threads: dict[str, float]


def _timed(fn: Callable[[], int]) -> _Run:
    """:class:`_Run` of ``fn()`` (which returns the frames it did)."""
    s0 = _cpu_ticks()
    clock = _ThreadClock()
    t0, c0 = time.perf_counter(), time.process_time()
    n = fn()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    threads = clock.stop()
    s1 = _cpu_ticks()
    steal = None
    if s0 is not None and s1 is not None and s1[1] > s0[1]:
        steal = 100.0 * (s1[0] - s0[0]) / (s1[1] - s0[1])
    return _Run(wall, cpu, n, steal, threads)


# --------------------------------------------------------------------------------------
# agreement
# --------------------------------------------------------------------------------------


def _table_rows(path: Path) -> FloatArray:
    """MOT rows ``(frame, track_id, x, y, w, h)`` of a ``tracks.csv``."""
    rows = []
    with path.open(newline="", encoding="utf-8") as fh:
        for r in csv.DictReader(fh):
            rows.append([float(r[k]) for k in ("frame", "track_id", "x", "y", "w", "h")])
    return np.array(rows, dtype=np.float64).reshape(-1, 6)


def quality(tracks: FloatArray, truth: FloatArray, first: int = SCORED_FROM) -> dict[str, Any]:
    """Tracks (MOT rows ``frame, id, x, y, w, h`` [px]) scored against the truth rows
    from frame ``first`` on: MOTA, IDF1, ID switches, false positives and negatives (box
    IoU ≥ 0.5), the mean CLE [px and % of the truth box diagonal], the coverage of each
    ship and the number of track ids that cover it."""
    from seawatch.metrics import mot_metrics
    from seawatch.metrics.cle import centre_location_error

    tracks = tracks[tracks[:, 0] >= first]
    truth = truth[truth[:, 0] >= first]

    m = mot_metrics(truth, tracks, "iou", 0.5)
    cle = centre_location_error(tracks, truth)
    covered = np.isfinite(cle.per_frame)
    ships = {}
    for oid in np.unique(truth[:, 1]).astype(int):
        sel = truth[:, 1] == oid
        ids = [t for t, o in cle.matches.items() if o == oid]
        ships[str(oid)] = {"coverage": float(np.mean(covered[sel])), "track_ids": len(ids)}
    return {
        "mota": float(m.clear.mota),
        "idf1": float(m.identity.idf1),
        "id_switches": int(m.clear.id_switches),
        "false_positives": int(m.clear.fp),
        "false_negatives": int(m.clear.fn),
        "cle_px": float(cle.mean_px),
        "cle_percent": float(cle.mean_percent),
        "ships": ships,
        "tracks": int(np.unique(tracks[:, 1]).size) if tracks.size else 0,
    }


def _same_tracks(stage: FloatArray, table: FloatArray) -> tuple[bool, float]:
    """Whether two MOT row sets hold the same (frame, id) rows, and their largest box
    difference [px]."""
    if stage.shape[0] != table.shape[0]:
        return False, math.inf
    if stage.shape[0] == 0:
        return True, 0.0
    a = stage[np.lexsort((stage[:, 1], stage[:, 0]))]
    b = table[np.lexsort((table[:, 1], table[:, 0]))]
    if not np.array_equal(a[:, :2], b[:, :2]):
        return False, math.inf
    return True, float(np.max(np.abs(a[:, 2:] - b[:, 2:])))


# --------------------------------------------------------------------------------------
# run
# --------------------------------------------------------------------------------------

VARIANTS = (
    "decode",
    "decode+horizon",
    "decode+horizon+detect",
    "decode+horizon+detect+track",
    "track_video",
)
"""Result names, in the order they run."""


def run(
    frames: int = 250,
    *,
    repeats: int = 3,
    width: int = 1920,
    height: int = 1080,
    fps: float = 25.0,
    seed: int = 0,
    folder: str | Path | None = None,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Run the benchmark; returns the benchmark JSON of INTERFACES.md plus problem,
    stage costs, quality and targets (module docstring).

    Args:
        frames: clip length [frames] (250: 10 s, a stable timing at 1080p).
        repeats: timed runs of each variant; the fastest counts.
        width, height: frame size [px] (the issues' 1920×1080 by default).
        fps: frame rate of the clip [1/s].
        seed: render seed.
        folder: the clip's folder (rendered there once); None: a cache folder under the
            system's temporary directory.
        progress: ``progress(label)`` before each step.
    """
    repeats = integer("repeats", repeats, 1)
    say = progress or (lambda _msg: None)
    say("render")
    clip = render_clip(frames, width=width, height=height, fps=fps, seed=seed, folder=folder)

    from seawatch.scenarios.ship_video import read_truth

    truth = read_truth(clip.truth)
    stage_rows: list[FloatArray] = []
    with tempfile.TemporaryDirectory(prefix="seawatch-bench-video-") as tmp:
        tmp_path = Path(tmp)
        say("warm-up")  # compile or load the numba kernels, open the codecs
        warm = render_clip(
            8, width=min(width, 640), height=min(height, 360), fps=fps, seed=seed,
            folder=tmp_path / "warm",
        )  # fmt: skip
        _stage(warm)
        _track_video(warm, tmp_path / "warm-out")

        runs: dict[str, Callable[[], int]] = {
            "decode": lambda: _decode(clip),
            "decode+horizon": lambda: _horizon(clip),
            "decode+horizon+detect": lambda: _detect(clip),
            "decode+horizon+detect+track": lambda: _stage(clip),
            "track_video": lambda: _track_video(clip, tmp_path / "out"),
        }
        best: dict[str, _Run] = {}
        for name in VARIANTS:
            say(name)
            for _ in range(repeats):
                t = _timed(runs[name])
                if name not in best or t.wall < best[name].wall:
                    best[name] = t
        say("agreement")
        _stage(clip, stage_rows)  # untimed: the image stage's tracks for the comparison
        table = _table_rows(tmp_path / "out" / "tracks.csv")

    stage = np.concatenate(stage_rows) if stage_rows else np.empty((0, 6))
    q = quality(table, truth)
    same, diff = _same_tracks(stage, table)
    fps_of = {k: b.frames / b.wall for k, b in best.items()}
    cpu_of = {k: (b.frames / b.cpu if b.cpu > 0 else math.inf) for k, b in best.items()}
    results = [
        {
            "name": k,
            "value": fps_of[k],
            "unit": "frames/s",
            "cpu_time_frames_per_s": cpu_of[k],
            "steal_percent": best[k].steal,
            "thread_cpu_ms_per_frame": {
                name: 1000.0 * sec / max(best[k].frames, 1) for name, sec in best[k].threads.items()
            },
            "frames": best[k].frames,
        }
        for k in VARIANTS
    ]
    ratios = {f"{k}/decode": fps_of[k] / fps_of["decode"] for k in VARIANTS[1:]}
    ms = {k: 1000.0 / v for k, v in fps_of.items()}
    stage_ms = {
        "decode": ms["decode"],
        "horizon": ms["decode+horizon"] - ms["decode"],
        "detect": ms["decode+horizon+detect"] - ms["decode+horizon"],
        "image_stage_overlapped": ms["decode+horizon+detect+track"],
        "pipeline": ms["track_video"] - ms["decode+horizon+detect+track"],
    }
    ships_ok = all(s["coverage"] >= COVERAGE_MIN for s in q["ships"].values()) and len(
        q["ships"]
    ) == len(_SHIPS)
    quality_ok = (
        ships_ok
        and all(q[k] >= v for k, v in QUALITY_MIN.items())
        and q["cle_percent"] <= CLE_PERCENT_MAX
    )
    targets: dict[str, Any] = {}
    for k in ("track_video", "decode+horizon+detect+track"):
        targets[k] = {
            "target": SPEED_TARGET,
            "measured": fps_of[k],
            "met": bool(fps_of[k] >= SPEED_TARGET),
            "cpu_time_frames_per_s": cpu_of[k],
        }
    for k, v in QUALITY_MIN.items():
        targets[k] = {"target": v, "measured": q[k], "met": bool(q[k] >= v)}
    return {
        "benchmark": "video",
        "problem": {
            "frame_size": [clip.height, clip.width],
            "frames": clip.frames,
            "fps": clip.fps,
            "ships": len(_SHIPS),
            "truth_rows": int(truth.shape[0]),
            "scored_from_frame": SCORED_FROM,
            "clip": str(clip.folder),
            "render_seconds": clip.render_seconds,
            "repeats": int(repeats),
            "cpus": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        },
        "results": results,
        "ratios": ratios,
        "stage_ms_per_frame": stage_ms,
        "agreement": {
            "ok": bool(quality_ok and same and diff <= SAME_TRACKS_TOL),
            "quality_ok": bool(quality_ok),
            "coverage_min": COVERAGE_MIN,
            "cle_percent_max": CLE_PERCENT_MAX,
            "same_tracks_as_image_stage": bool(same),
            "max_abs_diff_px": diff,
            "tolerance_px": SAME_TRACKS_TOL,
        },
        "quality": q,
        "targets": targets,
    }
