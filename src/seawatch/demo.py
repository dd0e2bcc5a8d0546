"""The bundled demo (``make demo``, ``seawatch demo``): real Solent ship traffic on video.

A fixed shore camera on the Solent (:func:`seawatch.synth.ais_scene.demo_camera`) watches
the real traffic of the packaged AIS file (Stone Soup's Solent recording of 2016-01-12,
MIT; :func:`seawatch.scenarios.solent_ais.default_ais_path`):

1. ``seawatch synth ais`` renders the vessels in view into a 1080p clip with exact ground
   truth (``clip/video.mp4``, ``truth.csv``, ``horizon.csv``, ``clip.json``) — reused
   when a previous demo rendered the same clip into the same folder;
2. ``seawatch track`` runs on it with the camera, the AIS file and the truth, writing
   everything ``seawatch track`` writes plus the ``camera.yaml`` it used.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from seawatch.pipeline import TrackRun, track_video

__all__ = ["DemoRun", "run_demo"]

Progress = Callable[[str, int, int | None], None]


@dataclass(frozen=True)
class DemoRun:
    """What :func:`run_demo` produced.

    Attributes:
        track: the tracking run (outputs, errors, AIS cross-check).
        camera: the camera file used.
        clip: the rendered clip's folder.
        rendered: False when an earlier identical clip was reused.
    """

    track: TrackRun
    camera: Path
    clip: Path
    rendered: bool

    @property
    def report(self) -> Path:
        """The HTML report."""
        return next(p for p in self.track.outputs if p.name == "report.html")

    def to_json(self) -> dict[str, Any]:
        """``seawatch demo --json``: the ``seawatch track`` summary, the camera and clip."""
        doc = self.track.to_json()
        doc["outputs"] = [*doc["outputs"], str(self.camera)]
        doc["camera"] = str(self.camera)
        doc["clip"] = str(self.clip)
        doc["rendered"] = self.rendered
        return doc


def _settings() -> dict[str, Any]:
    from seawatch.io.camera_file import camera_to_dict
    from seawatch.synth.ais_scene import DEMO, demo_camera
    from seawatch.synth.render import RENDER_VERSION

    return {
        "camera": camera_to_dict(demo_camera()),
        "start": DEMO.start,
        "duration": DEMO.duration,
        "fps": DEMO.fps,
        "lighting": DEMO.lighting,
        "seed": DEMO.seed,
        "coastline": DEMO.coastline,
        "sway": list(DEMO.sway) if DEMO.sway else None,
        "renderer": RENDER_VERSION,
    }


def run_demo(out_dir: str | Path, *, progress: Progress | None = None) -> DemoRun:
    """Render the demo clip (or reuse it) and track it (module docstring).

    Args:
        out_dir: output folder: ``camera.yaml``, ``clip/`` and the ``seawatch track``
            outputs (``tracks.csv``, ``estimates.csv``, ``tracks.geojson``,
            ``annotated.mp4``, ``report.html``).
        progress: ``progress(stage, done, total)`` with stage ``render`` or ``track``.
    """
    from seawatch.io.ais import read_ais
    from seawatch.io.camera_file import save_camera
    from seawatch.scenarios.solent_ais import default_ais_path
    from seawatch.synth.ais_scene import DEMO, demo_camera, render_ais

    out = Path(out_dir)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot write ({exc.strerror or exc})") from None
    camera = demo_camera()
    cam_path = out / "camera.yaml"
    save_camera(camera, cam_path, description="seawatch demo: shore camera on the Solent")
    ais_path = default_ais_path()
    clip = out / "clip"
    stamp = clip / "demo-settings.json"
    settings = _settings()
    rendered = False
    fresh = (
        stamp.is_file()
        and (clip / "video.mp4").is_file()
        and (clip / "truth.csv").is_file()
        and json.loads(stamp.read_text(encoding="utf-8")) == json.loads(json.dumps(settings))
    )
    ais = read_ais(ais_path)  # once, for the rendering and the cross-check
    if not fresh:
        render_ais(
            ais,
            camera,
            out_dir=clip,
            start=DEMO.start,
            duration=DEMO.duration,
            fps=DEMO.fps,
            lighting=DEMO.lighting,
            seed=DEMO.seed,
            sway=DEMO.sway,
            coastline=DEMO.coastline,
            progress=None if progress is None else lambda d, t: progress("render", d, t),
        )
        stamp.write_text(json.dumps(settings, indent=1), encoding="utf-8")
        rendered = True
    run = track_video(
        clip / "video.mp4",
        out,
        camera=camera,
        ais=ais,
        truth=clip / "truth.csv",
        start=DEMO.start,
        progress=None if progress is None else lambda d, t: progress("track", d, t),
    )
    return DemoRun(track=run, camera=cam_path, clip=clip, rendered=rendered)
