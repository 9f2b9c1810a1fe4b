"""The report's first step: ``alte warmup`` in its own processes, once, before any notebook.

numba writes a compiled kernel to its cache only when the compile ends, so on a fresh
install every notebook (and every Dask worker of chapter 5) that maps before another has
finished compiling compiles the same kernels again: tens of CPU seconds each. The report
starts the warmup (:func:`alte.commands.warmup.warm_kernels`, every kernel the notebooks
use, in two processes that share the mappers) while it simulates the missing terrains
and waits for it before the first notebook, which then loads each kernel from the cache.
With a warm cache it takes a few seconds.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from typing import Protocol

from tqdm.auto import tqdm

from alte.paths import REPO_ROOT

__all__ = ["Warmup", "start_warmup"]

#: The command run: the same ``alte warmup`` a user runs after an install.
COMMAND: tuple[str, ...] = (sys.executable, "-m", "alte", "warmup")
#: Processes it is split into (``--part K/N``): the terrains take a few seconds of one
#: core, the kernels ~60 s of one, so the two cores share the kernels.
PARTS = 2
#: Seconds waited silently (a warm cache's warmup) before a line says what is happening.
QUIET_S = 10.0


class Warmup(Protocol):
    """``start(progress)`` starts compiling and returns ``finish()``, which waits for it and
    returns what went wrong (None: every kernel is compiled and cached)."""

    def __call__(self, progress: bool) -> Callable[[], str | None]:
        ...


def start_warmup(progress: bool) -> Callable[[], str | None]:
    """Start ``alte warmup`` in :data:`PARTS` child processes (:data:`COMMAND` with
    ``--part K/N``); see :class:`Warmup`.

    A failed warmup is reported, never fatal: the notebooks then compile what they need.
    """
    procs = [subprocess.Popen((*COMMAND, "--part", f"{k}/{PARTS}"), cwd=REPO_ROOT,
                              stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
             for k in range(1, PARTS + 1)]

    def finish() -> str | None:
        try:
            procs[0].wait(timeout=QUIET_S)
        except subprocess.TimeoutExpired:
            if progress:
                tqdm.write("compiling alte's numba kernels (once per install; cached for every "
                           "notebook) ...", file=sys.stderr)
        problems = [_outcome(proc) for proc in procs]
        return next((p for p in problems if p is not None), None)

    return finish


def _outcome(proc: subprocess.Popen[str]) -> str | None:
    """Wait for one part; None when it compiled and cached its kernels, else what failed."""
    out, _ = proc.communicate()
    if proc.returncode == 0:
        return None
    last = out.strip().splitlines()[-1:] or ["no output"]
    return f"kernel warmup (alte warmup) failed with exit code {proc.returncode}: {last[0]}"
