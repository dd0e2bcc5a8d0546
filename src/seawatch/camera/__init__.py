"""Camera models: pixels ↔ rays ↔ (azimuth, elevation), attitude and the sea horizon.

ALGORITHMS.md §4.3 (pinhole camera, attitude, horizon-based roll and pitch) and §4.2
(horizon dip). Frames: camera x right, y down, z forward; world NED (x North, y East,
z Down); angles in radians, pitch positive nose-up, roll positive right-side-down.
"""

from seawatch.camera.attitude import (
    R_BC,
    attitude_from_rotation,
    rotation_nb,
    rotation_nc,
    rotation_x,
    rotation_y,
    rotation_z,
)
from seawatch.camera.horizon import (
    HorizonAttitude,
    HorizonLine,
    attitude_from_horizon,
    horizon_dip,
    horizon_line,
)
from seawatch.camera.pinhole import PinholeCamera

__all__ = [
    "R_BC",
    "HorizonAttitude",
    "HorizonLine",
    "PinholeCamera",
    "attitude_from_horizon",
    "attitude_from_rotation",
    "horizon_dip",
    "horizon_line",
    "rotation_nb",
    "rotation_nc",
    "rotation_x",
    "rotation_y",
    "rotation_z",
]
