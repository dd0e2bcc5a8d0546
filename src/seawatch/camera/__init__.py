"""Camera models: pixels ↔ rays ↔ (azimuth, elevation), attitude, the sea horizon,
stereo triangulation (§6) and calibration.

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
from seawatch.camera.calibration import (
    CameraCalibration,
    StereoCalibration,
    calibrate_camera,
    calibrate_stereo,
    find_corners,
)
from seawatch.camera.horizon import (
    HorizonAttitude,
    HorizonLine,
    attitude_from_horizon,
    horizon_dip,
    horizon_line,
)
from seawatch.camera.pinhole import PinholeCamera
from seawatch.camera.stereo import (
    SEED003_CALIBRATION,
    StereoRig,
    Triangulation,
    TriangulationFlag,
    depth_bias,
    depth_sigma,
    disparity_to_depth,
    projection_matrices_from_calibration,
    rectified_point,
    triangulate,
    triangulate_points,
    triangulation_covariance,
)

__all__ = [
    "R_BC",
    "SEED003_CALIBRATION",
    "CameraCalibration",
    "HorizonAttitude",
    "HorizonLine",
    "PinholeCamera",
    "StereoCalibration",
    "StereoRig",
    "Triangulation",
    "TriangulationFlag",
    "attitude_from_horizon",
    "attitude_from_rotation",
    "calibrate_camera",
    "calibrate_stereo",
    "depth_bias",
    "depth_sigma",
    "disparity_to_depth",
    "find_corners",
    "horizon_dip",
    "horizon_line",
    "projection_matrices_from_calibration",
    "rectified_point",
    "rotation_nb",
    "rotation_nc",
    "rotation_x",
    "rotation_y",
    "rotation_z",
    "triangulate",
    "triangulate_points",
    "triangulation_covariance",
]
