"""Synthetic footage with exact ground truth (`seawatch synth`).

- :mod:`seawatch.synth.world` — ships (hull and superstructure prisms) on world
  trajectories, encounter helpers (meeting, overtaking, crossing) and
  :func:`ships_from_tracks`, the hook for AIS traffic.
- :mod:`seawatch.synth.render` — the renderer: sky, sea with waves, glint, haze, sway,
  day/dusk/night-thermal lighting, ships as shaded silhouettes; writes ``video.mp4``,
  ``camera.yaml``, ``truth.csv`` and ``horizon.csv`` (INTERFACES.md).
- :mod:`seawatch.synth.cases` — the ``ship-video`` cases of SCENARIOS.md (seed 001).
"""

from seawatch.synth.ais_scene import (
    DEMO,
    AisRenderResult,
    AisScene,
    DemoSettings,
    ais_ships,
    busiest_start,
    demo_camera,
    render_ais,
)
from seawatch.synth.cases import CASES, ShipVideoCase, render_case, ship_video_case
from seawatch.synth.render import (
    HORIZON_COLUMNS,
    LIGHTINGS,
    TRUTH_COLUMNS,
    Lighting,
    ObjectTruth,
    RenderedFrame,
    Renderer,
    RenderResult,
    lighting_preset,
    render,
    sway_attitude,
)
from seawatch.synth.world import (
    KINDS,
    Prism,
    Ship,
    Trajectory,
    crossing,
    hull_prism,
    make_ship,
    meeting,
    overtaking,
    ships_from_tracks,
    straight,
    through,
    turning,
)

__all__ = [
    "CASES",
    "DEMO",
    "HORIZON_COLUMNS",
    "KINDS",
    "LIGHTINGS",
    "TRUTH_COLUMNS",
    "AisRenderResult",
    "AisScene",
    "DemoSettings",
    "Lighting",
    "ObjectTruth",
    "Prism",
    "RenderResult",
    "RenderedFrame",
    "Renderer",
    "Ship",
    "ShipVideoCase",
    "Trajectory",
    "ais_ships",
    "busiest_start",
    "crossing",
    "demo_camera",
    "hull_prism",
    "lighting_preset",
    "make_ship",
    "meeting",
    "overtaking",
    "render",
    "render_ais",
    "render_case",
    "ship_video_case",
    "ships_from_tracks",
    "straight",
    "sway_attitude",
    "through",
    "turning",
]
