"""Row 9: peak memory of ``alte map BAG`` on a mission and on that mission flown four times,
and of the commands that only read or print (``alte --version``, ``alte info BAG``) against
the bare interpreter: a CLI that imports only what its command runs.

Frames stream from the bag through registration into the map, so the peak resident
set should be the map plus a few frames, whatever the bag's length. The long mission
is the terrain's bag with its scans repeated (stamps shifted past the previous
lap, poses repeated with them), written once beside the bench data. Each run is a
fresh ``alte map`` process; its peak RSS is its own ``VmHWM`` (see :data:`_CHILD`). The peer of a
long-mission row is the same mapper on the short mission, measured in the same run.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from bench.core import LIMITS, Context, Result
from bench.workload import Points, workload_dir

__all__ = ["LAPS", "LIGHT_CEILINGS_MB", "MAPPER_SETS", "RSS_CEILING_MB", "RSS_SPREAD",
           "light_memory", "long_mission", "map_memory", "peak_rss_mb"]

#: How many times the long mission flies the short one.
LAPS = 4
#: The long mission's peak may exceed the short one's by this share at most.
RSS_SPREAD = LIMITS[9] - 1.0
#: 3D-ALTE's ceiling for ``alte map BAG`` (MB).
RSS_CEILING_MB = 300.0
#: ``--set`` arguments of each measured mapper (Octomap at the bench's 0.2 m).
MAPPER_SETS: dict[str, tuple[str, ...]] = {"alte3d": (), "octomap": ("--set", "resolution=5")}
TERRAIN = "sim_nav_1"
#: Ceilings (MB) of the commands that load no mapper, study or viewer.
LIGHT_CEILINGS_MB: dict[str, float] = {"--version": 80.0, "info": 150.0}


def _laps(bag: Path, laps: int, gap_ns: int) -> Iterator[tuple[int, Points]]:
    """The bag's scans (sensor frame) ``laps`` times, each lap shifted by ``gap_ns``."""
    from alte.io.bags.bag import FrameStream

    for lap in range(laps):
        for frame in FrameStream(bag):
            yield frame.stamp + lap * gap_ns, frame.points


def long_mission(bag: Path, out: Path, laps: int = LAPS) -> Path:
    """``out``: ``bag``'s scans and poses repeated ``laps`` times (kept once written)."""
    from alte.io.bags.bag import FrameStream
    from alte.io.bags.writer import write_bag

    if out.exists():
        return out
    stream = FrameStream(bag)
    poses = [(f.stamp, f.position, f.quaternion) for f in stream]
    stamps = np.array([p[0] for p in poses], dtype=np.int64)
    gap = int(stamps[-1] - stamps[0]) + int(np.median(np.diff(stamps))) if len(stamps) > 1 \
        else 10**8
    shifted = np.concatenate([stamps + lap * gap for lap in range(laps)])
    positions = np.tile(np.array([p[1] for p in poses]), (laps, 1))
    quaternions = np.tile(np.array([p[2] for p in poses]), (laps, 1))
    return write_bag(out, _laps(bag, laps, gap), shifted, positions, quaternions, stream.mount)


#: Runs ``alte`` with the given arguments and reports its own high-water mark on exit.
#: ``os.wait4``'s ``ru_maxrss`` cannot be used: Linux folds the pre-``exec`` memory of a
#: forked child (a copy of this, much larger, bench process) into it.
_CHILD = """
import sys
from alte.cli import main
try:
    code = main(sys.argv[1:])
finally:
    with open("/proc/self/status") as status:
        hwm = next(line.split()[1] for line in status if line.startswith("VmHWM:"))
    sys.stderr.write(f"\\nVmHWM_kB {hwm}\\n")
sys.exit(code)
"""


#: The interpreter alone, reporting its high-water mark as :data:`_CHILD` does.
_BARE = _CHILD.replace("from alte.cli import main", "").replace("main(sys.argv[1:])", "0")


def peak_rss_mb(args: Sequence[str], code: str = _CHILD) -> tuple[float, float]:
    """Peak resident set (MB, the process's own ``VmHWM``) and wall time (s) of one
    ``alte ARGS`` child process (``code``: another program with the same report)."""
    start = time.perf_counter()
    child = subprocess.run([sys.executable, "-c", code, *args], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True, check=False)
    wall = time.perf_counter() - start
    if child.returncode != 0:
        raise RuntimeError(f"alte {' '.join(args)} failed ({child.returncode}): "
                           f"{child.stderr.strip()[-2000:]}")
    marks = [line.split()[1] for line in child.stderr.splitlines()
             if line.startswith("VmHWM_kB ")]
    if not marks:
        raise RuntimeError(f"alte {' '.join(args)} reported no VmHWM: {child.stderr[-500:]}")
    return int(marks[-1]) / 1024.0, wall


def _median_rss(bag: Path, mapper: str, repeats: int,
                frames: int | None) -> tuple[float, float]:
    args = ["map", str(bag), "--mapper", mapper, *MAPPER_SETS[mapper], "--json",
            *(() if frames is None else ("--frames", str(frames)))]
    runs = [peak_rss_mb(args) for _ in range(repeats)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def map_memory(ctx: Context) -> list[Result]:
    """Row 9: peak RSS of ``alte map`` on the long mission against the short one."""
    from alte.sim import ensure_terrain

    cfg = ctx.config
    folder = ensure_terrain(TERRAIN, workload_dir(cfg.data_dir, cfg.quick),
                            frames=6 if cfg.quick else None, progress=cfg.progress)
    bag = folder / "bag"
    long_bag = long_mission(bag, folder.parent / f"{folder.name}-x{LAPS}-bag")
    repeats = max(1, min(cfg.repeats, 3))  # peak RSS barely varies between runs
    frames = cfg.frames if cfg.quick else None  # quick: the first laps' worth of scans
    out = []
    for mapper in MAPPER_SETS:
        short_mb, short_s = _median_rss(bag, mapper, repeats, frames)
        long_mb, long_s = _median_rss(long_bag, mapper, repeats,
                                      None if frames is None else LAPS * frames)
        ceiling = RSS_CEILING_MB if mapper == "alte3d" else float("inf")
        met = long_mb <= (1 + RSS_SPREAD) * short_mb and max(long_mb, short_mb) < ceiling
        target = f"ratio <= {1 + RSS_SPREAD:g}" + (
            f", < {RSS_CEILING_MB:g} MB" if ceiling < float("inf") else "")
        out.append(Result(9, f"{mapper} alte map peak RSS, {TERRAIN} x{LAPS} vs x1",
                          long_mb, short_mb, "MB", target, bool(met),
                          {"wall_s_long": long_s, "wall_s_short": short_s,
                           "repeats": repeats, "laps": LAPS, "frames_short": frames}))
    return out + light_memory(bag)


def light_memory(bag: Path) -> list[Result]:
    """Row 9's light commands: their peak RSS against the bare interpreter's."""
    bare_mb, _ = peak_rss_mb([], _BARE)
    out = []
    for command, ceiling in LIGHT_CEILINGS_MB.items():
        args = [command, str(bag)] if command == "info" else [command]
        mb, wall = peak_rss_mb(args)
        name = "alte info BAG" if command == "info" else f"alte {command}"
        out.append(Result(9, f"{name} peak RSS vs the bare interpreter", mb, bare_mb, "MB",
                          f"< {ceiling:g} MB", mb < ceiling, {"wall_s": wall}))
    return out
