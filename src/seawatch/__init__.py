"""seawatch: passive electro-optical tracking of targets at sea.

Video from ordinary cameras in; azimuth/elevation angles, ranges, positions and
tracks of ships and small targets out. See README.md for the tour.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("seawatch")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
