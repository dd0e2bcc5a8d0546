"""Measurement models for nonlinear filters: sea-surface angles and a linear wrapper.

A measurement model is a small frozen dataclass that holds configuration only and
maps a state ``x`` of shape (..., n) to a measurement ``z = h(x)`` of shape (..., m);
``jacobian(x)`` returns ``H = dh/dx`` of shape (..., m, n). Leading axes of ``x`` are
batch axes; array-valued configuration (e.g. one observer position per Monte-Carlo
run) broadcasts against them with numpy's rules (trailing axes aligned), so a model
whose observer has shape (B, 2) works on states of shape (B, n) and on sigma points of
shape (2n+1, B, n). ``angular`` tells which measurement components are angles, so a
filter can wrap their residuals to (−π, π].

Conventions (ALGORITHMS.md "Conventions", SCENARIOS.md ``uav-sea``): local frame with
x North, y East; state positions first, ``x = [x_north, y_east, vx, vy, ...]`` [m, m/s];
azimuth clockwise from North [rad]; depression positive below the true horizontal
[rad].
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array, finite, in_range, matrix
from seawatch.geometry.sea import EARTH_RADIUS

"""Mean earth radius R [m] (ALGORITHMS.md §4.2)."""


def wrap_angle(angle: ArrayLike) -> FloatArray:
    """Wrap angles [rad] to the interval (−π, π] (elementwise, any shape)."""
    a = np.asarray(angle, dtype=np.float64)
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


@runtime_checkable
class MeasurementModel(Protocol):
    """What the EKF/UKF need from a measurement model (``seawatch.filters.nonlinear``)."""

    @property
    def dim_z(self) -> int:
        """Measurement size m."""
        ...

    @property
    def angular(self) -> tuple[bool, ...]:
        """Per measurement component: True if it is an angle [rad] to wrap to (−π, π]."""
        ...

    def __call__(self, x: ArrayLike) -> FloatArray:
        """z = h(x): (..., n) -> (..., m)."""
        ...

    def jacobian(self, x: ArrayLike) -> FloatArray:
        """H = dh/dx at x: (..., n) -> (..., m, n)."""
        ...


def _state(x: ArrayLike, min_size: int) -> FloatArray:
    arr = as_float_array("x", x)
    if arr.ndim == 0 or arr.shape[-1] < min_size:
        raise ValueError(
            f"x: expected a state of shape (..., n) with n >= {min_size}, got {arr.shape}"
        )
    return arr


@dataclass(frozen=True, eq=False)
class SeaSurfaceAngles:
    """Azimuth and depression of a target on the sea surface seen from a camera.

    Implements SCENARIOS.md ``uav-sea`` / seed 000 eqs. 1–2 and ALGORITHMS.md §4.1
    (flat sea) and §4.2 (curved sea with refraction); Jacobian of ALGORITHMS.md §7(a).
    With offsets ``Dx = x - x_o`` (North), ``Dy = y - y_o`` (East) [m] and horizontal
    distance ``rho = sqrt(Dx^2 + Dy^2)`` [m]:

        z[0] = alpha = wrap(atan2(Dy, Dx) - psi)      azimuth relative to the heading psi,
                                                      clockwise, in (−π, π] [rad]
        z[1] = beta  = atan2(h, rho)                  flat sea: depression below the
                                                      true horizontal [rad]

    (seed 000 eq. 1 writes alpha = atan(p/r) with p, r the offsets rotated by psi, which
    is the same angle.) With ``curved=True`` the sea is a sphere of effective radius
    ``R_e = R / (1 - k)`` (R = 6 371 000 m, k = ``refraction``), ``rho`` is read as the
    arc distance D along the surface (local tangent plane, as in §4.2), and the
    depression is the exact ray–sphere angle, the inverse of §4.2's ray–sphere range:

        phi  = D / R_e                                central angle [rad]
        beta = atan2(h + 2 R_e sin^2(phi/2), R_e sin(phi))
             ≈ atan(h/D) + D/(2 R_e)                  (§4.2 / §7(a) small-angle form)

    (the vertical drop ``R_e + h - R_e cos(phi)`` is written with ``sin^2`` to avoid
    cancellation). Beyond the horizon distance ``sqrt(2 R_e h)`` the formula still
    returns a value, but such a target is hidden by the horizon.

    Jacobian (§7(a)): d alpha/dx = -Dy/rho^2, d alpha/dy = Dx/rho^2;
    d beta/d(x, y) = (d beta/d rho) (Dx, Dy)/rho with d beta/d rho = -h/(rho^2 + h^2)
    (flat) or the exact derivative of the curved form above, which is
    ``-(h/rho^2 - 1/(2 R_e))`` to first order (§7(a) "spherical"). Velocity (and all
    further) columns are zero. A target at the observer (rho = 0) has no azimuth: rho is
    floored at 1e-9 m there so that nothing divides by zero.

    Args:
        height: camera height h above the sea surface [m], > 0; scalar or an array
            that broadcasts against the batch axes of x.
        observer: camera position (x_o North, y_o East) [m], shape (2,) or (B..., 2).
        heading: heading psi from which the azimuth is measured [rad, clockwise from
            North]; scalar or (B...,).
        curved: use the curved-sea (§4.2) depression instead of the flat one.
        refraction: terrestrial refraction coefficient k in [0, 1) (curved only).
        earth_radius: earth radius R [m].

    For a moving platform, make one model per step with :meth:`at`.
    """

    height: float | FloatArray
    observer: tuple[float, float] | FloatArray = (0.0, 0.0)
    heading: float | FloatArray = 0.0
    curved: bool = False
    refraction: float = 0.14
    earth_radius: float = EARTH_RADIUS
    _Re: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        h = finite("height", as_float_array("height", self.height))
        if np.any(h <= 0.0):
            raise ValueError(f"height: expected a camera height > 0 m, got {self.height!r}")
        obs = finite("observer", as_float_array("observer", self.observer))
        if obs.ndim == 0 or obs.shape[-1] != 2:
            raise ValueError(f"observer: expected shape (2,) or (..., 2) [m], got {obs.shape}")
        psi = finite("heading", as_float_array("heading", self.heading))
        if not isinstance(self.curved, bool | np.bool_):
            raise ValueError(f"curved: expected True or False, got {self.curved!r}")
        k = in_range("refraction", self.refraction, 0.0, 1.0, hi_open=True)
        R = in_range("earth_radius", self.earth_radius, 0.0, np.inf, lo_open=True, hi_open=True)
        set_ = object.__setattr__
        set_(self, "height", float(h) if h.ndim == 0 else h)
        set_(self, "observer", obs)
        set_(self, "heading", float(psi) if psi.ndim == 0 else psi)
        set_(self, "curved", bool(self.curved))
        set_(self, "refraction", k)
        set_(self, "earth_radius", R)
        set_(self, "_Re", R / (1.0 - k))

    @property
    def dim_z(self) -> int:
        """Measurement size m = 2: (azimuth, depression)."""
        return 2

    @property
    def angular(self) -> tuple[bool, ...]:
        """Both components are angles [rad]; their residuals wrap to (−π, π]."""
        return (True, True)

    @property
    def effective_radius(self) -> float:
        """Effective earth radius R_e = R / (1 - k) [m] (ALGORITHMS.md §4.2)."""
        return self._Re

    def at(
        self,
        observer: ArrayLike | None = None,
        heading: ArrayLike | None = None,
        height: ArrayLike | None = None,
    ) -> SeaSurfaceAngles:
        """The same model seen from a new observer position / heading / height.

        Arguments left as None keep their current value. Units as in the constructor.
        """
        changes: dict[str, object] = {}
        if observer is not None:
            changes["observer"] = observer
        if heading is not None:
            changes["heading"] = heading
        if height is not None:
            changes["height"] = height
        return dataclasses.replace(self, **changes)

    # --------------------------------------------------------------- maths
    def _offsets(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        obs = np.asarray(self.observer)
        dx = x[..., 0] - obs[..., 0]
        dy = x[..., 1] - obs[..., 1]
        rho = np.maximum(np.hypot(dx, dy), 1e-9)
        return dx, dy, rho

    def _depression(self, rho: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Depression beta(rho) [rad] and d beta / d rho [rad/m]."""
        h = self.height
        if not self.curved:
            return np.arctan2(h, rho), -h / (rho * rho + h * h)
        Re = self._Re
        phi = rho / Re
        u = Re * np.sin(phi)  # horizontal component of the line of sight [m]
        v = h + 2.0 * Re * np.sin(0.5 * phi) ** 2  # vertical drop [m]
        beta = np.arctan2(v, u)
        # d/d rho: du/d rho = cos(phi), dv/d rho = sin(phi)
        dbeta = (u * np.sin(phi) - v * np.cos(phi)) / (u * u + v * v)
        return beta, dbeta

    def __call__(self, x: ArrayLike) -> FloatArray:
        """z = [azimuth relative to heading, depression] [rad] of states x (..., n>=2)."""
        xa = _state(x, 2)
        dx, dy, rho = self._offsets(xa)
        az = wrap_angle(np.arctan2(dy, dx) - self.heading)
        beta, _ = self._depression(rho)
        az, beta = np.broadcast_arrays(az, beta)
        return np.stack([az, beta], axis=-1)

    def jacobian(self, x: ArrayLike) -> FloatArray:
        """H = dz/dx [rad/m], shape (..., 2, n); columns beyond the positions are zero."""
        xa = _state(x, 2)
        dx, dy, rho = self._offsets(xa)
        _, dbeta = self._depression(rho)
        rho2 = rho * rho
        batch = np.broadcast_shapes(dx.shape, np.shape(dbeta))
        H = np.zeros((*batch, 2, xa.shape[-1]))
        H[..., 0, 0] = -dy / rho2
        H[..., 0, 1] = dx / rho2
        H[..., 1, 0] = dbeta * dx / rho
        H[..., 1, 1] = dbeta * dy / rho
        return H


