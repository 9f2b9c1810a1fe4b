"""Terrain folders on disk: ``DIR/NAME/`` = ROS 2 bag + ground truth + scenario.json.

:func:`ensure_terrain` simulates a terrain unless a finished folder with the same
spec hash and seed already exists; the folder is built under a temporary name and
renamed when complete (:func:`alte.fsutil.atomic_dir`), and scenario.json records
the size and SHA-256 of every file, so an interrupted or altered run is never
mistaken for a finished one. :func:`load_scenario` reads a folder back. A sensor profile
other than the thesis' (:mod:`alte.sim.profile`) is part of the spec hash and of the
folder name (``NAME-uav``), so it never replaces the thesis' terrain.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from alte.errors import AlteError, SimulationError
from alte.fsutil import atomic_dir
from alte.io.bags.writer import BagSettings
from alte.sim.groundtruth import GROUND_TRUTH_FILE, load_ground_truth, write_ground_truth
from alte.sim.meta import SCENARIO_FILE, MountMeta, ScenarioMeta
from alte.sim.mission import Simulation, simulate
from alte.sim.profile import PROFILES, SensorProfile
from alte.sim.scene import Scene
from alte.sim.sensor import VLP16
from alte.sim.terrains import TERRAINS, Terrain
from alte.types import JSONDict, Mount

if TYPE_CHECKING:
    from alte.io.bags.imu import ImuSamples
    from alte.io.bags.writer import Cloud

__all__ = ["BAG_DIR", "IMU_TOPIC", "SCENARIO_FILE", "SIM_VERSION", "MountMeta", "Scenario",
           "ScenarioMeta", "ensure_terrain", "get_terrain", "is_current", "load_metadata",
           "load_scenario", "profile_label", "spec_hash", "terrain_folder", "update_terrain",
           "write_scenario"]

#: Bump when the simulator's output changes for the same spec (invalidates caches).
SIM_VERSION = 1
BAG_DIR = "bag"
CLOUD_TOPIC = "/velodyne_points"
POSE_TOPIC = "/pose"
IMU_TOPIC = "/imu"


def get_terrain(name: str, data_dir: str | os.PathLike[str] | None = None) -> Terrain:
    """Build the registered terrain ``name``, or read the terrain imported as
    ``data_dir/NAME`` (``alte simulate TILE ...``); SimulationError lists the valid names."""
    builder = TERRAINS.get(name)
    if builder is not None:
        return builder()
    folder = Path(data_dir) / name if data_dir is not None else None
    if folder is not None and (folder / SCENARIO_FILE).is_file():
        from alte.sim.real.folder import imported_terrain

        return imported_terrain(folder)
    where = f" in {data_dir}" if data_dir is not None else ""
    raise SimulationError(f"unknown terrain {name!r}; valid: {', '.join(TERRAINS)}, or a "
                          f"terrain imported{where} (`alte simulate TILE.laz`)")


def profile_label(profile: SensorProfile) -> str:
    """The profile's name in :data:`PROFILES`, else ``custom-<hash>`` of its settings."""
    for name, known in PROFILES.items():
        if known == profile:
            return name
    digest = hashlib.sha256(json.dumps(profile.as_dict(), sort_keys=True).encode())
    return f"custom-{digest.hexdigest()[:8]}"


def spec_hash(terrain: Terrain, frames: int | None, storage: str,
              sensor: VLP16 | None = None, profile: SensorProfile | None = None) -> str:
    """SHA-256 of everything that defines the output except the seed (the cache key)."""
    sensor = sensor or VLP16()
    spec = {"version": SIM_VERSION, "spec": terrain.spec.to_dict(), "sensor": sensor.to_dict(),
            "frames": frames, "storage": storage, "mount": terrain.spec.mount.to_string()}
    if profile is not None and not profile.instantaneous:  # the thesis' hash is unchanged
        spec["profile"] = profile.as_dict()
    digest = hashlib.sha256(json.dumps(spec, sort_keys=True).encode())
    scene = terrain.scene
    for arr in (scene.vertices, scene.triangles, scene.object_ids):
        digest.update(np.ascontiguousarray(arr).tobytes())
    digest.update(json.dumps([[o.name, o.cls] for o in scene.objects]).encode())
    return digest.hexdigest()


def _file_table(root: Path) -> dict[str, dict[str, int | str]]:
    table: dict[str, dict[str, int | str]] = {}
    for path in sorted(p for p in root.rglob("*") if p.is_file()):
        rel = path.relative_to(root).as_posix()
        if rel != SCENARIO_FILE:
            table[rel] = {"size": path.stat().st_size,
                          "sha256": hashlib.sha256(path.read_bytes()).hexdigest()}
    return table


#: Folders whose files matched their scenario's hashes in this process, with the files'
#: (path, size, mtime) then: a sweep asks for the same terrain once per map, and hashing a
#: whole UAV mission's bag (57 MB) each time cost more than mapping it.
_VERIFIED: dict[Path, tuple[tuple[str, int, int], ...]] = {}


