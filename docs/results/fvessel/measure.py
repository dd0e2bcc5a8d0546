"""seawatch's ship tracker on real detections: FVessel Video-01 against its authors' tracker.

FVessel Video-01 (Yangtze River, Wuhan; ``../shared/data/fvessel/``, MIT): ground-truth
tracks (5 ships, 1,709 boxes at 1 frame/s over 621 s), the authors' detections
(``Video-01_re_detection.txt``, 1,822 boxes) and their tracker's output on them
(``Video-01_re_tracking.txt``). The same detections are tracked by
:class:`seawatch.vision.tracker.VisualTracker` with its defaults (the AFKF, FKF and KF;
the occlusion handling on; nothing tuned to these data, ``fps`` = 1), and every output
is scored with :func:`seawatch.metrics.mot_metrics` (TrackEval; IoU >= 0.5) against the
ground truth. Two readings of seawatch's output: every confirmed track row (coasting
predictions included), and only the rows a detection updated (as the authors' file,
one row per detection). Also the AFKF with σ_z alone (``sigma_z_rel`` = 0, the box noise
before session 12) and with σ_z = 4 and 8 px instead of the default 2 px.
Writes ``fvessel.json`` beside this file.

    .venv/bin/python docs/results/fvessel/measure.py
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from seawatch.io.mot import read_mot
from seawatch.metrics import mot_metrics
from seawatch.vision.detect import Detections
from seawatch.vision.tracker import FILTERS, VisualTracker, tracks_to_rows

SIGMA_Z_SWEEP = (4.0, 8.0)
"""Box-centre noise σ_z [px] tried besides the default 2 px (the boxes here are 34–431 px
wide at 2560 px; the sweep shows the sensitivity, the defaults are the result)."""
HERE = Path(__file__).resolve().parent
DATA = (HERE.parents[2] / ".." / "shared" / "data" / "fvessel").resolve()


def _scores(gt: np.ndarray, rows: np.ndarray) -> dict[str, float | int]:
    m = mot_metrics(gt, rows, "iou", 0.5)
    c = m.clear
    return {
        "hota": m.hota.hota,
        "mota": c.mota,
        "idf1": m.identity.idf1,
        "id_switches": c.id_switches,
        "fp": c.fp,
        "fn": c.fn,
        "track_ids": int(np.unique(rows[:, 1]).size),
        "rows": int(rows.shape[0]),
    }


def _per_frame(det: np.ndarray, frames: int) -> list[Detections]:
    """Per-frame detections of MOT rows (score 1, water line at the box's bottom centre)."""
    return [Detections.from_boxes(det[det[:, 0] == f, 2:6]) for f in range(frames)]


def main() -> int:
    gt_path = DATA / "Video-01_gt_tracking.txt"
    if not gt_path.is_file():
        print(f"FVessel sample not found at {DATA}", file=sys.stderr)
        return 2
    gt = read_mot(gt_path)
    det = read_mot(DATA / "Video-01_re_detection.txt")
    frames = int(max(gt[:, 0].max(), det[:, 0].max())) + 1
    scans = _per_frame(det, frames)
    result: dict[str, object] = {
        "data": "FVessel Video-01, 621 frames at 1 frame/s, 5 ships (../shared/data/fvessel)",
        "metric": "TrackEval via seawatch.metrics.mot_metrics, IoU >= 0.5",
        "authors_tracker": _scores(gt, read_mot(DATA / "Video-01_re_tracking.txt")),
    }
    runs = [(name, {}) for name in FILTERS]
    runs += [("afkf", {"sigma_z_rel": 0.0})]
    runs += [("afkf", {"sigma_z": sz}) for sz in SIGMA_Z_SWEEP]
    for name, options in runs:
        vt = VisualTracker(
            detector=lambda *a, **k: None, filter=name, horizon=False, fps=1.0, **options
        )
        t0 = time.perf_counter()
        per = vt.track_detections(scans)
        seconds = time.perf_counter() - t0
        updated = [p[p[:, 7] == 0] for p in per]
        key = " ".join([name] + [f"{k}={v:g}" for k, v in options.items()])
        result[key] = {
            "all_rows": _scores(gt, tracks_to_rows(per)),
            "detection_rows": _scores(gt, tracks_to_rows(updated)),
            "seconds": round(seconds, 3),
        }
    (HERE / "fvessel.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
