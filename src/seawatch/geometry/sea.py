"""Monocular sea-surface ranging: flat and curved sea, horizon, positions and their errors.

Implements ALGORITHMS.md §4.1 (flat sea, seed 000 eqs. 3–5), §4.2 (earth curvature with
terrestrial refraction, horizon dip and distance, exact ray–sphere range, sensitivity)
and the first-order error propagation behind §7(a).

Conventions (ALGORITHMS.md "Conventions"): local frame x North, y East [m]; azimuths
clockwise from North [rad]; the relative azimuth ``alpha`` is measured from the platform
heading ``psi``, clockwise; the depression ``beta`` (also written ``delta``) is the angle
of the line of sight **below the true horizontal** [rad], not below the visible horizon
(§4.1 pitfall; on a real sea the visible horizon lies :func:`horizon_dip` below it).

Bad input never raises inside a batch: a depression at or above the horizon (``beta <= 0``
on the flat sea, ``beta`` smaller than the dip on the curved sea) gives range = +inf and
flag :attr:`RangeFlag.ABOVE_HORIZON`; NaN inputs, or a depression beyond the nadir
(``beta > pi/2``), give NaN and flag :attr:`RangeFlag.INVALID`. Only configuration errors
(a finite camera height <= 0, a refraction coefficient outside [0, 1), negative sigmas)
raise ValueError naming the argument.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from seawatch._validation import FloatArray, as_float_array, finite, in_range

EARTH_RADIUS = 6_371_000.0
"""Mean earth radius R [m] (ALGORITHMS.md §4.2)."""

DEFAULT_REFRACTION = 0.14
"""Typical optical terrestrial refraction coefficient k (ALGORITHMS.md §4.2: 0.13–0.17)."""

__all__ = [
    "DEFAULT_REFRACTION",
    "EARTH_RADIUS",
    "RangeFlag",
    "SeaPosition",
    "SeaRange",
    "curved_sea_range",
    "effective_radius",
    "flat_error_limit",
    "flat_sea_range",
    "horizon_dip",
    "horizon_distance",
    "range_sigma",
    "sea_depression",
    "sea_position",
    "sea_position_covariance",
    "sea_range",
]


class RangeFlag(enum.IntEnum):
    """Per-row status of a sea-surface range (stored as int8 arrays)."""

    OK = 0
    """Finite range, the line of sight meets the sea."""
    ABOVE_HORIZON = 1
    """The line of sight is at or above the horizon: range = +inf, position NaN."""
    INVALID = 2
    """NaN input or a depression beyond the nadir (> pi/2): range and position NaN."""


# ----------------------------------------------------------------------------- helpers
def _height(height: ArrayLike) -> FloatArray:
    """Camera height [m]: NaN allowed (NaN rows), finite values must be > 0."""
    h = as_float_array("height", height)
    if np.any(np.isinf(h)) or np.any(h[np.isfinite(h)] <= 0.0):
        raise ValueError(f"height: expected camera heights > 0 m (NaN allowed), got {height!r}")
    return h


def _refraction(refraction: float) -> float:
    return in_range("refraction", refraction, 0.0, 1.0, hi_open=True)


def _earth_radius(earth_radius: float) -> float:
    return in_range("earth_radius", earth_radius, 0.0, np.inf, lo_open=True, hi_open=True)


def _sigma(name: str, value: ArrayLike) -> FloatArray:
    """A standard deviation (array): NaN allowed (NaN rows), finite values must be >= 0."""
    s = as_float_array(name, value)
    if np.any(np.isinf(s)) or np.any(s[np.isfinite(s)] < 0.0):
        raise ValueError(f"{name}: expected standard deviations >= 0 (NaN allowed), got {value!r}")
    return s


def _scalar_or_array(a: FloatArray) -> FloatArray:
    return a[()] if a.ndim == 0 else a


def effective_radius(
    refraction: float = DEFAULT_REFRACTION, earth_radius: float = EARTH_RADIUS
) -> float:
    """Effective earth radius ``R_e = R / (1 - k)`` [m] (ALGORITHMS.md §4.2).

    Args:
        refraction: terrestrial refraction coefficient k in [0, 1) (0 = geometric).
        earth_radius: earth radius R [m].
    """
    return _earth_radius(earth_radius) / (1.0 - _refraction(refraction))


def horizon_dip(
    height: ArrayLike,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Dip of the visible sea horizon below the true horizontal [rad] (ALGORITHMS.md §4.2).

        dip = arccos( R_e / (R_e + h) ) = atan( sqrt(2 R_e h + h^2) / R_e ) ≈ sqrt(2 h / R_e)

    (the atan form is the same angle without the cancellation of arccos near 1).
    Example: h = 5 m, k = 0.14 gives 0.0666 deg; the geometric dip (k = 0) is
    1.93' sqrt(h [m]).

    Args:
        height: camera height h above the sea [m], > 0 (array; NaN gives NaN).
        refraction: refraction coefficient k in [0, 1).
        earth_radius: earth radius R [m].
    """
    h = _height(height)
    Re = effective_radius(refraction, earth_radius)
    return _scalar_or_array(np.arctan(np.sqrt(2.0 * Re * h + h * h) / Re))