def _file_stats(root: Path) -> tuple[tuple[str, int, int], ...]:
    """(relative path, size, mtime in ns) of every file under ``root``, sorted."""
    return tuple((p.relative_to(root).as_posix(), st.st_size, st.st_mtime_ns)
                 for p in sorted(root.rglob("*")) if p.is_file() for st in (p.stat(),))


def _mount_dict(mount: Mount) -> MountMeta:
    return {"translation": mount.translation.tolist(), "quaternion": mount.quaternion.tolist(),
            "xyz_rpy_deg": mount.to_string()}


def _metadata(terrain: Terrain, sim: Simulation, run: JSONDict) -> JSONDict:
    spec = terrain.spec
    control = list(spec.crop_box) if spec.kind == "exp" else None
    return {
        "alte_sim_version": SIM_VERSION, "name": spec.name, "section": spec.section,
        "title": spec.title, "case": spec.case, "kind": spec.kind, **run,
        "bag": BAG_DIR, "ground_truth": GROUND_TRUTH_FILE,
        "cloud_topic": CLOUD_TOPIC, "pose_topic": POSE_TOPIC,
        "crop_box": list(spec.crop_box), "control_volume": control,
        "extent": terrain.scene.bounds().tolist(), "landing_zone": spec.landing_zone,
        "registration_voxel": spec.registration_voxel, "mount": _mount_dict(spec.mount),
        "duration_s": sim.duration_s, "spec": spec.to_dict(), "sensor": VLP16().to_dict(),
        "sensor_profile": {"name": profile_label(sim.profile), **sim.profile.as_dict()},
        "point_time_field": sim.profile.time_field if sim.times is not None else None,
        "imu_topic": IMU_TOPIC if sim.imu is not None else None,
        "imu_mount": _mount_dict(sim.imu.mount) if sim.imu is not None else None,
        "counts": sim.counts,
        "objects": [{"id": i, "name": o.name, "class": o.cls}
                    for i, o in enumerate(terrain.scene.objects)],
    }


def write_scenario(target: str | os.PathLike[str], terrain: Terrain, sim: Simulation, *,
                   seed: int, frames: int | None, storage: str = "sqlite3",
                   progress: bool = False, extra: JSONDict | None = None,
                   more: Callable[[Path], None] | None = None) -> Path:
    """Write bag, ground truth and scenario.json into ``target`` atomically (replacing it);
    ``extra`` adds keys to scenario.json, ``more`` writes further files into the folder."""
    from alte.io.bags.writer import write_bag

    key = spec_hash(terrain, frames, storage, profile=sim.profile)
    with atomic_dir(target, overwrite=True) as tmp:
        tmp.mkdir()
        settings = BagSettings(cloud_topic=CLOUD_TOPIC, pose_topic=POSE_TOPIC, storage=storage,
                               progress=progress)
        write_bag(tmp / BAG_DIR, _clouds(sim), sim.pose_stamps, sim.positions, sim.quaternions,
                  sim.mount, settings, imu=_imu_samples(sim))
        write_ground_truth(tmp / GROUND_TRUTH_FILE, terrain.scene)
        if more is not None:
            more(tmp)
        run: JSONDict = {"seed": int(seed), "frames_requested": frames, "spec_hash": key,
               "storage": storage}
        meta = {**_metadata(terrain, sim, run), **(extra or {})}
        meta["files"] = _file_table(tmp)
        (tmp / SCENARIO_FILE).write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
    return Path(target)


def _clouds(sim: Simulation) -> Iterator[Cloud]:
    """The scans to write, each with its per-point time field when the sensor sweeps."""
    if sim.times is None:
        yield from zip(sim.stamps.tolist(), sim.scans, strict=True)
        return
    for stamp, points, times in zip(sim.stamps.tolist(), sim.scans, sim.times, strict=True):
        if sim.profile.time_field == "t":
            field = {"t": np.round(times * 1e9).astype(np.uint32)}
        else:
            field = {"time": times.astype(np.float32)}
        yield stamp, points, field


def _imu_samples(sim: Simulation) -> ImuSamples | None:
    from alte.io.bags.imu import ImuSamples

    imu = sim.imu
    if imu is None:
        return None
    return ImuSamples(imu.stamps, imu.angular_velocity, imu.linear_acceleration, "imu_link",
                      imu.mount, imu.gyro_sigma, imu.accel_sigma)


def is_current(folder: Path, key: str, seed: int) -> bool:
    """True when ``folder`` holds a finished simulation with this spec hash and seed."""
    try:
        meta: JSONDict = json.loads((folder / SCENARIO_FILE).read_text())
    except (OSError, ValueError):
        return False
    if meta.get("spec_hash") != key or meta.get("seed") != seed or not meta.get("files"):
        return False
    stats = _file_stats(folder)
    if _VERIFIED.get(folder.resolve()) == stats:
        return True
    current = bool(_file_table(folder) == meta["files"])
    if current:
        _VERIFIED[folder.resolve()] = stats
    return current


