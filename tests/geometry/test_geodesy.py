"""Local ENU/NED/north-east ↔ WGS-84 (pymap3d): round trips and independent closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from seawatch.geometry.geodesy import (
    destination,
    enu_to_geodetic,
    geodetic_to_enu,
    geodetic_to_ned,
    geodetic_to_north_east,
    ned_to_geodetic,
    north_east_to_geodetic,
)

A = 6_378_137.0  # WGS-84 semi-major axis [m]
F = 1.0 / 298.257223563
E2 = F * (2.0 - F)

lats = st.floats(-80.0, 80.0)
lons = st.floats(-180.0, 179.999)
offsets = st.floats(-50_000.0, 50_000.0)


def _metres_between(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Small-distance separation on the ellipsoid [m] (meridian/prime-vertical radii)."""
    phi = math.radians(lat1)
    w = math.sqrt(1 - E2 * math.sin(phi) ** 2)
    M = A * (1 - E2) / w**3
    N = A / w
    dlon = (lon2 - lon1 + 180.0) % 360.0 - 180.0
    return math.hypot(math.radians(lat2 - lat1) * M, math.radians(dlon) * N * math.cos(phi))


@given(
    lat0=lats,
    lon0=lons,
    alt0=st.floats(-100.0, 3000.0),
    e=offsets,
    n=offsets,
    u=st.floats(-500.0, 500.0),
)
def test_enu_geodetic_round_trip_within_a_millimetre(
    lat0: float, lon0: float, alt0: float, e: float, n: float, u: float
) -> None:
    lat, lon, alt = enu_to_geodetic(e, n, u, lat0, lon0, alt0)
    e2, n2, u2 = geodetic_to_enu(lat, lon, alt, lat0, lon0, alt0)
    assert math.dist((e, n, u), (e2, n2, u2)) < 1e-3
    # and back again: the geodetic position is reproduced to < 1 mm on the ground
    lat3, lon3, alt3 = enu_to_geodetic(e2, n2, u2, lat0, lon0, alt0)
    assert _metres_between(lat, lon, lat3, lon3) < 1e-3 and abs(alt3 - alt) < 1e-3


@given(lat0=lats, lon0=lons, north=offsets, east=offsets, down=st.floats(-500.0, 500.0))
def test_ned_is_enu_with_swapped_axes_and_round_trips(
    lat0: float, lon0: float, north: float, east: float, down: float
) -> None:
    lat, lon, alt = ned_to_geodetic(north, east, down, lat0, lon0, 10.0)
    lat_e, lon_e, alt_e = enu_to_geodetic(east, north, -down, lat0, lon0, 10.0)
    assert (lat, lon, alt) == pytest.approx((lat_e, lon_e, alt_e), abs=1e-12)
    n2, e2, d2 = geodetic_to_ned(lat, lon, alt, lat0, lon0, 10.0)
    assert math.dist((north, east, down), (n2, e2, d2)) < 1e-3


@given(lat0=lats, lon0=lons, north=offsets, east=offsets, up=st.floats(-50.0, 50.0))
def test_north_east_round_trip_within_a_millimetre(
    lat0: float, lon0: float, north: float, east: float, up: float
) -> None:
    xy = np.array([[north, east], [0.5 * north, -east]])
    lat, lon = north_east_to_geodetic(xy, lat0, lon0, alt0=5.0, up=up)
    back = geodetic_to_north_east(lat, lon, lat0, lon0, alt0=5.0, up=up)
    assert np.max(np.linalg.norm(back - xy, axis=1)) < 1e-3


@pytest.mark.parametrize("lat0", [0.0, 45.0, 60.0, -33.0])
def test_small_offsets_follow_the_meridian_and_prime_vertical_radii(lat0: float) -> None:
    phi = math.radians(lat0)
    w = math.sqrt(1 - E2 * math.sin(phi) ** 2)
    M, N = A * (1 - E2) / w**3, A / w
    lat, lon = north_east_to_geodetic([[10.0, 0.0], [0.0, 10.0]], lat0, 3.0)
    assert math.radians(lat[0] - lat0) * M == pytest.approx(10.0, rel=1e-6)
    assert math.radians(lon[1] - 3.0) * N * math.cos(phi) == pytest.approx(10.0, rel=1e-6)


def test_one_nautical_mile_north_is_about_one_arc_minute() -> None:
    lat, _ = north_east_to_geodetic([1852.0, 0.0], 45.0, 0.0)
    assert (lat - 45.0) * 60.0 == pytest.approx(1.0, abs=2e-3)


def test_destination_agrees_with_the_tangent_plane_at_short_range() -> None:
    az = np.radians([0.0, 37.0, 90.0, 200.0])
    D = 3000.0
    lat, lon = destination(50.8, -1.3, D, az)
    lat_t, lon_t = north_east_to_geodetic(
        np.stack([D * np.cos(az), D * np.sin(az)], -1), 50.8, -1.3
    )
    for i in range(4):
        assert _metres_between(lat[i], lon[i], lat_t[i], lon_t[i]) < 0.05


def test_longitudes_wrap_across_the_antimeridian() -> None:
    lat, lon = north_east_to_geodetic([0.0, 5000.0], 10.0, 179.99)
    assert -180.0 <= lon < -179.9
    back = geodetic_to_north_east(lat, lon, 10.0, 179.99)
    np.testing.assert_allclose(back, [0.0, 5000.0], atol=1e-3)


def test_nan_rows_give_nan_and_bad_origins_raise() -> None:
    lat, _ = north_east_to_geodetic([[np.nan, 0.0], [10.0, 0.0]], 50.0, 1.0)
    assert np.isnan(lat[0]) and np.isfinite(lat[1])
    dl, _ = destination(50.0, 1.0, [np.inf, 10.0, -1.0], 0.0)
    assert np.isnan(dl[0]) and np.isfinite(dl[1]) and np.isnan(dl[2])
    with pytest.raises(ValueError, match="lat0"):
        enu_to_geodetic(0.0, 0.0, 0.0, 95.0, 0.0)
    with pytest.raises(ValueError, match="lon0"):
        geodetic_to_enu(0.0, 0.0, 0.0, 0.0, np.nan)
    with pytest.raises(ValueError, match="xy"):
        north_east_to_geodetic([1.0, 2.0, 3.0], 0.0, 0.0)