def horizon_distance(
    height: ArrayLike,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Distance to the visible sea horizon [m] (ALGORITHMS.md §4.2).

        D_hor = sqrt( 2 R_e h + h^2 ) ≈ sqrt( 2 R_e h )     (h = 5 m, k = 0.14: 8.6 km)

    This is the line-of-sight (tangent) length; the distance along the sea surface,
    ``R_e * dip``, which :func:`curved_sea_range` returns at the dip, is shorter by the
    fraction ``dip^2 / 3`` (< 1e-5 for h < 100 m).

    Args:
        height: camera height h above the sea [m], > 0 (array; NaN gives NaN).
        refraction: refraction coefficient k in [0, 1).
        earth_radius: earth radius R [m].
    """
    h = _height(height)
    Re = effective_radius(refraction, earth_radius)
    return _scalar_or_array(np.sqrt(2.0 * Re * h + h * h))


# ----------------------------------------------------------------------------- ranges
def _range_and_flag(
    depression: ArrayLike,
    height: ArrayLike,
    curved: bool,
    refraction: float,
    earth_radius: float,
) -> tuple[FloatArray, NDArray[np.int8], FloatArray, FloatArray]:
    """Range [m], flag, and the broadcast (depression, height) arrays."""
    beta = as_float_array("depression", depression)
    h = _height(height)
    beta, h = np.broadcast_arrays(beta, h)
    flag = np.zeros(beta.shape, dtype=np.int8)
    invalid = ~(np.isfinite(beta) & np.isfinite(h)) | (beta > 0.5 * np.pi)
    b = np.where(invalid, 0.5, beta)  # harmless placeholders, overwritten below
    hh = np.where(invalid, 1.0, h)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if not curved:
            # seed 000 eq. 5 / ALGORITHMS.md §4.1: d = h / tan(beta)
            above = b <= 0.0
            rng = hh / np.tan(np.where(above, 0.5, b))
        else:
            # ALGORITHMS.md §4.2: ray–sphere intersection, camera at C = R_e + h
            Re = effective_radius(refraction, earth_radius)
            C = Re + hh
            c = 2.0 * Re * hh + hh * hh  # C^2 - R_e^2
            sin_b = np.sin(b)
            disc = (C * sin_b) ** 2 - c
            above = (b <= 0.0) | (disc < 0.0)
            root = np.sqrt(np.where(above, 0.0, disc))
            # s = C sin(delta) - sqrt(disc), written as c / (C sin(delta) + sqrt(disc))
            # (product of the roots) to avoid cancellation for small heights.
            s = c / (C * np.where(above, 1.0, sin_b) + root)
            phi = np.arctan2(s * np.cos(b), C - s * sin_b)
            rng = Re * phi
    rng = np.where(above, np.inf, rng)
    rng = np.where(invalid, np.nan, rng)
    flag[above] = RangeFlag.ABOVE_HORIZON
    flag[invalid] = RangeFlag.INVALID
    return rng, flag, beta, h


def flat_sea_range(depression: ArrayLike, height: ArrayLike) -> FloatArray:
    """Flat-sea horizontal range ``d = h / tan(beta)`` [m] (seed 000 eq. 5, ALGORITHMS.md §4.1).

    Args:
        depression: depression beta of the waterline below the true horizontal [rad]
            (any shape).
        height: camera height h above the sea [m], > 0; broadcasts against depression.

    Returns:
        d [m], the broadcast shape. ``beta <= 0`` (at or above the horizon) gives +inf;
        NaN input or ``beta > pi/2`` gives NaN. Use :func:`sea_range` for the flags.
    """
    return _scalar_or_array(_range_and_flag(depression, height, False, 0.0, EARTH_RADIUS)[0])


def curved_sea_range(
    depression: ArrayLike,
    height: ArrayLike,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Exact curved-sea range along the surface (arc) [m] (ALGORITHMS.md §4.2).

    Ray–sphere intersection on a sphere of effective radius ``R_e = R/(1-k)``, camera at
    ``C = R_e + h`` from the centre, line of sight ``delta`` below the true horizontal:

        disc = C^2 sin^2(delta) - (2 R_e h + h^2)        (< 0: the ray misses the sea)
        s    = C sin(delta) - sqrt(disc)                  slant range [m]
        phi  = atan2( s cos(delta), C - s sin(delta) )    central angle [rad]
        D    = R_e phi                                    arc distance [m]

    ``s`` is computed as ``(2 R_e h + h^2) / (C sin(delta) + sqrt(disc))`` (same value,
    no cancellation). For ``delta << 1`` this is ``D ≈ R_e (delta - sqrt(delta^2 - 2h/R_e))``.

    Args:
        depression: delta below the true horizontal [rad] (any shape).
        height: camera height h above the sea [m], > 0; broadcasts against depression.
        refraction: refraction coefficient k in [0, 1).
        earth_radius: earth radius R [m].

    Returns:
        D [m]. A depression smaller than the horizon dip (or <= 0) gives +inf; NaN input
        or ``delta > pi/2`` gives NaN. Use :func:`sea_range` for the flags.
    """
    rng = _range_and_flag(depression, height, True, refraction, earth_radius)[0]
    return _scalar_or_array(rng)


@dataclass(frozen=True, eq=False)
class SeaRange:
    """Sea-surface range with per-row flags (ALGORITHMS.md §4.1/§4.2).

    Attributes:
        range: horizontal (flat) or arc (curved) distance [m]; +inf above the horizon,
            NaN for invalid rows.
        flag: :class:`RangeFlag` values, int8, same shape.
    """

    range: FloatArray
    flag: NDArray[np.int8]

    @property
    def ok(self) -> NDArray[np.bool_]:
        """True where the range is finite and valid."""
        return self.flag == RangeFlag.OK


def sea_range(
    depression: ArrayLike,
    height: ArrayLike,
    curved: bool = False,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> SeaRange:
    """Flat (§4.1) or curved (§4.2) sea range with flags; see :func:`flat_sea_range`."""
    rng, flag, _, _ = _range_and_flag(depression, height, curved, refraction, earth_radius)
    return SeaRange(range=rng, flag=flag)


def sea_depression(
    distance: ArrayLike,
    height: ArrayLike,
    curved: bool = False,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Depression below the true horizontal of a sea-surface point [rad] (inverse of the ranges).

    Flat (§4.1): ``beta = atan2(h, d)``. Curved (§4.2), with ``phi = D / R_e``:

        beta = atan2( h + 2 R_e sin^2(phi/2), R_e sin(phi) )  ≈ h/D + D/(2 R_e)

    (the vertical drop ``R_e + h - R_e cos(phi)`` written without cancellation). Beyond
    the horizon the curved formula still returns a value, but the point is hidden.

    Args:
        distance: horizontal (flat) or arc (curved) distance [m], >= 0 (NaN gives NaN).
        height: camera height h [m], > 0.
        curved: use the curved sea with refraction.
        refraction: refraction coefficient k in [0, 1) (curved only).
        earth_radius: earth radius R [m].
    """
    d = as_float_array("distance", distance)
    if np.any(d[~np.isnan(d)] < 0.0):
        raise ValueError("distance: expected distances >= 0 m")
    h = _height(height)
    if not curved:
        return _scalar_or_array(np.arctan2(h, d))
    Re = effective_radius(refraction, earth_radius)
    phi = d / Re
    return _scalar_or_array(np.arctan2(h + 2.0 * Re * np.sin(0.5 * phi) ** 2, Re * np.sin(phi)))


def _range_derivatives(
    rng: FloatArray, h: FloatArray, curved: bool, refraction: float, earth_radius: float
) -> tuple[FloatArray, FloatArray]:
    """(dD/d beta [m/rad], dD/dh [m/m]) at range D and height h (implicit differentiation).

    Flat: beta = atan2(h, d) so dd/dbeta = -(d^2 + h^2)/h, dd/dh = d/h. Curved: with
    u = R_e sin(phi), v = h + 2 R_e sin^2(phi/2), beta = atan2(v, u):
    dbeta/dD = (u sin(phi) - v cos(phi)) / (u^2 + v^2), dbeta/dh = u / (u^2 + v^2).
    """
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if not curved:
            return -(rng * rng + h * h) / h, rng / h
        Re = effective_radius(refraction, earth_radius)
        phi = rng / Re
        u = Re * np.sin(phi)
        v = h + 2.0 * Re * np.sin(0.5 * phi) ** 2
        dbeta_dD = (u * np.sin(phi) - v * np.cos(phi)) / (u * u + v * v)
        dbeta_dh = u / (u * u + v * v)
        return 1.0 / dbeta_dD, -dbeta_dh / dbeta_dD


# ----------------------------------------------------------------------------- limits
def flat_error_limit(
    height: ArrayLike,
    tolerance: float = 0.01,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Range beyond which the flat-sea model is wrong by more than ``tolerance`` [m].

    A target at true arc distance D on the curved, refracting sea (§4.2) is seen at the
    depression ``beta(D)`` of :func:`sea_depression`; the flat model (§4.1) turns it into
    ``d = h / tan(beta(D))``, which is always too short. This returns the D at which
    ``(D - d) / D = tolerance``, solved numerically (vectorised bisection on log D, to
    1e-12 relative) between 0 and the horizon. To first order
    ``D ≈ sqrt(2 R_e h tol / (1 - tol))`` — about a tenth of the horizon distance for 1 %.

    For tolerance 1 %, k = 0.14 (R_e = 7 408 km):

        h =   2 m:  547 m        h =  20 m: 1 730 m
        h =   5 m:  865 m        h =  50 m: 2 736 m
        h =  10 m: 1 223 m       h = 100 m: 3 869 m

    Args:
        height: camera height h [m], > 0 (array; NaN gives NaN).
        tolerance: relative range error, in (0, 0.5) — at the horizon the flat model
            returns about half the true distance, so larger errors are never reached
            before it (+inf is returned for tolerance >= 0.5).
        refraction: refraction coefficient k in [0, 1).
        earth_radius: earth radius R [m].
    """
    tol = in_range("tolerance", tolerance, 0.0, 1.0, lo_open=True, hi_open=True)
    h = _height(height)
    Re = effective_radius(refraction, earth_radius)
    if tol >= 0.5:
        return _scalar_or_array(np.where(np.isnan(h), np.nan, np.inf))
    hh = np.where(np.isnan(h), 1.0, h)
    hor = Re * np.arctan(np.sqrt(2.0 * Re * hh + hh * hh) / Re)  # arc distance to the horizon

    def rel_error(D: FloatArray) -> FloatArray:
        beta = sea_depression(D, hh, curved=True, refraction=refraction, earth_radius=earth_radius)
        return (D - hh / np.tan(beta)) / D

    lo = np.log(hor * 1e-9)
    hi = np.log(hor)
    for _ in range(80):  # 2^-80 of ~21 in log D: far below 1e-12 relative
        mid = 0.5 * (lo + hi)
        too_far = rel_error(np.exp(mid)) > tol
        hi = np.where(too_far, mid, hi)
        lo = np.where(too_far, lo, mid)
    out = np.exp(0.5 * (lo + hi))
    return _scalar_or_array(np.where(np.isnan(h), np.nan, out))


# ----------------------------------------------------------------------------- positions
@dataclass(frozen=True, eq=False)
class SeaPosition:
    """Target positions on the sea surface (ALGORITHMS.md §4.1/§4.2, seed 000 eqs. 3–5).

    Attributes:
        xy: (..., 2) target (x North, y East) [m] in the observer's local frame; NaN where
            the flag is not OK.
        range: (...) horizontal (flat) or arc (curved) distance from the observer [m];
            +inf above the horizon, NaN for invalid rows.
        bearing: (...) absolute azimuth ``alpha + psi`` of the line of sight, clockwise
            from North, wrapped to [0, 2 pi) [rad].
        flag: (...) :class:`RangeFlag` values, int8.
    """

    xy: FloatArray
    range: FloatArray
    bearing: FloatArray
    flag: NDArray[np.int8]

    @property
    def ok(self) -> NDArray[np.bool_]:
        """True where the position is valid (flag OK)."""
        return self.flag == RangeFlag.OK


def sea_position(
    observer_xy: ArrayLike,
    heading: ArrayLike,
    azimuth: ArrayLike,
    depression: ArrayLike,
    height: ArrayLike,
    curved: bool = False,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> SeaPosition:
    """Target position from camera angles on a flat or curved sea.

    Seed 000 eqs. 3–5 / ALGORITHMS.md §4.1 (flat) and §4.2 (curved, local tangent plane):

        d   = h / tan(beta)                     (curved: the arc distance D of §4.2)
        x_t = x_o + d cos(alpha + psi)          (x = North)
        y_t = y_o + d sin(alpha + psi)          (y = East)

    All arguments broadcast (numpy rules, trailing axes aligned; observer_xy carries a
    trailing axis of 2).

    Args:
        observer_xy: observer (x_o North, y_o East) [m], shape (2,) or (..., 2).
        heading: platform heading psi, clockwise from North [rad].
        azimuth: relative azimuth alpha of the target from the heading, clockwise [rad].
        depression: depression beta below the true horizontal [rad].
        height: camera height h above the sea [m], > 0.
        curved: use the exact curved-sea range (§4.2) instead of the flat one.
        refraction: refraction coefficient k in [0, 1) (curved only).
        earth_radius: earth radius R [m] (curved only).

    Returns:
        :class:`SeaPosition`. Rows at or above the horizon: range +inf, xy NaN, flag
        ABOVE_HORIZON; NaN inputs: NaN, flag INVALID. Never raises for bad data rows.
    """
    obs = as_float_array("observer_xy", observer_xy)
    if obs.ndim == 0 or obs.shape[-1] != 2:
        raise ValueError(f"observer_xy: expected shape (2,) or (..., 2) [m], got {obs.shape}")
    psi = as_float_array("heading", heading)
    alpha = as_float_array("azimuth", azimuth)
    rng, flag, _, _ = _range_and_flag(depression, height, curved, refraction, earth_radius)
    shape = np.broadcast_shapes(obs.shape[:-1], psi.shape, alpha.shape, rng.shape)
    theta = np.broadcast_to(alpha + psi, shape)
    rng = np.broadcast_to(rng, shape)
    flag = np.broadcast_to(flag, shape).copy()
    bad_angle = ~np.isfinite(theta)
    bad_obs = ~np.all(np.isfinite(obs), axis=-1)
    flag[np.broadcast_to(bad_angle | bad_obs, shape)] = RangeFlag.INVALID
    ok = flag == RangeFlag.OK
    rng = np.where(flag == RangeFlag.INVALID, np.nan, rng)
    d = np.where(ok, rng, np.nan)
    xy = np.empty((*shape, 2))
    xy[..., 0] = obs[..., 0] + d * np.cos(theta)
    xy[..., 1] = obs[..., 1] + d * np.sin(theta)
    bearing = np.mod(theta, 2.0 * np.pi)
    return SeaPosition(xy=xy, range=rng, bearing=bearing, flag=flag)


# ----------------------------------------------------------------------------- uncertainty
def range_sigma(
    depression: ArrayLike,
    height: ArrayLike,
    sigma_depression: ArrayLike,
    sigma_height: ArrayLike = 0.0,
    curved: bool = False,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """1-sigma range error [m] from depression and height errors (first order).

    ALGORITHMS.md §4.2 "Sensitivity" and §7(a). Flat sea:

        sigma_d^2 = ((d^2 + h^2)/h)^2 sigma_beta^2 + (d/h)^2 sigma_h^2

    whose first term is exactly the Cramér–Rao bound of §7(a) (``≈ d^2 sigma_beta / h``).
    Curved sea: the exact derivatives of the §4.2 ray–sphere range (implicit
    differentiation of :func:`sea_depression`), ``dD/ddelta ≈ -1/(h/D^2 - 1/(2 R_e))``,
    which is infinite at the horizon.

    Args:
        depression: beta below the true horizontal [rad].
        height: camera height h [m], > 0.
        sigma_depression: 1-sigma of beta [rad], >= 0 (include pixel, pitch and, with a
            horizon reference, horizon errors: §7(a) "effective angular noise").
        sigma_height: 1-sigma of h [m] (tide, heave, squat), >= 0.
        curved, refraction, earth_radius: as in :func:`sea_range`.

    Returns:
        sigma [m], broadcast shape: +inf above the horizon, NaN for invalid rows.
    """
    s_b = _sigma("sigma_depression", sigma_depression)
    s_h = _sigma("sigma_height", sigma_height)
    rng, flag, _, h = _range_and_flag(depression, height, curved, refraction, earth_radius)
    dD_db, dD_dh = _range_derivatives(rng, h, curved, refraction, earth_radius)
    with np.errstate(invalid="ignore", over="ignore"):
        sig = np.sqrt((dD_db * s_b) ** 2 + (dD_dh * s_h) ** 2)
    sig = np.where(flag == RangeFlag.ABOVE_HORIZON, np.inf, sig)
    sig = np.where(np.broadcast_to(flag == RangeFlag.INVALID, sig.shape), np.nan, sig)
    return _scalar_or_array(sig)


def sea_position_covariance(
    heading: ArrayLike,
    azimuth: ArrayLike,
    depression: ArrayLike,
    height: ArrayLike,
    sigma_azimuth: ArrayLike,
    sigma_depression: ArrayLike,
    sigma_height: ArrayLike = 0.0,
    sigma_heading: ArrayLike = 0.0,
    observer_covariance: ArrayLike | None = None,
    curved: bool = False,
    refraction: float = DEFAULT_REFRACTION,
    earth_radius: float = EARTH_RADIUS,
) -> FloatArray:
    """Covariance of the target (x North, y East) of :func:`sea_position` [m^2] (first order).

    With theta = alpha + psi, u = (cos theta, sin theta) and w = (-sin theta, cos theta):

        Cov = sigma_D^2 u u^T + D^2 (sigma_alpha^2 + sigma_psi^2) w w^T + Cov_observer

    where sigma_D is :func:`range_sigma` (ALGORITHMS.md §4.2 sensitivity, §7(a)); the
    azimuth, heading, depression, height and observer errors are taken as independent.

    Args:
        heading: psi [rad]; azimuth: relative alpha [rad]; depression: beta [rad];
            height: h [m] — as in :func:`sea_position`.
        sigma_azimuth: 1-sigma of alpha [rad]. sigma_depression: of beta [rad].
        sigma_height: of h [m]. sigma_heading: of psi [rad].
        observer_covariance: optional covariance of the observer position [m^2], (2, 2)
            or (..., 2, 2).
        curved, refraction, earth_radius: as in :func:`sea_range`.

    Returns:
        (..., 2, 2) [m^2]; NaN for rows at or above the horizon or invalid (the position
        itself is NaN there).
    """
    s_a = _sigma("sigma_azimuth", sigma_azimuth)
    s_p = _sigma("sigma_heading", sigma_heading)
    theta = as_float_array("azimuth", azimuth) + as_float_array("heading", heading)
    rng, flag, _, _ = _range_and_flag(depression, height, curved, refraction, earth_radius)
    s_d = np.asarray(
        range_sigma(
            depression,
            height,
            sigma_depression,
            sigma_height,
            curved=curved,
            refraction=refraction,
            earth_radius=earth_radius,
        )
    )
    shape = np.broadcast_shapes(theta.shape, rng.shape, s_d.shape, s_a.shape, s_p.shape)
    theta = np.broadcast_to(theta, shape)
    bad = np.broadcast_to(flag != RangeFlag.OK, shape) | ~np.isfinite(theta)
    c, s = np.cos(theta), np.sin(theta)
    var_d = np.broadcast_to(s_d, shape) ** 2
    var_t = np.broadcast_to(rng, shape) ** 2 * (s_a**2 + s_p**2)
    with np.errstate(invalid="ignore"):
        cov = np.empty((*shape, 2, 2))
        cov[..., 0, 0] = var_d * c * c + var_t * s * s
        cov[..., 1, 1] = var_d * s * s + var_t * c * c
        cov[..., 0, 1] = cov[..., 1, 0] = (var_d - var_t) * c * s
    if observer_covariance is not None:
        oc = finite(
            "observer_covariance", as_float_array("observer_covariance", observer_covariance)
        )
        if oc.ndim < 2 or oc.shape[-2:] != (2, 2):
            raise ValueError(
                f"observer_covariance: expected shape (2, 2) or (..., 2, 2) [m^2], got {oc.shape}"
            )
        cov = cov + oc
    cov[np.broadcast_to(bad, cov.shape[:-2])] = np.nan
    return cov