@dataclass(frozen=True, eq=False)
class LinearMeasurement:
    """Linear measurement z = H x (ALGORITHMS.md §2/§5 measurement equation).

    Args:
        H: measurement matrix, (m, n), finite.
        angular: optional per-component flags marking angle measurements (wrapped to
            (−π, π] by the filters); default: none.

    ``__call__(x)`` returns ``x @ H.T`` (..., m); ``jacobian(x)`` returns H broadcast to
    (..., m, n). Units are those of H and the state.
    """

    H: FloatArray
    angular: tuple[bool, ...] = ()

    def __post_init__(self) -> None:
        H = matrix("H", self.H)
        m = H.shape[0]
        ang = tuple(bool(a) for a in self.angular) if len(self.angular) else (False,) * m
        if len(ang) != m:
            raise ValueError(f"angular: expected {m} flags (one per row of H), got {len(ang)}")
        object.__setattr__(self, "H", H)
        object.__setattr__(self, "angular", ang)

    @property
    def dim_z(self) -> int:
        """Measurement size m."""
        return self.H.shape[0]

    def __call__(self, x: ArrayLike) -> FloatArray:
        """z = H x for states x (..., n)."""
        xa = _state(x, self.H.shape[1])
        if xa.shape[-1] != self.H.shape[1]:
            raise ValueError(f"x: expected shape (..., {self.H.shape[1]}), got {xa.shape}")
        return xa @ self.H.T

    def jacobian(self, x: ArrayLike) -> FloatArray:
        """H broadcast to (..., m, n)."""
        xa = _state(x, self.H.shape[1])
        if xa.shape[-1] != self.H.shape[1]:
            raise ValueError(f"x: expected shape (..., {self.H.shape[1]}), got {xa.shape}")
        return np.broadcast_to(self.H, (*xa.shape[:-1], *self.H.shape))
