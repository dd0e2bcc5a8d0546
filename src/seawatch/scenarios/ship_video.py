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
interior (neither end of the swept range). With an output folder the figures are drawn
too (:func:`plot_cle`): ``cle.png``, the error per case and filter (the paper's Tables
1–2) beside the error against the fractional order (its order figure).
"""

from __future__ import annotations

import contextlib
import csv
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from seawatch._validation import integer
from seawatch.io.video import VideoReader
from seawatch.metrics.cle import CLEResult, centre_location_error
from seawatch.scenarios.base import ExperimentResult, ProgressCallback, record
from seawatch.synth import render_case
from seawatch.synth.cases import CASES
from seawatch.vision.detect import POLARITIES, ClassicalShipDetector
from seawatch.vision.tracker import DEFAULT_ORDER, FILTERS, VisualTracker, tracks_to_rows

__all__ = ["ORDERS", "chunk", "merge", "plot_cle", "run", "track_case", "unit_costs", "units"]

ORDERS: tuple[float, ...] = (0.7, 0.8, 0.9, 0.95, 1.0)
"""Fractional orders of the sweep (ALGORITHMS.md §1.3: tunable 0.8–1.0, default 0.95)."""

SWEEP_CASE = "small"
PARALLEL_MIN_COST = 5.0
"""Parallel protocol: a run of less than this (in :func:`unit_costs`, one 960×540 case =
1) stays in one process unless ``workers`` is given (a local cluster takes 5–10 s)."""


def read_truth(path: str | Path) -> np.ndarray:
    """MOT rows ``(frame, object_id, x, y, w, h)`` [px] of a truth.csv from the renderer."""
    rows = []
    with Path(path).open(newline="", encoding="utf-8") as f:
        for r in csv.DictReader(f):
            rows.append([float(r["frame"]), float(r["object_id"])] + [float(r[k]) for k in "xywh"])
    return np.array(rows, dtype=np.float64).reshape(-1, 6)


def detect_video(
    video: str | Path,
    tracker: VisualTracker | None = None,
    offsets: list[np.ndarray] | None = None,
    horizons: list[Any] | None = None,
    zooms: list[np.ndarray] | None = None,
) -> list[np.ndarray]:
    """Per-frame detections (k, 7) of a video (horizon + detector of ``tracker``); with a
    list ``offsets``, each frame's camera offset is appended to it
    (:meth:`VisualTracker.next_offset`), with a list ``horizons`` its horizon
    (:meth:`VisualTracker.next_horizon`), with a list ``zooms`` its camera zoom
    (:meth:`VisualTracker.next_zoom`)."""
    vt = tracker if tracker is not None else VisualTracker()
    vt.reset()
    out = []
    with VideoReader(video) as reader:
        for _, _, det in vt.stream(reader):
            out.append(det)
            offset, line, zoom = vt.next_offset(), vt.next_horizon(), vt.next_zoom()
            if offsets is not None:
                offsets.append(offset)
            if horizons is not None:
                horizons.append(line)
            if zooms is not None:
                zooms.append(zoom)
    return out


def track_case(
    detections: Sequence[np.ndarray],
    truth: np.ndarray,
    filter: str,
    offsets: Sequence[np.ndarray] | None = None,
    horizons: Sequence[Any] | None = None,
    zooms: Sequence[np.ndarray] | None = None,
    **options: Any,
) -> CLEResult:
    """CLE (§1.6) of :class:`VisualTracker` with ``filter`` on precomputed detections
    (and the frames' camera ``offsets``, ``horizons`` and ``zooms``,
    :func:`detect_video`)."""
    vt = VisualTracker(detector=_no_detector, filter=filter, horizon=False, **options)  # type: ignore[arg-type]
    tracks = vt.track_detections(detections, offsets, horizons, zooms)
    return centre_location_error(tracks_to_rows(tracks), truth)


def _no_detector(image: Any, **_: Any) -> None:  # pragma: no cover - never called
    raise RuntimeError("track_case runs on precomputed detections")


def _names(cases: Sequence[str] | None) -> list[str]:
    names = list(CASES if cases is None else cases)
    for n in names:
        if n not in CASES:
            raise ValueError(f"cases: unknown case {n!r}; expected some of {', '.join(CASES)}")
    return names


def _orders(orders: Sequence[float]) -> list[float]:
    alphas = [float(a) for a in orders]
    if any(not (a > 0) for a in alphas):
        raise ValueError(f"orders: expected positive fractional orders, got {orders!r}")
    return alphas


def units(runs: int = 1, cases: Sequence[str] | None = None, **_: Any) -> int:
    """Parallel protocol: one work unit per rendering (run × case)."""
    return integer("runs", runs, 1) * len(_names(cases))


def unit_costs(
    runs: int = 1,
    cases: Sequence[str] | None = None,
    small_scale: int = 2,
    orders: Sequence[float] = ORDERS,
    **_: Any,
) -> np.ndarray:
    """Parallel protocol: relative cost of each unit (pixels rendered and detected; the
    small case is ``small_scale``² larger and is tracked once more per swept order)."""
    names = _names(cases)
    one = [small_scale**2 * (1.0 + 0.1 * len(orders)) if n == SWEEP_CASE else 1.0 for n in names]
    return np.tile(np.array(one), integer("runs", runs, 1))


def _unit_options(
    width: int,
    height: int,
    duration: float,
    orders: Sequence[float],
    small_scale: int,
    fps: float,
    crf: int,
    polarity: str,
) -> dict[str, Any]:
    """The rendering, detection and sweep options of :func:`_unit`, checked."""
    if polarity not in POLARITIES:
        raise ValueError(f"polarity: expected both, dark or bright, got {polarity!r}")
    return {
        "width": width,
        "height": height,
        "duration": duration,
        "orders": _orders(orders),
        "small_scale": small_scale,
        "fps": fps,
        "crf": integer("crf", crf, 0, 51),  # libx264's range
        "polarity": polarity,
    }


def _case(u: int, names: list[str]) -> tuple[int, str]:
    """Unit ``u`` is run ``u // len(names)`` of case ``names[u % len(names)]``."""
    r, i = divmod(u, len(names))
    return r, names[i]


