"""Issue 6's detection target on real thermal pixels, through the CLI — and tracking.

Runs ``seawatch detect`` on the 88 MarDCT ir-3 frames of ``../shared/data/mardct_ir3/``
(read in place: see its README) and scores the boxes against the annotated boat box of
each frame: a *hit* is a detection centre within 12 px (city block) of the annotated
box centre, every other box is a *false box*. Issue 6 asks for recall >= 0.9 with at
most 0.5 false boxes per frame. The frames are stored as RGBA; a thermal camera gives
one grey channel, so the same frames are also written as one-channel PNGs under
``--out`` and scored the same way (``one_channel``). Writes ``mardct_ir3.json`` beside
this file (and the CLI's ``boxes.csv`` files under ``--out``).

Tracking (``tracking``): ``seawatch track`` on the same frames (no camera: pixel tracks;
the source states no frame rate, 25 frames/s is assumed, which changes nothing but the
time column) scored against the annotated boxes as pixel truth (``--truth``: MOTA,
IDF1, HOTA and the centre error of the matched boxes, IoU >= 0.3; ``errors_centre_12px``:
the same with the boxes matched by their centres, within 12 px), and seed 001's
comparison of the filters on real pixels: the centre location error (ALGORITHMS.md
§1.6, :func:`seawatch.metrics.centre_location_error`) of
:class:`~seawatch.vision.tracker.VisualTracker` with the adaptive fractional KF, the
fractional KF and the integer-order KF.

    .venv/bin/python docs/results/detect/measure.py --out out/detect-mardct
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
DATA = (HERE.parents[2] / ".." / "shared" / "data" / "mardct_ir3").resolve()
RADIUS = 12.0  # [px], city block, issue 6


def score(boxes_csv: Path, truth_csv: Path) -> dict[str, float | int]:
    """Recall, false boxes per frame and the hits' centre error of a ``seawatch detect``
    BOXES.csv against the annotated boxes (matched by file name)."""
    truth = {r["file"]: r for r in csv.DictReader(truth_csv.open())}
    found: dict[str, list[list[float]]] = {name: [] for name in truth}
    for r in csv.DictReader(boxes_csv.open()):
        name = Path(r["file"]).name
        if name in found:
            found[name].append([float(r[k]) for k in ("x", "y", "w", "h")])
    hits = false = 0
    errors = []
    for name, t in truth.items():
        x, y, w, h = (float(t[k]) for k in "xywh")
        b = np.array(found[name]).reshape(-1, 4)
        d = np.abs(b[:, :2] + b[:, 2:] / 2 - [x + w / 2, y + h / 2])
        city = d.sum(axis=1)
        near = city <= RADIUS
        hits += bool(near.any())
        false += int((~near).sum())
        if near.any():
            errors.append(float(np.hypot(*d[np.argmin(city)])))
    n = len(truth)
    return {
        "frames": n,
        "hits": hits,
        "recall": hits / n,
        "false_boxes": false,
        "false_boxes_per_frame": false / n,
        "hit_centre_error_px_mean": float(np.mean(errors)) if errors else float("nan"),
        "hit_centre_error_px_median": float(np.median(errors)) if errors else float("nan"),
    }


def pixel_truth(truth_csv: Path, out: Path) -> Path:
    """The annotated boxes as a pixel truth table for ``seawatch track --truth``
    (``frame`` = the frame's index in file-name order, ``object_id`` 1)."""
    rows = sorted(csv.DictReader(truth_csv.open()), key=lambda r: int(r["frame"]))
    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["frame", "object_id", "x", "y", "w", "h"])
        for i, r in enumerate(rows):
            w.writerow([i, 1, r["x"], r["y"], r["w"], r["h"]])
    return out


def track(out: Path) -> dict[str, object]:
    """``seawatch track`` on the frames against the annotated boxes, and the centre
    location error of each filter (module docstring)."""
    from seawatch.io.video import VideoReader
    from seawatch.metrics.cle import centre_location_error
    from seawatch.metrics.track_errors import score_tracks
    from seawatch.vision.tracker import FILTERS, VisualTracker, tracks_to_rows

    truth = pixel_truth(DATA / "boxes.csv", out / "truth-pixels.csv")
    images = os.path.relpath(DATA / "images")
    cmd = [sys.executable, "-m", "seawatch", "track", images, "--fps", "25"]
    cmd += ["--truth", str(truth), "--out", str(out / "track")]
    cmd += ["--no-video", "--no-report", "--json"]
    run = subprocess.run(cmd, check=True, capture_output=True, text=True)
    summary = json.loads(run.stdout)
    keep = ("cle_px", "mota", "idf1", "hota", "id_switches", "tp", "fp", "fn", "track_ids")
    gt = np.loadtxt(truth, delimiter=",", skiprows=1, ndmin=2)
    cle = {}
    for name in FILTERS:
        vt = VisualTracker(filter=name, fps=25.0)
        with VideoReader(DATA / "images", fps=25.0) as reader:
            rows = tracks_to_rows(vt.track_frames(reader))
        c = centre_location_error(rows, gt)
        cle[name] = {
            "cle_px": c.mean_px,
            "cle_percent": c.mean_percent,
            "precision": c.precision,
            "coverage": c.coverage,
        }
    # the annotated boxes are looser than the detector's (13.6 x 9.8 against about 9 x 5
    # px), so IoU >= 0.3 misses some true pairs: also matched by centre, within the
    # detection target's 12 px
    near = score_tracks(out / "track" / "tracks.csv", truth, match="centre", gate_px=RADIUS)
    return {
        "command": " ".join(["seawatch", *cmd[3:]]),
        "errors": {k: summary["errors"][k] for k in keep if k in summary["errors"]},
        "errors_centre_12px": {k: getattr(near, k) for k in keep},
        "cle": cle,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("out/detect-mardct"))
    args = ap.parse_args()
    if not (DATA / "boxes.csv").is_file():
        print(f"MarDCT ir-3 frames not found at {DATA}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    boxes = args.out / "boxes.csv"
    images = os.path.relpath(DATA / "images")
    cmd = [sys.executable, "-m", "seawatch", "detect", images, "-o", str(boxes)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    seconds = time.perf_counter() - t0
    grey = args.out / "one-channel"
    grey.mkdir(exist_ok=True)
    for path in sorted((DATA / "images").glob("*.png")):
        cv2.imwrite(str(grey / path.name), cv2.imread(str(path), cv2.IMREAD_GRAYSCALE))
    grey_boxes = args.out / "boxes-one-channel.csv"
    grey_cmd = [*cmd[:4], str(grey), "-o", str(grey_boxes)]
    subprocess.run(grey_cmd, check=True, stdout=subprocess.DEVNULL)
    result = {
        "data": "MarDCT ir-3, 88 frames 640x512 (TIRSD annotations), ../shared/data/mardct_ir3",
        "command": " ".join(["seawatch", *cmd[3:]]),
        "radius_px_city_block": RADIUS,
        **score(boxes, DATA / "boxes.csv"),
        "targets": {"recall": 0.9, "false_boxes_per_frame": 0.5},
        "seconds": round(seconds, 2),
        "one_channel": {
            "command": " ".join(["seawatch", *grey_cmd[3:]]),
            **score(grey_boxes, DATA / "boxes.csv"),
        },
    }
    result["tracking"] = track(args.out)
    both = (result, result["one_channel"])
    result["met"] = all(r["recall"] >= 0.9 and r["false_boxes_per_frame"] <= 0.5 for r in both)
    (HERE / "mardct_ir3.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
