"""What every experiment returns: the experiment JSON of INTERFACES.md.

``results`` is a flat list of records ``{"estimator", "metric", "unit", "mean",
"stderr", "paper", "params"}`` (``paper`` is the paper's value or None, ``params`` the
case parameters, ``{}`` if none); bounds are records too, with estimator ``crlb``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

ProgressCallback = Callable[[int, int], None]
"""``progress(done, total)``: called as Monte-Carlo runs or cases complete."""


def record(
    estimator: str,
    metric: str,
    unit: str,
    values: Sequence[float] | np.ndarray | float,
    *,
    paper: float | None = None,
    params: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """One result record: mean and standard error of ``values`` (one value per run).

    A single value (or one run) has ``stderr`` None.
    """
    v = np.atleast_1d(np.asarray(values, dtype=np.float64))
    v = v[np.isfinite(v)]
    mean = float(np.mean(v)) if v.size else math.nan
    stderr = float(np.std(v, ddof=1) / math.sqrt(v.size)) if v.size > 1 else None
    return {
        "estimator": estimator,
        "metric": metric,
        "unit": unit,
        "mean": mean,
        "stderr": stderr,
        "paper": paper,
        "params": dict(params or {}),
    }


@dataclass(frozen=True)
class ExperimentResult:
    """Result of one experiment run (the experiment JSON of INTERFACES.md)."""

    scenario: str
    runs: int
    seed: int
    results: list[dict[str, Any]]
    outputs: list[Path] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The JSON document printed by ``seawatch experiment NAME --json``."""
        doc: dict[str, Any] = {
            "scenario": self.scenario,
            "runs": self.runs,
            "seed": self.seed,
            "results": self.results,
            "outputs": [str(p) for p in self.outputs],
        }
        doc.update(self.extra)
        return doc

    def find(self, estimator: str, metric: str, **params: Any) -> dict[str, Any]:
        """The record for (estimator, metric) whose params include ``params``."""
        for rec in self.results:
            if rec["estimator"] == estimator and rec["metric"] == metric:
                if all(rec["params"].get(k) == v for k, v in params.items()):
                    return rec
        raise KeyError(f"no record {estimator}/{metric} with {params}")