def _unit(
    u: int,
    names: list[str],
    seed: int,
    folder: Path,
    width: int,
    height: int,
    duration: float,
    orders: list[float],
    small_scale: int,
    fps: float,
    crf: int,
    polarity: str,
) -> dict[str, Any]:
    """Render (into ``folder``), detect and track unit ``u`` (:func:`_case`); rows
    ``(estimator, order, cle_px, cle_percent, precision)`` with order None except in the
    sweep."""
    r, name = _case(u, names)
    k = small_scale if name == SWEEP_CASE else 1
    res = render_case(
        name,
        folder,
        duration=duration,
        fps=fps,
        width=width * k,
        height=height * k,
        seed=seed + r,
        crf=crf,
    )
    detector = ClassicalShipDetector(polarity=polarity)  # type: ignore[arg-type]
    offsets: list[np.ndarray] = []
    lines: list[Any] = []
    zooms: list[np.ndarray] = []
    vt = VisualTracker(detector=detector, fps=fps)
    dets = detect_video(res.video, vt, offsets, lines, zooms)
    truth = read_truth(res.truth)
    rows: list[tuple[str, float | None, float, float, float]] = []
    for est in FILTERS:
        c = track_case(dets, truth, est, offsets, lines, zooms)
        rows.append((est, None, c.mean_px, c.mean_percent, c.precision))
    if name == SWEEP_CASE:
        for a in orders:
            c = track_case(dets, truth, "afkf", offsets, lines, zooms, order=a)
            rows.append(("afkf", a, c.mean_px, c.mean_percent, c.precision))
    return {"run": r, "case": name, "crf": crf, "polarity": polarity, "rows": rows}


_HEADER = ["case", "run", "estimator", "order", "cle_px", "cle_percent", "precision"]


