"""The per-frame loop shared by ``seawatch detect`` and ``horizon``
(:func:`seawatch.cli._common.frame_records`), on a real image folder."""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import cv2
import numpy as np

from seawatch.cli._common import frame_records, run_summary
from seawatch.io.prefetch import DEPTH
from seawatch.io.video import VideoReader


def _folder(tmp_path: Path, n: int) -> Path:
    for k in range(n):
        cv2.imwrite(str(tmp_path / f"f{k:03d}.png"), np.full((16, 16), 10 * k, np.uint8))
    return tmp_path


def _slow(frame) -> dict:
    time.sleep(0.1)  # a consumer far slower than the folder is read
    return {"index": int(frame.index)}


def test_keep_up_drops_what_arrives_while_the_queue_is_full(tmp_path):
    """20 images read in a few ms against 0.1 s of work each: the loop processes the
    ``DEPTH`` frames that wait (and the first, if it was taken up before they
    were queued, and a frame or two more on a loaded machine), drops the rest
    unprocessed, counts them and warns once; every frame is processed or counted, in
    order."""
    reader = VideoReader(_folder(tmp_path, 20), fps=25.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = frame_records(reader, "t", _slow, output=None, columns=(), csv_rows=list,
                            keep_up=True)  # fmt: skip
    index = [r["index"] for r in run.records]
    assert len(index) + run.dropped == 20 and index == sorted(index)
    assert index[0] == 0 and DEPTH <= len(index) <= DEPTH + 4
    assert run.failure is None
    assert sum("dropped to keep up" in str(w.message) for w in caught) == 1
    assert run_summary(run)["frames_dropped"] == run.dropped


def test_without_keep_up_a_slow_consumer_loses_nothing(tmp_path):
    reader = VideoReader(_folder(tmp_path, 6), fps=25.0)
    run = frame_records(reader, "t", _slow, output=None, columns=(), csv_rows=list)
    assert [r["index"] for r in run.records] == list(range(6)) and run.dropped == 0
    assert set(run_summary(run)) == {"frames"}
