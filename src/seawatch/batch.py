"""Many recordings, one task each, on Dask (``seawatch batch``; INTERFACES.md).

Each source (video file, image folder or stream) is one :func:`seawatch.pipeline.track_video`
run into its own folder ``out_dir/<source name>/`` on a Dask worker — a local cluster of
single-threaded processes by default, or an existing scheduler (``scheduler=``) for a
cluster. A recording that fails (an undecodable file, a missing folder) is reported with
its error and the others go on; ``batch.json`` in ``out_dir`` is rewritten as each task
ends, so an interrupted batch keeps the summaries of the recordings done.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["BatchItem", "BatchResult", "track_batch"]


@dataclass(frozen=True)
class BatchItem:
    """One recording of a batch: its output folder and ``seawatch track`` summary, or
    the error that stopped it."""

    source: str
    out_dir: Path
    summary: dict[str, Any] | None = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None

    def to_json(self) -> dict[str, Any]:
        doc: dict[str, Any] = {"source": self.source, "out": str(self.out_dir), "ok": self.ok}
        if self.summary is not None:
            doc["summary"] = self.summary
        if self.error is not None:
            doc["error"] = self.error
        return doc


@dataclass(frozen=True)
class BatchResult:
    """Every recording of a batch, in the order given."""

    items: list[BatchItem] = field(default_factory=list)
    summary_path: Path | None = None

    @property
    def failed(self) -> list[BatchItem]:
        return [it for it in self.items if not it.ok]

    def to_json(self) -> dict[str, Any]:
        """``seawatch batch --json``."""
        return {
            "recordings": len(self.items),
            "ok": sum(it.ok for it in self.items),
            "failed": len(self.failed),
            "items": [it.to_json() for it in self.items],
            "outputs": [] if self.summary_path is None else [str(self.summary_path)],
        }


def _folder_names(sources: Sequence[str]) -> list[str]:
    """One output folder name per source: its file stem, made unique with a suffix."""
    names: list[str] = []
    for src in sources:
        stem = Path(str(src).rstrip("/")).stem or "source"
        name, k = stem, 2
        while name in names:
            name, k = f"{stem}-{k}", k + 1
        names.append(name)
    return names


def _track_one(
    source: str,
    out_dir: str,
    camera: str | None,
    options: dict[str, Any],
    detector_options: dict[str, Any],
) -> Any:
    """The task of one recording (runs on a worker): a summary dict or an error string.
    Each recording gets its own detector (one keeps work buffers and, with the temporal
    model, the recording's clutter)."""
    import warnings

    from seawatch.io.camera_file import load_camera
    from seawatch.pipeline import track_video
    from seawatch.vision.external import make_detector

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # they are in the summary's "warnings"
            cam = load_camera(camera) if camera is not None else None
            detector = make_detector(**detector_options)
            run = track_video(source, out_dir, camera=cam, detector=detector, **options)
        return run.to_json()
    except Exception as exc:  # reported per recording; the others go on
        return f"{type(exc).__name__}: {exc}"


def track_batch(
    sources: Sequence[str | os.PathLike[str]],
    out_dir: str | Path,
    *,
    camera: str | Path | None = None,
    workers: int | None = None,
    scheduler: Any = None,
    progress: Callable[[int, int], None] | None = None,
    detector_options: Mapping[str, Any] | None = None,
    **options: Any,
) -> BatchResult:
    """Track every recording of ``sources`` into ``out_dir/<name>/`` (module docstring).

    Args:
        sources: video files, image folders or stream URLs.
        out_dir: the batch's output folder (``batch.json`` and one folder per source).
        camera: the camera file of the recordings (read on each worker), or None.
        workers: local Dask worker processes (default: the machine's cores); 1 runs the
            recordings one after the other in this process, without Dask.
        scheduler: address of an existing Dask scheduler (``tcp://HOST:8786``).
        progress: ``progress(done, total)`` after each recording.
        detector_options: keywords of :func:`seawatch.vision.external.make_detector`
            (``model``, ``threshold``, ``polarity``, ``temporal``, ``mask``); each
            recording gets a detector of its own. None: the classical detector's defaults.
        options: further :func:`seawatch.pipeline.track_video` keywords (``estimator``,
            ``attitude``, ``annotate``, ``report``, …; files such as ``truth`` do not
            apply to a whole batch).

    Raises:
        ValueError: no source, an unwritable ``out_dir``, a missing camera file or bad
            detector options (before any work); SchedulerError (a ValueError) when the
            scheduler does not answer.
    """
    from seawatch.report.geojson import atomic_write_text
    from seawatch.vision.external import make_detector

    srcs = [str(s) for s in sources]
    if not srcs:
        raise ValueError("SOURCES: expected at least one video, folder or stream")
    det_opts = dict(detector_options or {})
    for key in ("model", "mask"):  # files are read on the workers: absolute paths
        if det_opts.get(key) is not None:
            det_opts[key] = str(Path(det_opts[key]).resolve())
    make_detector(**det_opts)  # bad options fail here, before any work
    if camera is not None and not Path(camera).is_file():
        raise ValueError(f"--camera {camera}: no such file")
    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot write ({exc.strerror or exc})") from None
    cam = None if camera is None else str(Path(camera).resolve())
    folders = [str(out / n) for n in _folder_names(srcs)]
    results: list[Any] = [None] * len(srcs)
    summary_path = out / "batch.json"

    def record(i: int, value: Any, done: int) -> None:
        results[i] = value
        items = _items(srcs, folders, results)
        text = json.dumps(BatchResult(items, summary_path).to_json(), indent=1)
        atomic_write_text(summary_path, text)
        if progress is not None:
            progress(done, len(srcs))

    if workers == 1 and scheduler is None:
        for i, (src, folder) in enumerate(zip(srcs, folders, strict=True)):
            record(i, _track_one(src, folder, cam, options, det_opts), i + 1)
    else:
        from distributed import as_completed

        from seawatch.scenarios.parallel import dask_client

        with dask_client(workers, scheduler) as client:
            futures = [
                client.submit(_track_one, src, folder, cam, options, det_opts, pure=False)
                for src, folder in zip(srcs, folders, strict=True)
            ]
            index = {f.key: i for i, f in enumerate(futures)}
            for done, fut in enumerate(as_completed(futures, loop=client.loop), start=1):
                record(index[fut.key], fut.result(), done)
    return BatchResult(_items(srcs, folders, results), summary_path)


def _items(srcs: list[str], folders: list[str], results: list[Any]) -> list[BatchItem]:
    items = []
    for src, folder, res in zip(srcs, folders, results, strict=True):
        if res is None:
            items.append(BatchItem(src, Path(folder), error="not run (batch interrupted)"))
        elif isinstance(res, str):
            items.append(BatchItem(src, Path(folder), error=res))
        else:
            items.append(BatchItem(src, Path(folder), summary=res))
    return items
