"""The edges of the system: files in and out (camera files; more readers to come).

Degrees, knots and other display units live here and are converted to SI units and
radians on the way in (STYLE.md).
"""

from seawatch.io.camera_file import FORMAT_TAG, camera_to_dict, load_camera, save_camera

__all__ = ["FORMAT_TAG", "camera_to_dict", "load_camera", "save_camera"]
