"""Plot of range error against true range for the ``air-range`` scenario (seed 002 figs. 3–6).

Pure plotting: takes plain arrays, draws with matplotlib's object API on an Agg canvas
(no GUI, no global ``pyplot`` state), writes a PNG.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from seawatch._validation import as_float_array

_STYLE = {
    "raw": {"color": "0.55", "lw": 1.0},
    "ncv-1": {"color": "#9ecae1", "lw": 1.2},
    "ncv-5": {"color": "#4292c6", "lw": 1.2},
    "ncv-10": {"color": "#08519c", "lw": 1.2},
    "nca-0.001": {"color": "#fdae6b", "lw": 1.2},
    "nca-0.01": {"color": "#f16913", "lw": 1.2},
    "nca-0.1": {"color": "#a63603", "lw": 1.2},
    "ancv": {"color": "#238b45", "lw": 2.2},
    "anca": {"color": "#cb181d", "lw": 2.2},
}


def plot_range_errors(
    range_m: ArrayLike,
    rms_error: Mapping[str, ArrayLike],
    sigma_d: ArrayLike,
    path: str | Path,
    *,
    sigma_v: Mapping[str, ArrayLike] | None = None,
    pullup_range: float | None = None,
    title: str | None = None,
) -> Path:
    """Draw RMS range error vs. true range for each filter and save it as PNG.

    Args:
        range_m: true range per frame [m], (N,).
        rms_error: estimator name → RMS range error per frame [m], each (N,).
        sigma_d: standard deviation of the raw size-based range per frame [m], (N,)
            (ALGORITHMS.md §5.1), drawn dashed for reference.
        path: output file (PNG).
        sigma_v: optional estimator name → σ_v per frame [m/s²] of adaptive filters;
            drawn in a second panel.
        pullup_range: optional range [m] at which the manoeuvre starts (vertical line).
        title: optional figure title.

    Returns:
        The path written.
    """
    d = as_float_array("range_m", range_m, ndim=1)
    sd = as_float_array("sigma_d", sigma_d, ndim=1)
    if sd.shape != d.shape:
        raise ValueError(f"sigma_d: expected shape {d.shape}, got {sd.shape}")
    panels = 2 if sigma_v else 1
    fig = Figure(figsize=(9.0, 6.5 if panels == 2 else 4.8), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(panels, 1, sharex=True, squeeze=False, height_ratios=[3, 1.3][:panels])[
        :, 0
    ]
    ax = axes[0]
    for name, values in rms_error.items():
        e = as_float_array(f"rms_error[{name!r}]", values, ndim=1)
        if e.shape != d.shape:
            raise ValueError(f"rms_error[{name!r}]: expected shape {d.shape}, got {e.shape}")
        ax.plot(d, e, label=name, **_STYLE.get(name, {"lw": 1.2}))
    ax.plot(d, sd, "k--", lw=1.0, label="σ_d = d²σ_l/(fL)")
    ax.set_yscale("log")
    ax.set_ylabel("RMS range error [m]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(ncol=3, fontsize=8, loc="lower left")
    if sigma_v:
        ax2 = axes[1]
        for name, values in sigma_v.items():
            s = as_float_array(f"sigma_v[{name!r}]", values, ndim=1)
            if s.shape != d.shape:
                raise ValueError(f"sigma_v[{name!r}]: expected shape {d.shape}, got {s.shape}")
            ax2.plot(d, s, label=f"{name} σ_v (median)", **_STYLE.get(name, {"lw": 1.2}))
        ax2.set_yscale("log")
        ax2.set_ylabel("σ_v [m/s²]")
        ax2.grid(True, which="both", alpha=0.3)
        ax2.legend(fontsize=8)
    for a in axes:
        if pullup_range is not None:
            a.axvline(pullup_range, color="0.3", lw=0.8, ls=":")
    if pullup_range is not None:
        axes[0].annotate(
            "pull-up", (pullup_range, 1.0), xycoords=("data", "axes fraction"),
            xytext=(3, -12), textcoords="offset points", fontsize=8,
        )  # fmt: skip
    lo, hi = float(np.min(d)), float(np.max(d))
    axes[-1].set_xlim(hi, lo)  # range decreasing left to right, like the approach
    axes[-1].set_xlabel("true range [m]")
    if title:
        fig.suptitle(title)
    out = Path(path)
    fig.savefig(out, dpi=120)
    return out
