"""The experiments runnable by name (``seawatch experiment NAME``).

Each experiment is a function ``f(runs, seed, out_dir, progress, **options)`` returning
an :class:`~seawatch.scenarios.base.ExperimentResult`; ``options`` are the scenario's
own keyword options (e.g. ``table`` for ``clutter-tbd``). Scenario modules are imported
only when their experiment runs.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
from collections.abc import Callable

from seawatch.scenarios.base import ExperimentResult

SCENARIOS: dict[str, tuple[str, str]] = {
    "air-range": ("seawatch.scenarios.air_range", "experiment"),
    "clutter-tbd": ("seawatch.scenarios.clutter_tbd", "run"),
    "uav-sea": ("seawatch.scenarios.uav_sea", "run"),
    "stereo-ferry": ("seawatch.scenarios.stereo_ferry", "run"),
    "ship-video": ("seawatch.scenarios.ship_video", "run"),
    "solent-ais": ("seawatch.scenarios.solent_ais", "run"),
}
"""Experiment name → (module, function)."""


def available() -> list[str]:
    """Names of the experiments that can run in this installation."""
    return [name for name, (mod, _) in SCENARIOS.items() if importlib.util.find_spec(mod)]


def runner(name: str) -> Callable[..., ExperimentResult]:
    """The function running experiment *name*; ValueError naming it if unknown."""
    if name not in available():
        raise ValueError(f"NAME: unknown experiment {name!r}; available: {', '.join(available())}")
    module, function = SCENARIOS[name]
    return getattr(importlib.import_module(module), function)


def options(name: str) -> set[str]:
    """The scenario-specific keyword options experiment *name* accepts."""
    common = {"runs", "seed", "out_dir", "progress"}
    return set(inspect.signature(runner(name)).parameters) - common
