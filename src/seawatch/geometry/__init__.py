"""Rays to metres: sea-surface ranging, known-size ranging and geodesy.

- :mod:`seawatch.geometry.sea` — flat (ALGORITHMS.md §4.1, seed 000 eqs. 3–5) and curved
  (§4.2, refraction) sea ranges, horizon dip/distance, target positions, their errors
  (§4.2 sensitivity, §7(a)) and where the flat model stops being good enough.
- :mod:`seawatch.geometry.size` — range from the image size of a known-size target
  (§5.1, seed 002 eqs. 14–15), including the off-axis subtended-angle form.
- :mod:`seawatch.geometry.geodesy` — local ENU/NED/north-east ↔ WGS-84 (pymap3d).

Conventions: x North, y East [m]; angles in radians, azimuths clockwise from North,
depressions positive below the true horizontal; degrees only for latitude/longitude.
"""

from seawatch.geometry.geodesy import (
    destination,
    enu_to_geodetic,
    geodetic_to_enu,
    geodetic_to_ned,
    geodetic_to_north_east,
    ned_to_geodetic,
    north_east_to_geodetic,
)
from seawatch.geometry.sea import (
    DEFAULT_REFRACTION,
    EARTH_RADIUS,
    RangeFlag,
    SeaPosition,
    SeaRange,
    curved_sea_range,
    effective_radius,
    flat_error_limit,
    flat_sea_range,
    horizon_dip,
    horizon_distance,
    range_sigma,
    sea_depression,
    sea_position,
    sea_position_covariance,
    sea_range,
)
from seawatch.geometry.size import (
    size_range,
    size_range_sigma,
    subtended_angle,
    subtended_range,
    subtended_range_sigma,
)

__all__ = [
    "DEFAULT_REFRACTION",
    "EARTH_RADIUS",
    "RangeFlag",
    "SeaPosition",
    "SeaRange",
    "curved_sea_range",
    "destination",
    "effective_radius",
    "enu_to_geodetic",
    "flat_error_limit",
    "flat_sea_range",
    "geodetic_to_enu",
    "geodetic_to_ned",
    "geodetic_to_north_east",
    "horizon_dip",
    "horizon_distance",
    "ned_to_geodetic",
    "north_east_to_geodetic",
    "range_sigma",
    "sea_depression",
    "sea_position",
    "sea_position_covariance",
    "sea_range",
    "size_range",
    "size_range_sigma",
    "subtended_angle",
    "subtended_range",
    "subtended_range_sigma",
]
