"""Measure issue 7's track targets on rendered moving-platform clips (full size, 1080p).

    .venv/bin/python docs/results/track/measure.py [--out out/track-targets]
        [--preset uav-sea --preset range-1km] [--fps 10] [--attitude auto]

For each preset of :data:`seawatch.synth.platform_clip.PRESETS` it renders the clip
(:func:`render_platform_clip`, 1920×1080), runs the CLI exactly as a user would::

    python -m seawatch track CLIP/video.mp4 --camera CLIP/camera.yaml \\
        --platform CLIP/nav.csv --start 0 --truth CLIP/truth_world.csv \\
        --out CLIP/run --no-video --no-report --json

and scores the run (:func:`score_platform_run`: against ``truth_world.csv``, ranges from
the moving camera). Writes ``<preset>.json`` next to this script (or ``--results``): the clip,
timings, the CLI's own ``errors`` (world-frame truth) and the platform-frame errors per
estimator and range bin, and the issue's targets evaluated.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from seawatch.synth.platform_clip import (
    PRESETS,
    platform_clip_preset,
    render_platform_clip,
    score_platform_run,
)

HERE = Path(__file__).resolve().parent


def _targets(errors: dict[str, Any]) -> dict[str, Any]:
    """Issue 7's targets from a platform-frame ``errors`` object."""
    est = errors["estimators"]
    geo, ekf = est["geometry"], est["ekf"]
    geo_bins = {b["range_from_m"]: b for b in geo["range_bins"]}
    per_bin = []
    for b in ekf["range_bins"]:
        g = geo_bins.get(b["range_from_m"])
        if g is None:
            continue
        per_bin.append(
            {
                "range_from_m": b["range_from_m"],
                "range_to_m": b["range_to_m"],
                "ekf_rmse_m": b["rmse_position_m"],
                "geometry_rmse_m": g["rmse_position_m"],
                "ekf_not_worse": b["rmse_position_m"] <= g["rmse_position_m"],
            }
        )
    ratio = ekf["rmse_position_m"] / geo["rmse_position_m"]
    one_km = next((b for b in ekf["range_bins"] if b["range_from_m"] == 750.0), None)
    return {
        "ekf_over_geometry_rmse": ratio,
        "ekf_30pct_lower": ratio <= 0.7,
        "ekf_not_worse_every_bin": all(b["ekf_not_worse"] for b in per_bin),
        "per_bin": per_bin,
        "ekf_range_error_percent_750_1250m": None
        if one_km is None
        else one_km["rmse_range_percent"],
        "range_under_5pct_at_1km": None if one_km is None else one_km["rmse_range_percent"] < 5.0,
        "mota": errors["mota"],
        "mota_over_0.8": errors["mota"] > 0.8,
        "id_switches": errors["id_switches"],
        "at_most_one_switch": errors["id_switches"] <= 1,
        "one_id_per_object": all(len(o["track_ids"]) == 1 for o in errors["objects"]),
    }


def measure(preset: str, out: Path, fps: float, attitude: str, results: Path) -> dict[str, Any]:
    """Render, track (CLI) and score one preset; write ``results/<preset>.json``."""
    clip_dir = out / preset
    kw = platform_clip_preset(preset, fps=fps)
    t0 = time.perf_counter()
    clip = render_platform_clip(clip_dir, **kw)
    t_render = time.perf_counter() - t0
    run_dir = clip_dir / "run"
    cmd = [
        sys.executable, "-m", "seawatch", "track", str(clip.video),
        "--camera", str(clip.camera), "--platform", str(clip.nav), "--start", "0",
        "--truth", str(clip.truth_world), "--out", str(run_dir), "--attitude", attitude,
        "--no-video", "--no-report", "--json",
    ]  # fmt: skip
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    t_track = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"seawatch track failed ({proc.returncode}):\n{proc.stderr}")
    cli = json.loads(proc.stdout)
    errors = score_platform_run(run_dir, clip_dir).to_json()
    for key in ("files",):
        errors.pop(key, None)
    doc = {
        "preset": preset,
        "clip": json.loads(clip.meta.read_text(encoding="utf-8")),
        "command": " ".join(cmd[1:]),
        "attitude": attitude,
        "frames": cli["frames"],
        "render_seconds": round(t_render, 2),
        "track_seconds": round(t_track, 2),
        "track_frames_per_second": round(cli["frames"] / t_track, 2),
        "targets": _targets(errors),
        "errors_platform_frame": errors,
        "errors_cli_world_truth": {
            k: v for k, v in cli.get("errors", {}).items() if k not in ("files", "objects")
        },
        "warnings": cli.get("warnings", []),
    }
    results.mkdir(parents=True, exist_ok=True)
    path = results / f"{preset}{'' if attitude == 'auto' else '-' + attitude}.json"
    path.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    return doc


def main(argv: list[str] | None = None) -> None:
    """Command line (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("out/track-targets"))
    ap.add_argument("--results", type=Path, default=HERE)
    ap.add_argument("--preset", action="append", choices=list(PRESETS))
    ap.add_argument("--fps", type=float, default=10.0)
    ap.add_argument("--attitude", default="auto", choices=["auto", "horizon", "file"])
    a = ap.parse_args(argv)
    for preset in a.preset or list(PRESETS):
        doc = measure(preset, a.out, a.fps, a.attitude, a.results)
        t = doc["targets"]
        est = doc["errors_platform_frame"]["estimators"]
        print(
            f"{preset}: {doc['frames']} frames, track {doc['track_frames_per_second']} frames/s; "
            + ", ".join(
                f"{n} {e['rmse_position_m']:.1f} m / {e['rmse_range_percent']:.1f} %"
                for n, e in est.items()
                if n != "tracks"
            )
            + f"; EKF/geometry {t['ekf_over_geometry_rmse']:.2f}, MOTA {t['mota']:.3f}, "
            f"ID switches {t['id_switches']}"
        )


if __name__ == "__main__":
    main()
