"""Frames dropped to keep up: the ship-video cases tracked with frames left out.

    .venv/bin/python docs/results/live/drops.py [--cases meeting crossing …] [--seed 0]

A job slower than its camera sees only some frames (``--keep-up``). Which ones depends
on the host and its load, so this measurement fixes them: each rendered ``ship-video``
case (the experiment's rendering: 960×540, 8 s at 25 frames/s, the small case at twice
the size; ``--seed``) is detected once, frame by frame, and its detections are tracked
(:class:`~seawatch.vision.tracker.VisualTracker`, the AFKF, as ``seawatch track``) over
the frames of a drop pattern alone: every frame, every second, every third, and 30, 50
and 70 % of the frames dropped at random (seed 0). The frames between two frames given
are handed to the tracker in one of two ways:

- ``coast``: :meth:`VisualTracker.coast` — frames not looked at (what ``track`` does);
- ``empty``: frames looked at without a detection (``update(None)``), which is how
  session 25's ``coast`` counted them.

Per case and pattern: the frames given, the coverage (truth boxes of those frames with a
confirmed track on them, §1.6's matching), the CLE (mean px and % of the diagonal) and
the track ids matched to each ship. Writes ``drops.json`` beside this script.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from seawatch.metrics.cle import centre_location_error
from seawatch.scenarios.ship_video import detect_video, read_truth
from seawatch.synth import render_case
from seawatch.synth.cases import CASES
from seawatch.vision.tracker import VisualTracker, tracks_to_rows

HERE = Path(__file__).resolve().parent
PATTERNS: list[tuple[str, int | None, float]] = [
    ("all", 1, 0.0),
    ("every 2nd", 2, 0.0),
    ("every 3rd", 3, 0.0),
    ("30 % at random", None, 0.3),
    ("50 % at random", None, 0.5),
    ("70 % at random", None, 0.7),
]


def _given(n: int, every: int | None, rate: float) -> np.ndarray:
    """Indices of the frames a pattern gives the tracker."""
    if every is not None:
        return np.arange(0, n, every)
    return np.flatnonzero(np.random.default_rng(0).random(n) >= rate)


def _track(dets: list, offsets: list, lines: list, given: np.ndarray, rule: str) -> np.ndarray:
    """MOT rows ``(frame, id, x, y, w, h)`` of the confirmed tracks at the frames given."""
    vt = VisualTracker(detector=lambda *a, **k: None, horizon=False)
    per_frame = []
    last = None
    for k in given:
        if last is not None and k - last > 1:
            if rule == "coast":
                vt.coast(int(k - last - 1))
            else:
                for _ in range(last + 1, k):  # the camera offset of the last frame seen
                    vt.update(None, offset=offsets[last], horizon=None)
        last = int(k)
        per_frame.append(vt.update(dets[k], offset=offsets[k], horizon=lines[k]))
    rows = tracks_to_rows(per_frame)
    rows[:, 0] = given[rows[:, 0].astype(int)]  # the source frame of each row
    return rows


def _score(rows: np.ndarray, truth: np.ndarray, given: np.ndarray) -> dict[str, Any]:
    gt = truth[np.isin(truth[:, 0], given)]
    cle = centre_location_error(rows, gt)
    ships = {}
    for oid in np.unique(gt[:, 1]).astype(int):
        ids = sorted(int(t) for t, o in cle.matches.items() if int(o) == oid)
        ships[str(oid)] = ids
    return {
        "frames_given": int(given.size),
        "coverage": float(cle.coverage),
        "cle_px": float(cle.mean_px),
        "cle_percent": float(cle.mean_percent),
        "track_ids_per_ship": ships,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--results", type=Path, default=HERE / "drops.json")
    args = ap.parse_args()
    out: dict[str, Any] = {"seed": args.seed, "cases": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for case in args.cases:
            k = 2 if case == "small" else 1
            res = render_case(
                case, Path(tmp) / case, duration=8.0, width=960 * k, height=540 * k, seed=args.seed
            )
            offsets: list[np.ndarray] = []
            lines: list[Any] = []
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                dets = detect_video(res.video, VisualTracker(), offsets, lines)
            truth = read_truth(res.truth)
            out["cases"][case] = {}
            for name, every, rate in PATTERNS:
                given = _given(len(dets), every, rate)
                cell = {}
                for rule in ("coast", "empty"):
                    cell[rule] = _score(_track(dets, offsets, lines, given, rule), truth, given)
                out["cases"][case][name] = cell
                c, e = cell["coast"], cell["empty"]
                print(
                    f"{case:10s} {name:15s} {c['frames_given']:3d} frames  coverage "
                    f"{c['coverage']:.3f} (empty {e['coverage']:.3f})  CLE "
                    f"{c['cle_percent']:6.2f} % ({e['cle_percent']:6.2f})  ids "
                    f"{c['track_ids_per_ship']} ({e['track_ids_per_ship']})",
                    flush=True,
                )
    args.results.write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.results}")


if __name__ == "__main__":
    main()
