"""The thesis' eight terrains (ch. 4), registered by name in :data:`TERRAINS`.

Simulated cases (4.1) are flown by the quadrotor at a constant altitude over
urban-scale scenes (tens of metres); experimental cases (4.2) are scanned from the
tripod cart inside an 8 m x 6 m motion-capture control volume (thesis 2.2.4) in a
room whose walls lie outside it and are cropped away. Dimensions are ours; the
layouts follow each section's description. Scene layouts are fixed (the debris is
placed by a constant-seeded generator), so only the run seed varies the noise.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from alte.sim.platform import Cart, Quadrotor, tripod_mount
from alte.sim.scene import Scene, SceneBuilder
from alte.types import Mount, thesis_mount

__all__ = ["TERRAINS", "Terrain", "TerrainSpec"]

#: The control volume of the experimental cases: x, y in [0, 8] x [0, 6] m.
CONTROL_VOLUME = (0.0, 0.0, -0.2, 8.0, 6.0, 2.5)


@dataclass(frozen=True)
class TerrainSpec:
    """Everything that defines a terrain's mission besides its mesh."""

    name: str
    section: str
    title: str
    case: str
    kind: str
    frames: int
    platform: Quadrotor | Cart
    crop_box: tuple[float, ...]
    registration_voxel: float
    landing_zone: tuple[float, float, float] | None = None

    @property
    def mount(self) -> Mount:
        """Sensor mount: the thesis' quadrotor mount or the tripod's."""
        return thesis_mount() if isinstance(self.platform, Quadrotor) else tripod_mount()

    def to_dict(self) -> dict[str, object]:
        """JSON-ready parameters (platform type included)."""
        out = asdict(self)
        out["platform"] = {"type": type(self.platform).__name__.lower(), **out["platform"]}
        if out["platform"].get("heights", 0) is None:  # the built-in terrains' hashes stay
            del out["platform"]["heights"]
        return out


@dataclass(frozen=True, eq=False)
class Terrain:
    """A terrain's spec and scene."""

    spec: TerrainSpec
    scene: Scene


def _pad(extent: tuple[float, float, float, float],
         margin: float = 60.0) -> tuple[float, float, float, float]:
    """Ground beyond the region of interest, so every beam of every scan returns."""
    return (extent[0] - margin, extent[1] - margin, extent[2] + margin, extent[3] + margin)


def _room(b: SceneBuilder) -> None:
    """Lab floor and walls around the control volume (cropped away by the crop box)."""
    b.ground("floor", (-4.0, -4.0, 12.0, 10.0))
    walls = [("wall_s", (4.0, -4.1), (16.2, 0.2)), ("wall_n", (4.0, 10.1), (16.2, 0.2)),
             ("wall_w", (-4.1, 3.0), (0.2, 14.4)), ("wall_e", (12.1, 3.0), (0.2, 14.4))]
    for name, xy, size in walls:
        b.slab(name, "room", xy, size, z=(0.0, 4.0))


def sim_nav_1() -> Terrain:
    """4.1.1: three complex obstacles and two walls, urban scale."""
    b = SceneBuilder()
    b.ground("ground", _pad((-45.0, -35.0, 45.0, 35.0)))
    b.slab("l_building_a", "building", (-14.0, 8.5), (12.0, 7.0), z=(0.0, 8.0))
    b.slab("l_building_b", "building", (-17.5, -1.0), (5.0, 12.0), z=(0.0, 8.0))
    b.cylinder("l_building_tower", "building", (-17.5, 8.5), 2.0, z=(8.0, 12.0))
    for i, (side, top) in enumerate([(12.0, 3.0), (8.0, 6.0), (4.0, 9.0)]):
        b.slab(f"pyramid_step{i}", "building", (8.0, 12.0), (side, side), z=(top - 3.0, top))
    b.slab("gate_left", "pillar", (10.0, -12.0), (2.0, 2.0), z=(0.0, 7.0))
    b.slab("gate_right", "pillar", (20.0, -12.0), (2.0, 2.0), z=(0.0, 7.0))
    b.slab("gate_lintel", "overhang", (15.0, -12.0), (12.0, 2.0), z=(7.0, 9.0))
    b.slab("wall_south", "wall", (-8.0, -22.0), (30.0, 0.5), z=(0.0, 4.0))
    b.slab("wall_east", "wall", (30.0, 4.0), (0.5, 28.0), z=(0.0, 5.0), yaw_deg=15.0)
    spec = TerrainSpec(
        "sim_nav_1", "4.1.1", "Urban Navigation, Terrain 1: Complex Objects", "nav", "sim", 569,
        Quadrotor(((-35.0, -28.0), (0.0, -30.0), (36.0, -26.0), (38.0, 10.0), (25.0, 28.0),
                   (-10.0, 26.0), (-34.0, 22.0), (-36.0, -5.0), (-5.0, 0.0), (20.0, 2.0)), 14.0),
        (-45.0, -35.0, -1.0, 45.0, 35.0, 15.0), 0.185)
    return Terrain(spec, b.build())


