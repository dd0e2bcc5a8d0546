"""Size-specialised copies of compiled kernel modules, cached on disk.

numba treats module-level integers as compile-time constants. A kernel module that
reads its matrix sizes from two such constants (``N_STATE``, ``N_MEAS``) therefore
compiles, in a copy where those are set, to straight-line unrolled code. This module
writes such a copy per (module, n, m) into a cache folder, imports it, and lets numba
cache the compiled machine code next to it, so the cost is paid once per machine.

Cache folder: ``$SEAWATCH_CACHE_DIR`` or ``$XDG_CACHE_HOME/seawatch`` or
``~/.cache/seawatch``. If it cannot be written the generic module (sizes read from the
arrays at run time) is returned instead; results are identical, only slower.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import re
import sys
import tempfile
import warnings
from functools import cache
from pathlib import Path
from types import ModuleType

_CONST = re.compile(r"^(N_STATE|N_MEAS) = 0\b.*$", re.MULTILINE)


def cache_dir() -> Path:
    """Folder holding the specialised kernel copies and numba's compiled code."""
    env = os.environ.get("SEAWATCH_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "seawatch"


@cache
def specialised(module: ModuleType, n: int, m: int) -> ModuleType:
    """Return a copy of kernel *module* with ``N_STATE = n`` and ``N_MEAS = m`` frozen in."""
    source = Path(module.__file__ or "").read_text()
    sizes = {"N_STATE": n, "N_MEAS": m}
    text = _CONST.sub(lambda mt: f"{mt.group(1)} = {sizes[mt.group(1)]}", source)
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    stem = module.__name__.rsplit(".", 1)[-1].lstrip("_")
    name = f"seawatch_kernel_{stem}_n{n}_m{m}_{digest}"
    try:
        folder = cache_dir() / "kernels"
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{name}.py"
        if not path.exists():
            for stale in folder.glob(f"seawatch_kernel_{stem}_n{n}_m{m}_*.py"):
                stale.unlink(missing_ok=True)  # copies of an older kernel source
            # atomic write: concurrent processes (Dask workers) may race here
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(text)
            os.replace(tmp, path)
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise ImportError(f"cannot load {path}")
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
        return mod
    except OSError as exc:
        warnings.warn(
            f"seawatch: cannot write the kernel cache ({exc}); using generic kernels "
            "(same results, slower). Set SEAWATCH_CACHE_DIR to a writable folder.",
            RuntimeWarning,
            stacklevel=2,
        )
        return module
