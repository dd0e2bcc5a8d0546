"""The edges of the system: files in and out (video, camera, AIS, NAV, MOT, track tables).

Degrees, knots and other display units live here and are converted to SI units and
radians on the way in (STYLE.md).
"""

from seawatch.io.ais import (
    AisTable,
    AisWarning,
    interpolate_track,
    read_ais,
    read_ais_csv,
    read_ais_nmea,
    tracks,
)
from seawatch.io.camera_file import FORMAT_TAG, camera_to_dict, load_camera, save_camera
from seawatch.io.mot import read_mot, write_mot
from seawatch.io.nav import NavPoses, NavTrack, NavWarning, parse_time, read_nav
from seawatch.io.track_table import TableWriter, read_table
from seawatch.io.video import (
    Frame,
    VideoError,
    VideoReader,
    VideoWarning,
    VideoWriter,
    read_image,
)

__all__ = [
    "FORMAT_TAG",
    "AisTable",
    "AisWarning",
    "Frame",
    "NavPoses",
    "NavTrack",
    "NavWarning",
    "TableWriter",
    "VideoError",
    "VideoReader",
    "VideoWarning",
    "VideoWriter",
    "camera_to_dict",
    "interpolate_track",
    "load_camera",
    "parse_time",
    "read_ais",
    "read_ais_csv",
    "read_ais_nmea",
    "read_image",
    "read_mot",
    "read_nav",
    "read_table",
    "save_camera",
    "tracks",
    "write_mot",
]
