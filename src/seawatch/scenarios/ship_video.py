"""Scenario ``ship-video``: visual ship tracking in rendered CCTV footage (seed 001).

SCENARIOS.md ``ship-video``; ALGORITHMS.md §1. For every case of
:mod:`seawatch.synth` (small / medium / large ship, complex lighting, night, meeting,
overtaking, crossing) the footage is rendered with its ground truth, the detector (with
the horizon) runs once over the decoded video, and the *same* detections are tracked
three times by :class:`~seawatch.vision.tracker.VisualTracker` — with the adaptive
fractional KF (``afkf``), the fractional KF with constant state noise (``fkf``) and the
integer-order KF (``kf``) — so the comparison is of the filters alone. The centre
location error of the confirmed tracks against truth.csv is reported as §1.6's numbers:
``cle_px`` (mean CLE, px), ``cle_percent`` (CLE / truth box diagonal, %) and
``cle_precision`` (% of truth frames with CLE <= 20 px, missed frames failing), with
``params {"case": name}``. The fractional-order sweep re-tracks the small-ship case's
detections with the AFKF at each order (other parameters unchanged): ``cle_percent``
with ``params {"order": alpha}``.

The small case's boat is a few pixels high at 1920×1080; at a smaller frame it would be
under a pixel, so that case is rendered at ``small_scale`` × the frame size (default 2).

The paper's claims checked (``extra`` of the result): ``ordering`` per case, whether
``cle_percent`` of afkf <= fkf <= kf; ``best_order`` of the sweep and whether it is
interior (neither end of the swept range).
"""

from __future__ import annotations

import csv
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from seawatch.io.video import VideoReader
from seawatch.metrics.cle import CLEResult, centre_location_error
from seawatch.scenarios.base import ExperimentResult, ProgressCallback, record
from seawatch.synth import render_case
from seawatch.synth.cases import CASES
from seawatch.vision.tracker import FILTERS, VisualTracker, tracks_to_rows

__all__ = ["ORDERS", "run", "track_case"]

ORDERS: tuple[float, ...] = (0.7, 0.8, 0.9, 0.95, 1.0)
"""Fractional orders of the sweep (ALGORITHMS.md §1.3: tunable 0.8–1.0, default 0.95)."""

SWEEP_CASE = "small"


def read_truth(path: str | Path) -> np.ndarray:
    """MOT rows ``(frame, object_id, x, y, w, h)`` [px] of a truth.csv from the renderer."""
    rows = []
    with Path(path).open(newline="", encoding="utf-8") as f:
        for r in csv.DictReader(f):
            rows.append([float(r["frame"]), float(r["object_id"])] + [float(r[k]) for k in "xywh"])
    return np.array(rows, dtype=np.float64).reshape(-1, 6)


def detect_video(video: str | Path, tracker: VisualTracker | None = None) -> list[np.ndarray]:
    """Per-frame detections (k, 7) of a video (horizon + detector of ``tracker``)."""
    vt = tracker if tracker is not None else VisualTracker()
    vt.reset()
    with VideoReader(video) as reader:
        return [vt.detect(fr.image, fr.time) for fr in reader]


def track_case(
    detections: Sequence[np.ndarray], truth: np.ndarray, filter: str, **options: Any
) -> CLEResult:
    """CLE (§1.6) of :class:`VisualTracker` with ``filter`` on precomputed detections."""
    vt = VisualTracker(detector=_no_detector, filter=filter, horizon=False, **options)  # type: ignore[arg-type]
    tracks = vt.track_detections(detections)
    return centre_location_error(tracks_to_rows(tracks), truth)


def _no_detector(image: Any, **_: Any) -> None:  # pragma: no cover - never called
    raise RuntimeError("track_case runs on precomputed detections")