def terrain_folder(out_dir: str | os.PathLike[str], name: str, frames: int | None = None,
                   seed: int = 0, profile: SensorProfile | None = None) -> Path:
    """Where a terrain lives: ``out_dir/NAME`` (full mission, seed 0), ``NAME-Nf`` (N scans),
    ``NAME-sS`` / ``NAME-Nf-sS`` (seed S), each with ``-PROFILE`` for another sensor
    profile than the thesis' (``NAME-uav``).

    Reduced missions (quick runs, tests), other seeds and profiles get their own folders,
    so they never replace the full one and concurrent runs cannot collide.
    """
    stem = name if profile is None or profile.instantaneous else \
        f"{name}-{profile_label(profile)}"
    stem = stem if frames is None else f"{stem}-{int(frames)}f"
    return Path(out_dir) / (stem if seed == 0 else f"{stem}-s{int(seed)}")


def ensure_terrain(name: str, out_dir: str | os.PathLike[str] = "data", seed: int = 0,
                   frames: int | None = None, *, storage: str = "sqlite3", force: bool = False,
                   progress: bool = False, profile: SensorProfile | None = None) -> Path:
    """Simulate terrain ``name`` into :func:`terrain_folder` unless it is already current."""
    return update_terrain(name, out_dir, seed, frames, storage=storage, force=force,
                          progress=progress, profile=profile)[0]


def update_terrain(name: str, out_dir: str | os.PathLike[str] = "data", seed: int = 0,
                   frames: int | None = None, *, storage: str = "sqlite3", force: bool = False,
                   progress: bool = False, profile: SensorProfile | None = None
                   ) -> tuple[Path, bool]:
    """As :func:`ensure_terrain`; also says whether the terrain was (re)simulated."""
    terrain = get_terrain(name, out_dir)
    target = terrain_folder(out_dir, name, frames, seed, profile)
    key = spec_hash(terrain, frames, storage, profile=profile)
    if not force and is_current(target, key, seed):
        return target, False
    if target.exists() and not force and not (target / SCENARIO_FILE).is_file():
        raise SimulationError(f"{target} exists but is not a simulated terrain folder; "
                              "remove it or pass force=True", setting="output.overwrite")
    sim = simulate(terrain, seed=seed, frames=frames, progress=progress, profile=profile)
    folder = write_scenario(target, terrain, sim, seed=seed, frames=frames, storage=storage,
                            progress=progress)
    return folder, True


@dataclass(frozen=True, eq=False)
class Scenario:
    """A simulated terrain read back from its folder."""

    path: Path
    bag: Path
    metadata: ScenarioMeta
    ground_truth: Scene

    @property
    def name(self) -> str:
        """Terrain name."""
        return str(self.metadata["name"])

    @property
    def case(self) -> str:
        """``"nav"`` (3D maps) or ``"lan"`` (2D maps)."""
        return str(self.metadata["case"])

    @property
    def crop_box(self) -> tuple[float, ...]:
        """Region kept by registration: the control volume or the scene's extent."""
        return tuple(float(v) for v in self.metadata["crop_box"])

    @property
    def registration_voxel(self) -> float:
        """Recommended grid-average voxel (m) for thesis-sized clouds."""
        return float(self.metadata["registration_voxel"])

    @property
    def mount(self) -> Mount:
        """Sensor mount (also stored in the bag's ``/tf_static``)."""
        mount = self.metadata["mount"]
        return Mount(np.asarray(mount["translation"]), np.asarray(mount["quaternion"]))


def load_metadata(directory: str | os.PathLike[str]) -> ScenarioMeta:
    """``DIR/NAME/scenario.json``, checked for the keys the pipeline reads."""
    folder = Path(directory)
    try:
        meta: ScenarioMeta = json.loads((folder / SCENARIO_FILE).read_text())
    except OSError as err:
        raise SimulationError(f"{folder}: no {SCENARIO_FILE}; run `alte simulate`") from err
    except ValueError as err:
        raise SimulationError(f"{folder / SCENARIO_FILE}: not valid JSON ({err})") from err
    missing = [k for k in ("name", "case", "bag", "crop_box", "registration_voxel", "mount")
               if k not in meta]
    if missing:
        raise SimulationError(f"{folder / SCENARIO_FILE}: missing keys {missing}")
    return meta


def load_scenario(directory: str | os.PathLike[str]) -> Scenario:
    """Read ``DIR/NAME`` (scenario.json, bag path, ground truth)."""
    folder = Path(directory)
    meta = load_metadata(folder)
    bag = folder / meta["bag"]
    if not bag.is_dir():
        raise SimulationError(f"{folder}: bag folder {bag.name!r} is missing")
    try:
        truth = load_ground_truth(folder)
    except AlteError as err:
        raise SimulationError(f"{folder}: {err}") from err
    return Scenario(folder, bag, meta, truth)