def _csv_rows(unit: dict[str, Any]) -> list[list[Any]]:
    return [
        [unit["case"], unit["run"], est, "" if a is None else a, px, pct, prec]
        for est, a, px, pct, prec in unit["rows"]
    ]


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
    crf: int = 20,
    polarity: str = "both",
) -> ExperimentResult:
    """Run the ship-video experiment (module docstring).

    Args:
        runs: renderings per case (seeds ``seed``, ``seed + 1``, …); records hold the
            mean and standard error over them.
        seed: first rendering seed.
        out_dir: keep the footage and write ``cle.csv`` here (a row per case and filter
            as it is produced); None: a temporary folder.
        progress: ``progress(done, total)`` after each rendered and tracked case.
        cases: case names (default all of :data:`seawatch.synth.cases.CASES`).
        width, height: frame size [px] (the small case: ``small_scale`` times it).
        duration: clip length [s]; fps: frame rate [1/s].
        orders: fractional orders of the AFKF sweep on the small case (when it is run).
        crf: libx264 quality of the rendered footage (0–51; default 20, as the
            ``seawatch synth`` clips; 0 is lossless, which isolates the error of the
            detector and tracker from the compression's).
        polarity: ships the classical detector looks for (``both``; ``dark`` for a camera
            facing the sun, :func:`seawatch.vision.external.make_detector`).

    Returns:
        :class:`ExperimentResult` with records ``cle_px``, ``cle_percent``,
        ``cle_precision`` per estimator (afkf, fkf, kf) and case, and the order sweep.
        Run on Dask (``--workers``, :mod:`seawatch.scenarios.parallel`), the same records
        come from :func:`chunk` and :func:`merge`, without the footage.
    """
    n_runs = integer("runs", runs, 1)
    names = _names(cases)
    opts = _unit_options(width, height, duration, orders, small_scale, fps, crf, polarity)
    with contextlib.ExitStack() as stack:
        if out_dir is None:
            root = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="seawatch-sv-")))
            tw = None
        else:
            root = Path(out_dir)
            root.mkdir(parents=True, exist_ok=True)
            table = stack.enter_context((root / "cle.csv").open("w", newline="", encoding="utf-8"))
            tw = csv.writer(table)
            tw.writerow(_HEADER)
        done: list[dict[str, Any]] = []
        total = n_runs * len(names)
        for u in range(total):
            r, name = _case(u, names)
            folder = root / (name if n_runs == 1 else f"{name}-{r}")
            done.append(_unit(u, names, seed, folder, **opts))
            if tw is not None:
                tw.writerows(_csv_rows(done[-1]))
                table.flush()
            if progress is not None:
                progress(len(done), total)
    outputs: list[Path] = []
    if out_dir is not None:
        outputs = [Path(out_dir) / "cle.csv", plot_cle(done, Path(out_dir) / "cle.png")]
    return _result(done, names, n_runs, seed, outputs)


def chunk(
    indices: Sequence[int],
    runs: int = 1,
    seed: int = 0,
    *,
    progress: ProgressCallback | None = None,
    cases: Sequence[str] | None = None,
    width: int = 960,
    height: int = 540,
    duration: float = 8.0,
    orders: Sequence[float] = ORDERS,
    small_scale: int = 2,
    fps: float = 25.0,
    crf: int = 20,
    polarity: str = "both",
) -> list[dict[str, Any]]:
    """Units ``indices`` (run × case, see :func:`units`) of the experiment, rendered in a
    temporary folder (the parallel protocol of :mod:`seawatch.scenarios.parallel`); a
    unit's numbers depend only on (seed, run, case)."""
    names = _names(cases)
    opts = _unit_options(width, height, duration, orders, small_scale, fps, crf, polarity)
    idx = [int(i) for i in indices]
    n = integer("runs", runs, 1) * len(names)
    if not idx or idx != sorted(set(idx)) or idx[0] < 0 or idx[-1] >= n:
        raise ValueError(f"indices: expected increasing units in 0 … {n - 1}, got {indices!r}")
    out = []
    with tempfile.TemporaryDirectory(prefix="seawatch-sv-") as tmp:
        for u in idx:
            out.append(_unit(u, names, seed, Path(tmp) / str(u), **opts))
            if progress is not None:
                progress(len(out), len(idx))
    return out


def merge(
    payloads: Sequence[list[dict[str, Any]]],
    runs: int = 1,
    seed: int = 0,
    out_dir: str | Path | None = None,
    cases: Sequence[str] | None = None,
    **_: Any,
) -> ExperimentResult:
    """The records (and ``cle.csv`` in ``out_dir``) from the payloads of :func:`chunk` in
    unit order (the parallel protocol of :mod:`seawatch.scenarios.parallel`)."""
    names = _names(cases)
    done = [u for p in payloads for u in p]
    if len(done) != integer("runs", runs, 1) * len(names):
        raise ValueError(f"payloads: expected {runs * len(names)} units, got {len(done)}")
    outputs: list[Path] = []
    if out_dir is not None:
        root = Path(out_dir)
        root.mkdir(parents=True, exist_ok=True)
        with (root / "cle.csv").open("w", newline="", encoding="utf-8") as table:
            tw = csv.writer(table)
            tw.writerow(_HEADER)
            for unit in done:
                tw.writerows(_csv_rows(unit))
        outputs += [root / "cle.csv", plot_cle(done, root / "cle.png")]
    return _result(done, names, runs, seed, outputs)