def sim_nav_2() -> Terrain:
    """4.1.2: overhangs and slender horizontal objects, flown partly underneath."""
    b = SceneBuilder()
    b.ground("ground", _pad((-40.0, -30.0, 40.0, 30.0)))
    b.slab("bridge_deck", "overhang", (0.0, -2.0), (30.0, 4.0), z=(4.5, 5.0))
    for i, x in enumerate((-12.0, -4.0, 4.0, 12.0)):
        b.cylinder(f"bridge_pillar{i}", "pillar", (x, -2.0), 0.4, z=(0.0, 4.5))
    b.slab("canopy_wall", "wall", (18.5, 13.0), (1.0, 10.0), z=(0.0, 6.0))
    b.slab("canopy_roof", "overhang", (13.5, 13.0), (10.0, 10.0), z=(5.6, 6.0))
    b.slab("beam_post_a", "pillar", (-22.0, -18.0), (0.3, 0.3), z=(0.0, 3.8))
    b.slab("beam_post_b", "pillar", (-22.0, -6.0), (0.3, 0.3), z=(0.0, 3.8))
    b.slab("beam", "beam", (-22.0, -12.0), (0.25, 12.3), z=(3.5, 3.8))
    b.slab("tower_west", "building", (-25.0, 12.0), (6.0, 8.0), z=(0.0, 14.0))
    b.slab("tower_east", "building", (-9.0, 12.0), (6.0, 8.0), z=(0.0, 14.0))
    b.slab("sky_bridge", "overhang", (-17.0, 12.0), (10.0, 4.0), z=(10.0, 11.0))
    spec = TerrainSpec(
        "sim_nav_2", "4.1.2", "Urban Navigation, Terrain 2: Overhangs", "nav", "sim", 520,
        Quadrotor(((-34.0, -24.0), (-5.0, -16.0), (26.0, -14.0), (30.0, 4.0), (22.0, 24.0),
                   (0.0, 24.0), (-17.0, 25.0), (-17.0, 0.0), (-8.0, -8.0), (10.0, 4.0),
                   (28.0, 0.0)), 8.0),
        (-40.0, -30.0, -1.0, 40.0, 30.0, 15.0), 0.15)
    return Terrain(spec, b.build())


def sim_lan_1() -> Terrain:
    """4.1.3: flat ground, a few simple obstacles, an obvious landing zone."""
    b = SceneBuilder()
    b.ground("ground", _pad((-35.0, -35.0, 35.0, 35.0)))
    b.slab("box_a", "building", (-12.0, 9.0), (4.0, 4.0), z=(0.0, 3.0))
    b.cylinder("cylinder", "pillar", (10.0, 11.0), 1.5, z=(0.0, 4.0))
    b.slab("box_b", "building", (11.0, -11.0), (6.0, 3.0), z=(0.0, 2.0), yaw_deg=30.0)
    b.sphere("ball", "debris", (-12.0, -10.0, 1.5), 1.5)
    spec = TerrainSpec(
        "sim_lan_1", "4.1.3", "Autonomous Landing, Terrain 1: Simple Environment", "lan", "sim",
        450, Quadrotor(((-28.0, -24.0), (26.0, -22.0), (28.0, 0.0), (-26.0, 2.0), (-28.0, 24.0),
                        (26.0, 26.0)), 10.0),
        (-35.0, -35.0, -1.0, 35.0, 35.0, 12.0), 0.12, landing_zone=(0.0, 0.0, 5.0))
    return Terrain(spec, b.build())


