"""Motion models (ALGORITHMS.md §5.2) and measurement models (§4, §7a)."""

from seawatch.models.angles import LinearMeasurement, SeaSurfaceAngles, wrap_angle
from seawatch.models.kinematic import constant_acceleration, constant_velocity, position_measurement

__all__ = [
    "LinearMeasurement",
    "SeaSurfaceAngles",
    "constant_acceleration",
    "constant_velocity",
    "position_measurement",
    "wrap_angle",
]
