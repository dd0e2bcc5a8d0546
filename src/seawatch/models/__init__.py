"""Motion models (ALGORITHMS.md §5.2): transition matrices and process noise."""

from seawatch.models.kinematic import constant_acceleration, constant_velocity, position_measurement

__all__ = ["constant_acceleration", "constant_velocity", "position_measurement"]
