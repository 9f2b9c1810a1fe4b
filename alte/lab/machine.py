"""The machine a measurement ran on: CPU, cores, load, memory and the versions that matter.

Recorded beside every timed result (the benchmark's rows, a sweep's evidence), so a figure
read later says what it was measured on.
"""

from __future__ import annotations

import os
import platform
from importlib import metadata

from alte.types import JSONDict

__all__ = ["machine_info"]


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            for line in info:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "absent"


def machine_info() -> JSONDict:
    """CPU model, core counts, load, memory and the versions that matter for the figures."""
    try:
        pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError):
        pages = 0
    return {
        "cpu": _cpu_model(), "cores": os.cpu_count(),
        "cores_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "load_avg_1_5_15": [round(v, 2) for v in os.getloadavg()],
        "memory_gib": round(pages / 2**30, 1), "platform": platform.platform(),
        "python": platform.python_version(),
        **{name: _version(name) for name in ("numpy", "scipy", "numba", "open3d", "pyoctomap")},
    }
