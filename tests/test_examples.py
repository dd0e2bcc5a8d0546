"""Every script in examples/ runs, and says what it promises."""

from __future__ import annotations

import runpy
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).parents[1] / "examples").glob("*.py"))


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_example_script_runs(script):
    proc = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr


def test_constant_velocity_example_filters_below_the_raw_noise():
    ns = runpy.run_path(str(EXAMPLES[0].parent / "track_constant_velocity.py"))
    out = ns["main"](steps=1500, seed=3)
    assert out["rms_filtered_m"] < 0.5 * out["rms_raw_m"]
    assert 1.8 < out["mean_nis"] < 2.2