def run(
    runs: int = 1,
    seed: int = 0,
    out_dir: str | Path | None = None,
    progress: ProgressCallback | None = None,
    cases: Sequence[str] | None = None,
    width: int = 960,
    height: int = 540,
    duration: float = 8.0,
    *,
    orders: Sequence[float] = ORDERS,
    small_scale: int = 2,
    fps: float = 25.0,
) -> ExperimentResult:
    """Run the ship-video experiment (module docstring).

    Args:
        runs: renderings per case (seeds ``seed``, ``seed + 1``, …); records hold the
            mean and standard error over them.
        seed: first rendering seed.
        out_dir: keep the footage and write ``cle.csv`` here; None: a temporary folder.
        progress: ``progress(done, total)`` after each rendered and tracked case.
        cases: case names (default all of :data:`seawatch.synth.cases.CASES`).
        width, height: frame size [px] (the small case: ``small_scale`` times it).
        duration: clip length [s]; fps: frame rate [1/s].
        orders: fractional orders of the AFKF sweep on the small case (when it is run).

    Returns:
        :class:`ExperimentResult` with records ``cle_px``, ``cle_percent``,
        ``cle_precision`` per estimator (afkf, fkf, kf) and case, and the order sweep.
    """
    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1:
        raise ValueError(f"runs: expected an integer >= 1, got {runs!r}")
    names = list(CASES if cases is None else cases)
    for n in names:
        if n not in CASES:
            raise ValueError(f"cases: unknown case {n!r}; expected some of {', '.join(CASES)}")
    alphas = [float(a) for a in orders]
    if any(not (a > 0) for a in alphas):
        raise ValueError(f"orders: expected positive fractional orders, got {orders!r}")
    tmp = None
    if out_dir is None:
        tmp = tempfile.TemporaryDirectory(prefix="seawatch-ship-video-")
        root = Path(tmp.name)
    else:
        root = Path(out_dir)
        root.mkdir(parents=True, exist_ok=True)
    values: dict[tuple[str, str, str], list[float]] = {}
    sweep: dict[float, list[float]] = {a: [] for a in alphas}
    outputs: list[Path] = []
    table = None
    if out_dir is not None:
        table_path = root / "cle.csv"
        table = table_path.open("w", newline="", encoding="utf-8")
        tw = csv.writer(table)
        tw.writerow(["case", "run", "estimator", "order", "cle_px", "cle_percent", "precision"])
        outputs.append(table_path)
    total = len(names) * runs
    done = 0
    try:
        for r in range(runs):
            for name in names:
                k = small_scale if name == SWEEP_CASE else 1
                folder = root / (f"{name}" if runs == 1 else f"{name}-{r}")
                res = render_case(
                    name,
                    folder,
                    duration=duration,
                    fps=fps,
                    width=width * k,
                    height=height * k,
                    seed=seed + r,
                )
                dets = detect_video(res.video, VisualTracker(fps=fps))
                truth = read_truth(res.truth)
                for est in FILTERS:
                    c = track_case(dets, truth, est)
                    for metric, v in (
                        ("cle_px", c.mean_px),
                        ("cle_percent", c.mean_percent),
                        ("cle_precision", c.precision),
                    ):
                        values.setdefault((est, metric, name), []).append(v)
                    if table is not None:
                        tw.writerow([name, r, est, "", c.mean_px, c.mean_percent, c.precision])
                if name == SWEEP_CASE:
                    for a in alphas:
                        c = track_case(dets, truth, "afkf", order=a)
                        sweep[a].append(c.mean_percent)
                        if table is not None:
                            tw.writerow(
                                [name, r, "afkf", a, c.mean_px, c.mean_percent, c.precision]
                            )
                if table is not None:
                    table.flush()
                done += 1
                if progress is not None:
                    progress(done, total)
    finally:
        if table is not None:
            table.close()
        if tmp is not None:
            tmp.cleanup()
    units = {"cle_px": "px", "cle_percent": "%", "cle_precision": "%"}
    results = [
        record(est, metric, units[metric], v, params={"case": name})
        for (est, metric, name), v in values.items()
    ]
    results += [
        record("afkf", "cle_percent", "%", v, params={"order": a}) for a, v in sweep.items() if v
    ]
    ordering = {}
    for name in names:
        m = [float(np.nanmean(values[(e, "cle_percent", name)])) for e in FILTERS]
        ordering[name] = bool(m[0] <= m[1] <= m[2])
    extra: dict[str, Any] = {"ordering": ordering}
    swept = {a: float(np.nanmean(v)) for a, v in sweep.items() if v}
    if swept and all(np.isfinite(list(swept.values()))):
        best = min(swept, key=lambda a: swept[a])
        extra["best_order"] = best
        extra["best_order_interior"] = bool(min(swept) < best < max(swept))
    return ExperimentResult("ship-video", runs, seed, results, outputs, extra)
