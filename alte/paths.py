"""Where alte's folders are: the repository, its data and reports, the shared real recordings.

Notebooks, the report runner and the CLI resolve relative folders against
:data:`REPO_ROOT` (the folder holding ``alte/``), never against the current working
directory, so a kernel started in ``notebooks/`` uses the same ``data/`` as ``make``.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["REPO_ROOT", "realdata_dir", "resolve"]

#: The repository: the folder holding the ``alte`` package.
REPO_ROOT = Path(__file__).resolve().parents[1]


def resolve(path: str | os.PathLike[str]) -> Path:
    """``path`` itself when absolute, else relative to :data:`REPO_ROOT`."""
    given = Path(path).expanduser()
    return given if given.is_absolute() else REPO_ROOT / given


def realdata_dir() -> Path:
    """``<repo>/../shared/realdata``: the real recordings nobody on this project made."""
    return REPO_ROOT.parent / "shared" / "realdata"