def sim_lan_2() -> Terrain:
    """4.1.4: package-delivery yard; the roof ridge is above the flight altitude."""
    b = SceneBuilder()
    b.ground("ground", _pad((-30.0, -30.0, 30.0, 30.0)))
    b.slab("house", "building", (-8.0, 6.0), (10.0, 8.0), z=(0.0, 5.5))
    b.gable("house_roof", "building", (-8.0, 6.0), size=(11.0, 9.0), z=(5.5, 9.5))
    b.slab("shed", "building", (10.0, 10.0), (3.0, 2.5), z=(0.0, 2.4))
    b.slab("car_body", "car", (2.0, -2.0), (4.4, 1.8), z=(0.0, 1.0), yaw_deg=10.0)
    b.slab("car_cabin", "car", (1.8, -2.0), (2.4, 1.6), z=(1.0, 1.5), yaw_deg=10.0)
    b.cylinder("tree_trunk", "tree", (12.0, -8.0), 0.25, z=(0.0, 3.0), segments=12)
    b.sphere("tree_crown", "tree", (12.0, -8.0, 4.6), 2.2)
    for i, x in enumerate(np.arange(-20.0, 20.01, 2.5)):
        b.slab(f"fence_post{i}", "fence", (float(x), -15.0), (0.1, 0.1), z=(0.0, 1.2))
    for i, z in enumerate((0.5, 1.0)):
        b.slab(f"fence_rail{i}", "fence", (0.0, -15.0), (40.0, 0.05), z=(z, z + 0.1))
    spec = TerrainSpec(
        "sim_lan_2", "4.1.4", "Autonomous Landing, Terrain 2: Complex Scenario", "lan", "sim", 508,
        Quadrotor(((-24.0, -24.0), (22.0, -24.0), (24.0, -4.0), (-22.0, -6.0), (-24.0, 20.0),
                   (4.0, 24.0), (22.0, 22.0)), 8.0),
        (-30.0, -30.0, -1.0, 30.0, 30.0, 12.0), 0.12, landing_zone=(8.0, -7.0, 1.5))
    return Terrain(spec, b.build())


def exp_nav_1() -> Terrain:
    """4.2.1: urban canyon of buoys and pillars; back and forth with one turn."""
    b = SceneBuilder()
    _room(b)
    for i, x in enumerate((1.5, 3.0, 4.5, 6.0)):
        b.cylinder(f"buoy{i}", "buoy", (x, 1.4), 0.25, z=(0.0, 1.0 + 0.15 * i))
        b.slab(f"pillar{i}", "pillar", (x + 0.6, 4.6), (0.3, 0.3), z=(0.0, 1.6))
    spec = TerrainSpec(
        "exp_nav_1", "4.2.1", "Experimental Urban Navigation, Terrain 1: Urban Canyon", "nav",
        "exp", 300, Cart(((0.5, 2.6), (6.2, 2.6), (7.3, 3.0), (6.2, 3.4), (0.5, 3.4)),
                         time_offset_s=0.01, jitter_s=0.005),
        CONTROL_VOLUME, 0.03)
    return Terrain(spec, b.build())


