"""TUM trajectory files: one pose a line, ``t x y z qx qy qz qw`` (seconds, metres).

The format of the TUM RGB-D benchmark, which ``evo`` and most SLAM datasets use for
reference trajectories (BALM's ``poses_tum.txt``). Lines starting with ``#`` and blank
lines are skipped. Stamps are read as decimal text, so nanoseconds survive exactly.
"""

from __future__ import annotations

import os
from decimal import Decimal, InvalidOperation
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from alte.errors import PoseError
from alte.fsutil import atomic_path
from alte.io.poses.pose import PoseTrack

__all__ = ["read_tum", "write_tum"]

_NS = Decimal(1_000_000_000)


def _row(line: str, where: str) -> tuple[int, list[float]]:
    parts = line.split()
    if len(parts) != 8:
        raise PoseError(f"{where}: expected 8 values t x y z qx qy qz qw, got {len(parts)}")
    try:
        stamp = int((Decimal(parts[0]) * _NS).to_integral_value())
        values = [float(v) for v in parts[1:]]
    except (InvalidOperation, ValueError) as err:
        raise PoseError(f"{where}: not numbers: {line.strip()!r}") from err
    return stamp, values


def read_tum(path: str | os.PathLike[str]) -> PoseTrack:
    """The poses of a TUM file as a :class:`~alte.io.poses.pose.PoseTrack` (errors name the
    line)."""
    where = Path(path)
    try:
        lines = where.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as err:
        raise PoseError(f"pose file {where}: cannot read it ({err})") from err
    rows = [_row(line, f"{where}:{n}") for n, line in enumerate(lines, 1)
            if line.strip() and not line.lstrip().startswith("#")]
    if not rows:
        raise PoseError(f"pose file {where}: no poses (expected lines t x y z qx qy qz qw)")
    values = np.array([v for _, v in rows])
    return PoseTrack.from_samples([s for s, _ in rows], values[:, :3], values[:, 3:],
                                  str(where))


def write_tum(path: str | os.PathLike[str], stamps: NDArray[np.int64],
              positions: NDArray[np.float64], quaternions: NDArray[np.float64], *,
              overwrite: bool = False, header: str = "timestamp x y z qx qy qz qw") -> Path:
    """Write poses as a TUM file (stamps in ns, exact); refuses to replace a file unless
    ``overwrite``."""
    stamps = np.asarray(stamps, dtype=np.int64).reshape(-1)
    table = np.column_stack([np.asarray(positions, np.float64),
                             np.asarray(quaternions, np.float64)])
    if table.shape != (len(stamps), 7):
        raise PoseError(f"{path}: expected {len(stamps)} positions and quaternions, "
                        f"got {table.shape}")
    lines = [f"# {header}"] + [
        f"{s // 1_000_000_000}.{s % 1_000_000_000:09d} " + " ".join(f"{v:.9f}" for v in row)
        for s, row in zip(stamps.tolist(), table, strict=True)]
    with atomic_path(path, overwrite) as tmp:
        tmp.write_text("\n".join(lines) + "\n")
    return Path(path)
