"""The source papers' experiments and synthetic worlds, by name (SCENARIOS.md).

Each scenario module builds its truth, simulates the measurements, runs the estimators
the paper compares and returns records shaped like the experiment JSON of
INTERFACES.md (``estimator``, ``metric``, ``unit``, ``mean``, ``stderr``, ``paper``,
``params``). Available: :mod:`seawatch.scenarios.air_range` (``air-range``, seed 002).
"""