def exp_nav_2() -> Terrain:
    """4.2.2: a complex set-up and a manoeuvring path (strong desynchronization)."""
    b = SceneBuilder()
    _room(b)
    for i, (x, y) in enumerate([(1.5, 1.0), (2.2, 4.8), (5.5, 5.0), (6.8, 1.2)]):
        b.cylinder(f"buoy{i}", "buoy", (x, y), 0.25, z=(0.0, 1.2))
    b.slab("table_top", "overhang", (4.0, 3.0), (1.2, 0.8), z=(0.72, 0.75))
    for i, (dx, dy) in enumerate([(-0.55, -0.35), (0.55, -0.35), (-0.55, 0.35), (0.55, 0.35)]):
        b.slab(f"table_leg{i}", "pillar", (4.0 + dx, 3.0 + dy), (0.05, 0.05), z=(0.0, 0.72))
    b.slab("box_tall", "debris", (7.0, 4.5), (0.6, 0.6), z=(0.0, 1.4), yaw_deg=20.0)
    b.slab("box_low", "debris", (2.5, 2.5), (0.8, 0.5), z=(0.0, 0.4), yaw_deg=-35.0)
    b.slab("pole_stand_a", "pillar", (5.0, 0.6), (0.1, 0.1), z=(0.0, 1.1))
    b.slab("pole_stand_b", "pillar", (5.0, 2.0), (0.1, 0.1), z=(0.0, 1.1))
    b.slab("pole", "beam", (5.0, 1.3), (0.06, 1.5), z=(1.1, 1.16))
    spec = TerrainSpec(
        "exp_nav_2", "4.2.2", "Experimental Urban Navigation, Terrain 2: Complex Environment",
        "nav", "exp", 420,
        Cart(((0.4, 0.4), (3.0, 1.6), (5.8, 3.6), (7.4, 2.8), (6.0, 0.8), (3.4, 3.4),
              (1.0, 5.4), (0.6, 2.6), (2.8, 4.0)),
             wobble_deg=2.0, yaw_swing_deg=30.0, yaw_swing_hz=0.6, swing_burst_s=7.0, sway_deg=6.0,
             time_offset_s=0.08, jitter_s=0.03),
        CONTROL_VOLUME, 0.03)
    return Terrain(spec, b.build())


def _debris(b: SceneBuilder, n: int, heights: tuple[float, float], seed: int) -> None:
    """Foam blocks of random footprint/height/yaw placed on a jittered grid."""
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.linspace(1.2, 6.8, 5), np.linspace(1.0, 5.0, 4))
    pick = rng.permutation(xs.size)[:n]
    for i, k in enumerate(pick):
        dx, dy = rng.uniform(-0.3, 0.3, 2)
        xy = (float(xs.flat[k] + dx), float(ys.flat[k] + dy))
        size = (float(rng.uniform(0.2, 0.6)), float(rng.uniform(0.2, 0.6)))
        top = float(rng.uniform(*heights))
        b.slab(f"debris{i}", "debris", xy, size, z=(0.0, top), yaw_deg=float(rng.uniform(0, 90)))


_LAWNMOWER = ((0.4, 0.6), (7.2, 0.7), (7.5, 2.0), (0.8, 2.4), (0.5, 3.8), (7.2, 4.0), (7.4, 5.5))


def exp_lan_1() -> Terrain:
    """4.2.3: flat floor with foam debris and a car (high altitude contrast)."""
    b = SceneBuilder()
    _room(b)
    b.slab("car_body", "car", (4.0, 3.0), (2.0, 0.9), z=(0.0, 0.45))
    b.slab("car_cabin", "car", (3.9, 3.0), (1.0, 0.8), z=(0.45, 0.75))
    _debris(b, 8, (0.08, 0.3), seed=423)
    spec = TerrainSpec(
        "exp_lan_1", "4.2.3", "Experimental Autonomous Landing, Terrain 1: Simple Environment",
        "lan", "exp", 400, Cart(_LAWNMOWER), CONTROL_VOLUME, 0.03)
    return Terrain(spec, b.build())


def exp_lan_2() -> Terrain:
    """4.2.4: debris of varied sizes, some very close to the ground; no car."""
    b = SceneBuilder()
    _room(b)
    _debris(b, 12, (0.02, 0.35), seed=424)
    spec = TerrainSpec(
        "exp_lan_2", "4.2.4", "Experimental Autonomous Landing, Terrain 2: Complex Environment",
        "lan", "exp", 400, Cart(_LAWNMOWER), CONTROL_VOLUME, 0.03)
    return Terrain(spec, b.build())


#: Terrain name -> builder.
TERRAINS: dict[str, Callable[[], Terrain]] = {
    "sim_nav_1": sim_nav_1,
    "sim_nav_2": sim_nav_2,
    "sim_lan_1": sim_lan_1,
    "sim_lan_2": sim_lan_2,
    "exp_nav_1": exp_nav_1,
    "exp_nav_2": exp_nav_2,
    "exp_lan_1": exp_lan_1,
    "exp_lan_2": exp_lan_2,
}
