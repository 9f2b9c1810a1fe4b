"""The report's first step: ``alte warmup`` in its own process, once, before any notebook.

numba writes a compiled kernel to its cache only when the compile ends, so on a fresh
install every notebook (and every Dask worker of chapter 5) that maps before another has
finished compiling compiles the same kernels again: tens of CPU seconds each. The report
starts the warmup (:func:`alte.commands.warmup.warm_kernels`, every kernel the notebooks
use) while it simulates the missing terrains and waits for it before the first notebook,
which then loads each kernel from the cache. With a warm cache it takes a few seconds.
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
#: Seconds waited silently (a warm cache's warmup) before a line says what is happening.
QUIET_S = 10.0


class Warmup(Protocol):
    """``start(progress)`` starts compiling and returns ``finish()``, which waits for it and
    returns what went wrong (None: every kernel is compiled and cached)."""

    def __call__(self, progress: bool) -> Callable[[], str | None]:
        ...


def start_warmup(progress: bool) -> Callable[[], str | None]:
    """Start ``alte warmup`` in a child process (:data:`COMMAND`); see :class:`Warmup`.

    A failed warmup is reported, never fatal: the notebooks then compile what they need.
    """
    proc = subprocess.Popen(COMMAND, cwd=REPO_ROOT, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)

    def finish() -> str | None:
        try:
            out, _ = proc.communicate(timeout=QUIET_S)
        except subprocess.TimeoutExpired:
            if progress:
                tqdm.write("compiling alte's numba kernels (once per install; cached for every "
                           "notebook) ...", file=sys.stderr)
            out, _ = proc.communicate()
        if proc.returncode == 0:
            return None
        last = out.strip().splitlines()[-1:] or ["no output"]
        return f"kernel warmup (alte warmup) failed with exit code {proc.returncode}: {last[0]}"

    return finish