def _tables(
    done: Sequence[dict[str, Any]],
) -> tuple[dict[tuple[str, str, str], list[float]], dict[float, list[float]]]:
    """The units' numbers: ``(estimator, metric, case) → values over the renderings`` for
    cle_px, cle_percent and cle_precision, and ``order → cle_percent values`` of the
    sweep."""
    values: dict[tuple[str, str, str], list[float]] = {}
    sweep: dict[float, list[float]] = {}
    for unit in done:
        for est, a, px, pct, prec in unit["rows"]:
            if a is None:
                for metric, v in (("cle_px", px), ("cle_percent", pct), ("cle_precision", prec)):
                    values.setdefault((est, metric, unit["case"]), []).append(v)
            else:
                sweep.setdefault(a, []).append(pct)
    return values, sweep


def plot_cle(done: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """The experiment's figures in one PNG: (a) the centre location error [% of the truth
    box diagonal] per case for the adaptive fractional, fractional and integer-order KF
    (bars: the mean over the renderings, dots: each rendering; log scale) — the paper's
    Tables 1–2; (b) the AFKF's error on the small case against the fractional order
    (dots: each rendering, line: their mean; the default order marked) — its order
    figure. ``done``: the units of :func:`run` / :func:`chunk`."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    cases = list(dict.fromkeys(u["case"] for u in done))
    values, sweep = _tables(done)
    fig = Figure(figsize=(11.0, 4.2), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 2, 1)
    colours = {"afkf": "#d62728", "fkf": "#1f77b4", "kf": "#7f7f7f"}
    width = 0.27
    for k, est in enumerate(FILTERS):
        x = np.arange(len(cases)) + (k - 1) * width
        vals = [np.asarray(values.get((est, "cle_percent", c), [np.nan])) for c in cases]
        ax.bar(x, [np.nanmean(v) for v in vals], width, color=colours[est], label=est)
        for xi, v in zip(x, vals, strict=True):
            if v.size > 1:
                ax.plot(np.full(v.size, xi), v, "o", color="black", ms=2.5)
    ax.axhline(2.0, color="black", lw=0.8, ls="--", label="2 % (issue 6 target)")
    ax.set_yscale("log")
    ax.set_xticks(np.arange(len(cases)), cases, rotation=30, ha="right")
    ax.set_ylabel("centre location error [% of box diagonal]")
    ax.set_title("(a) per case and filter")
    ax.grid(True, axis="y", which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax = fig.add_subplot(1, 2, 2)
    if sweep:
        orders = sorted(sweep)
        for a in orders:
            ax.plot(np.full(len(sweep[a]), a), sweep[a], "o", color="#d62728", ms=3, alpha=0.6)
        ax.plot(orders, [np.nanmean(sweep[a]) for a in orders], "-", color="#d62728",
                label="afkf, mean")  # fmt: skip
        ax.axvline(
            DEFAULT_ORDER, color="black", lw=0.8, ls=":", label=f"default order {DEFAULT_ORDER:g}"
        )
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no order sweep (small case not run)", ha="center",
                transform=ax.transAxes)  # fmt: skip
    ax.set_xlabel("fractional order α")
    ax.set_ylabel("centre location error [% of box diagonal]")
    ax.set_title(f"(b) {SWEEP_CASE} case: error against the order")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path)
    return Path(path)


def _result(
    done: list[dict[str, Any]], names: list[str], runs: int, seed: int, outputs: list[Path]
) -> ExperimentResult:
    values, sweep = _tables(done)
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
    extra: dict[str, Any] = {
        "ordering": ordering,
        "crf": done[0]["crf"] if done else None,
        "polarity": done[0].get("polarity", "both") if done else None,
    }
    swept = {a: float(np.nanmean(v)) for a, v in sweep.items() if v}
    if swept and all(np.isfinite(list(swept.values()))):
        best = min(swept, key=lambda a: swept[a])
        extra["best_order"] = best
        extra["best_order_interior"] = bool(min(swept) < best < max(swept))
    return ExperimentResult("ship-video", runs, seed, results, outputs, extra)
