"""Camera attitude: rotations between the camera frame and the local level (NED) frame.

Implements ALGORITHMS.md §4.3 "With known attitude":

    R_nc = R_z(psi) R_y(theta) R_x(phi) R_bc,      R_bc = [[0, 0, 1],
                                                           [1, 0, 0],
                                                           [0, 1, 0]]

Frames (all right-handed):

- camera ``c``: x right, y down, z forward along the optical axis (OpenCV);
- body ``b``: FRD, x forward (= camera z), y right (= camera x), z down (= camera y);
  ``r_b = R_bc r_c``;
- world ``n``: local level NED, x North, y East, z Down; ``r_n = R_nc r_c``.

Angles [rad], aerospace Z-Y-X (yaw-pitch-roll) order:

- ``heading`` psi: azimuth of the optical axis, clockwise from North;
- ``pitch`` theta: elevation of the optical axis, **positive nose-up** — a camera
  looking down at the sea has a *negative* pitch, and a camera with pitch −5° sees the
  true horizon 5° *above* its image centre;
- ``roll`` phi: rotation about the optical axis, **positive right-side-down** (the
  camera's x axis, the image's right-hand side, tilts towards the sea); a camera rolled
  by +phi sees the horizon turned anticlockwise in the image, i.e. its right end higher
  (smaller v).

All functions broadcast their angle arguments with numpy's rules and return arrays
with the rotation axes last, ``(..., 3, 3)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from seawatch._validation import FloatArray, as_float_array

R_BC: FloatArray = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
"""Camera (x right, y down, z forward) → body FRD rotation R_bc (ALGORITHMS.md §4.3)."""
R_BC.setflags(write=False)


def _angle(name: str, value: ArrayLike) -> FloatArray:
    return as_float_array(name, value)


def rotation_x(angle: ArrayLike) -> FloatArray:
    """Active rotation about x by ``angle`` [rad]: R_x = [[1,0,0],[0,c,-s],[0,s,c]], (..., 3, 3)."""
    a = _angle("angle", angle)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack(
        [np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2
    )


def rotation_y(angle: ArrayLike) -> FloatArray:
    """Active rotation about y by ``angle`` [rad]: R_y = [[c,0,s],[0,1,0],[-s,0,c]], (..., 3, 3)."""
    a = _angle("angle", angle)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack(
        [np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2
    )


def rotation_z(angle: ArrayLike) -> FloatArray:
    """Active rotation about z by ``angle`` [rad]: R_z = [[c,-s,0],[s,c,0],[0,0,1]], (..., 3, 3)."""
    a = _angle("angle", angle)
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack(
        [np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2
    )


def rotation_nb(heading: ArrayLike, pitch: ArrayLike, roll: ArrayLike) -> FloatArray:
    """Body FRD → world NED rotation R_nb = R_z(psi) R_y(theta) R_x(phi), (..., 3, 3).

    ALGORITHMS.md §4.3. ``heading`` psi, ``pitch`` theta (nose-up positive) and ``roll``
    phi (right-side-down positive) in radians, broadcast against each other.
    """
    psi = _angle("heading", heading)
    theta = _angle("pitch", pitch)
    phi = _angle("roll", roll)
    return rotation_z(psi) @ rotation_y(theta) @ rotation_x(phi)


def rotation_nc(heading: ArrayLike, pitch: ArrayLike, roll: ArrayLike) -> FloatArray:
    """Camera → world NED rotation R_nc = R_z(psi) R_y(theta) R_x(phi) R_bc, (..., 3, 3).

    ALGORITHMS.md §4.3: a unit ray ``r_c`` in the camera frame (x right, y down,
    z forward) is ``r_n = R_nc r_c`` in the local level NED frame. Angles in radians:
    ``heading`` clockwise from North, ``pitch`` positive nose-up, ``roll`` positive
    right-side-down (see the module docstring); they broadcast against each other.
    """
    return rotation_nb(heading, pitch, roll) @ R_BC


def attitude_from_rotation(r_nc: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(heading, pitch, roll) [rad] of a camera → NED rotation, the inverse of `rotation_nc`.

    ``r_nc`` has shape (..., 3, 3). With ``R_nb = R_nc R_bc^T``: pitch
    ``theta = asin(-R_nb[2, 0])`` in [−π/2, π/2], heading ``psi = atan2(R_nb[1, 0],
    R_nb[0, 0])`` in (−π, π], roll ``phi = atan2(R_nb[2, 1], R_nb[2, 2])`` in (−π, π].
    At pitch ±90° (gimbal lock) heading and roll are not separable; the split is then
    arbitrary but the composed rotation is still reproduced.
    """
    r = as_float_array("r_nc", r_nc)
    if r.ndim < 2 or r.shape[-2:] != (3, 3):
        raise ValueError(f"r_nc: expected shape (..., 3, 3), got {r.shape}")
    r_nb = r @ R_BC.T
    theta = np.arcsin(np.clip(-r_nb[..., 2, 0], -1.0, 1.0))
    psi = np.arctan2(r_nb[..., 1, 0], r_nb[..., 0, 0])
    phi = np.arctan2(r_nb[..., 2, 1], r_nb[..., 2, 2])
    return psi, theta, phi
