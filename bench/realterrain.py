"""Row 14: a real LiDAR tile imported as a terrain and flown, against a built-in mission.

Ours: ``alte simulate ign_lidarhd_farmland.laz`` as the library runs it: the 351 m x 370 m
IGN LiDAR HD tile (698 k points) read, gridded and meshed, and the thesis' landing mission
sized to it flown and written (bag, truth, scenario.json; every scan). The peer: the
built-in ``sim_lan_1`` simulated and written whole in the same run (450 scans), so a ratio
survives the machine's load. Target: the tile imported and flown in under a minute of wall
time; CPU seconds beside it. ``--quick`` flies a 100 m x 100 m corner of the tile.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from alte.paths import realdata_dir
from alte.types import JSONDict
from bench.core import Context, Result

__all__ = ["TILE", "real_terrain"]

#: The shared tile of the row (relative to the real-data folder).
TILE = Path("als") / "ign_lidarhd_farmland.laz"


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def _since(start: tuple[float, float]) -> tuple[float, float]:
    return time.perf_counter() - start[0], time.process_time() - start[1]


def real_terrain(ctx: Context) -> list[Result]:
    """Row 14 (module docstring); no result without the shared tile."""
    from alte.sim import ensure_terrain
    from alte.sim.real import Flight, import_terrain, write_imported

    tile = realdata_dir() / TILE
    if not tile.is_file():
        return []
    with tempfile.TemporaryDirectory() as tmp:
        start = _clock()
        # Quick runs (the tests) fly a 100 m corner of the tile.
        region = (484880.0, 6632880.0, 484980.0, 6632980.0) if ctx.config.quick else None
        imported = import_terrain([tile], Flight(), region=region)
        wall_i, cpu_i = _since(start)
        start = _clock()
        write_imported(imported, Path(tmp))
        wall_f, cpu_f = _since(start)
        start = _clock()
        ensure_terrain("sim_lan_1", Path(tmp) / "peer", force=True)
        peer_wall, peer_cpu = _since(start)
    spec = imported.terrain.spec
    wall = wall_i + wall_f
    detail: JSONDict = {"scans": spec.frames, "import_wall_s": wall_i, "import_cpu_s": cpu_i,
                        "fly_wall_s": wall_f, "fly_cpu_s": cpu_f, "cpu_s": cpu_i + cpu_f,
                        "peer_cpu_s": peer_cpu, "peer_scans": 450,
                        "altitude_m": imported.source["altitude_m"], "quick": ctx.config.quick}
    part = "a 100 m corner of " if ctx.config.quick else ""
    return [Result(14, f"{part}{TILE.name} imported + landing mission flown ({spec.frames} scans) "
                       "vs sim_lan_1 simulated (450 scans)", wall, peer_wall, "s",
                   "< 60 s wall", wall < 60.0, detail)]
