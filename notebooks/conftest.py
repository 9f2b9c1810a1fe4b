"""nbval set-up for ``pytest --nbval-lax notebooks/``: headless, run from the repo root.

The kernels nbval starts inherit this process' environment, so setting the
variables here makes every notebook render statically (matplotlib Agg, pyvista
off-screen, ``alte.lab.notebook.setup`` in static mode) without a display. nbval starts
kernels in the notebook's folder; the report runner (papermill) starts them in the
repository root, where the notebooks' relative defaults (``DATA_DIR = "data"``,
``OUT_DIR = "reports/scratch/..."``) are meant to resolve, so nbval is made to do
the same. (``alte.lab.notebook.setup()`` also moves a kernel to the repository root,
which is what JupyterLab relies on; starting there covers code run before it.)
"""

from __future__ import annotations

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

os.environ["MPLBACKEND"] = "Agg"
os.environ["PYVISTA_OFF_SCREEN"] = "true"
os.environ["ALTE_RENDER"] = "static"


def _kernels_in_root() -> None:
    """Start nbval's kernels in the repository root instead of ``notebooks/``."""
    try:
        from nbval import plugin
    except ImportError:  # nbval not installed: plain pytest runs, nothing to adjust
        return
    base = plugin.RunningKernel

    class RootKernel(base):  # type: ignore[misc, valid-type]
        def __init__(self, kernel_name: str, cwd: str | None = None, **kwargs: object) -> None:
            super().__init__(kernel_name, cwd=str(ROOT), **kwargs)

    if not getattr(base, "_alte_root", False):
        RootKernel._alte_root = True  # type: ignore[attr-defined]
        plugin.RunningKernel = RootKernel


_kernels_in_root()
