"""numba's threading layer, chosen once for every parallel kernel of alte.

OpenMP first: thread-safe, and already loaded by pykdtree and open3d; numba would try
TBB first and warn (to no one's benefit) when the machine's TBB is too old. A user's
``NUMBA_THREADING_LAYER_PRIORITY`` wins. Modules with ``parallel=True`` kernels import
this module before their first parallel call.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

import numba

__all__ = ["CLOUD_MIN", "threads_for"]

#: Inputs from this many points on (a whole cloud, never one scan of ~7,000 returns) run
#: the per-point kernels of a batch build on every thread.
CLOUD_MIN = 1 << 16

if "NUMBA_THREADING_LAYER_PRIORITY" not in os.environ:
    numba.config.THREADING_LAYER_PRIORITY = ["omp", "tbb", "workqueue"]  # type: ignore[attr-defined]


@contextmanager
def threads_for(items: int, minimum: int) -> Iterator[None]:
    """numba's threads for a parallel kernel over ``items``: all of them from ``minimum``
    items on, else one (waking a second thread costs more than it saves on small inputs,
    such as one scan)."""
    if items >= minimum:
        yield
        return
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(threads)
