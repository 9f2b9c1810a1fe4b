"""File-system helpers: atomic writes so an interrupted run never leaves a file
that a later run mistakes for a finished one, and nothing a user made is overwritten
silently."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from alte.errors import AlteError

__all__ = ["atomic_dir", "atomic_path", "refuse_overwrite"]


def refuse_overwrite(path: Path, overwrite: bool) -> None:
    """Raise when ``path`` exists and the caller did not ask to overwrite it."""
    if path.exists() and not overwrite:
        raise AlteError(f"{path} already exists; overwrite=True replaces it",
                        setting="output.overwrite")


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], overwrite: bool = False) -> Iterator[Path]:
    """Yield a temporary file name beside ``path``; rename it onto ``path`` on success."""
    target = Path(path)
    refuse_overwrite(target, overwrite)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    tmp_path.chmod(0o666 & ~_umask())  # mkstemp makes 0600; give the user's usual mode
    try:
        yield tmp_path
        os.replace(tmp_path, target)
    finally:
        tmp_path.unlink(missing_ok=True)


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike[str], overwrite: bool = False) -> Iterator[Path]:
    """Yield a temporary directory beside ``path``; move it onto ``path`` on success.

    The temporary name must not exist, so callers that need a non-existing folder
    (rosbags writers) get one: the yielded path itself does not exist yet.
    """
    target = Path(path)
    refuse_overwrite(target, overwrite)
    target.parent.mkdir(parents=True, exist_ok=True)
    holder = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent))
    tmp_path = holder / target.name
    try:
        yield tmp_path
        if target.exists():
            shutil.rmtree(target) if target.is_dir() else target.unlink()
        os.replace(tmp_path, target)
    finally:
        shutil.rmtree(holder, ignore_errors=True)
