"""Write ROS 2 bags (sqlite3 or mcap) that :func:`alte.io.bags.bag.read_frames` reads back.

Used by the simulator and the tests: scans go out as PointCloud2 in the sensor
frame (with extra per-point fields such as a ``time`` when given), body poses as
PoseStamped (at their own rate, e.g. 100 Hz motion capture), IMU samples as
``sensor_msgs/msg/Imu`` and the mounts as one ``/tf_static`` message (body -> sensor,
body -> IMU). Output is atomic and
deterministic: the same input gives byte-identical files (rosbags writes no wall
clock or random data; only its version string enters the mcap header).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from alte.errors import BagError
from alte.fsutil import atomic_dir
from alte.io.bags.imu import IMU_TYPE, ImuSamples
from alte.io.bags.pointcloud2 import CoordType, encode_pointcloud2, make_header
from alte.params import Record, param
from alte.progress import bar as progress_bar
from alte.types import Frame, Mount

if TYPE_CHECKING:  # rosbags declares MsgType (its message classes' type) for checkers only
    from rosbags.typesys.store import MsgType

__all__ = ["STORAGES", "BagSettings", "write_bag", "write_frames"]

STORAGES = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP}
_POSE = "geometry_msgs/msg/PoseStamped"
_PC2 = "sensor_msgs/msg/PointCloud2"
_TF = "tf2_msgs/msg/TFMessage"
_TYPESTORE = get_typestore(Stores.ROS2_HUMBLE)
#: Poses to interleave with the clouds: stamps, positions, quaternions, write order.
_Poses = tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]
#: A scan: stamp and points, optionally extra per-point fields (name -> (N,) array).
Cloud: TypeAlias = ("tuple[int, NDArray[np.float64]] | tuple[int, NDArray[np.float64], "
                    "Mapping[str, NDArray[np.generic[object]]]]")


def _pose_arrays(
    pose_stamps: ArrayLike, positions: ArrayLike, quaternions: ArrayLike
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    stamps = np.asarray(pose_stamps, dtype=np.int64).reshape(-1)
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    quat = np.asarray(quaternions, dtype=np.float64).reshape(-1, 4)
    if pos.shape[0] != stamps.size or quat.shape[0] != stamps.size:
        raise BagError(
            f"poses: {stamps.size} stamps but {pos.shape[0]} positions and "
            f"{quat.shape[0]} quaternions"
        )
    if not (np.isfinite(pos).all() and np.isfinite(quat).all()):
        raise BagError("poses: positions and quaternions must be finite")
    return stamps, pos, quat


def _pose_msg(header: MsgType, position: NDArray[np.float64], quat: NDArray[np.float64]) -> MsgType:
    types = _TYPESTORE.types
    point = types["geometry_msgs/msg/Point"](*map(float, position))
    orientation = types["geometry_msgs/msg/Quaternion"](*map(float, quat))
    return types[_POSE](header=header, pose=types["geometry_msgs/msg/Pose"](point, orientation))


def _transform(mount: Mount, stamp: int, body: str, child: str) -> MsgType:
    types = _TYPESTORE.types
    vector = types["geometry_msgs/msg/Vector3"](*map(float, mount.translation))
    rotation = types["geometry_msgs/msg/Quaternion"](*map(float, mount.quaternion))
    return types["geometry_msgs/msg/TransformStamped"](
        header=make_header(stamp, body, _TYPESTORE),
        child_frame_id=child,
        transform=types["geometry_msgs/msg/Transform"](vector, rotation),
    )


def _imu_msg(imu: ImuSamples, k: int) -> MsgType:
    """Sample ``k`` as ``sensor_msgs/msg/Imu``: orientation not given (covariance -1, REP 145)."""
    types = _TYPESTORE.types
    vec = types["geometry_msgs/msg/Vector3"]
    no_orientation = np.zeros(9)
    no_orientation[0] = -1.0
    return types[IMU_TYPE](
        header=make_header(int(imu.stamps[k]), imu.frame_id, _TYPESTORE),
        orientation=types["geometry_msgs/msg/Quaternion"](0.0, 0.0, 0.0, 1.0),
        orientation_covariance=no_orientation,
        angular_velocity=vec(*map(float, imu.angular_velocity[k])),
        angular_velocity_covariance=np.eye(3).reshape(-1) * imu.gyro_sigma**2,
        linear_acceleration=vec(*map(float, imu.linear_acceleration[k])),
        linear_acceleration_covariance=np.eye(3).reshape(-1) * imu.accel_sigma**2,
    )


@dataclass(frozen=True)
class _Names:
    """Where scans and poses go: world and sensor frames, topics, coordinate type."""

    world: str
    sensor: str
    cloud: str
    pose: str
    dtype: CoordType


class _BagOut:
    """An open writer: its connections, frame names and the time-sorted poses."""

    def __init__(self, writer: Writer, topics: dict[str, str], names: _Names) -> None:
        self.writer = writer
        self.names = names
        self.conns = {
            topic: writer.add_connection(topic, msgtype, typestore=_TYPESTORE)
            for topic, msgtype in topics.items()
        }
        self.next_pose = 0
        self.imu: ImuSamples | None = None
        self.next_imu = 0

    def put(self, topic: str, stamp: int, msg: object) -> None:
        data = _TYPESTORE.serialize_cdr(msg, self.conns[topic].msgtype)
        self.writer.write(self.conns[topic], int(stamp), data)

    def imu_until(self, until: int | None) -> None:
        """Write the not yet written IMU samples stamped at or before ``until`` (all: None)."""
        imu = self.imu
        while imu is not None and self.next_imu < len(imu) and (
                until is None or imu.stamps[self.next_imu] <= until):
            self.put(_IMU_TOPIC, int(imu.stamps[self.next_imu]), _imu_msg(imu, self.next_imu))
            self.next_imu += 1

    def poses_until(self, poses: _Poses, until: int | None) -> None:
        """Write the not yet written poses stamped at or before ``until`` (all for None)."""
        self.imu_until(until)
        stamps, pos, quat, order = poses
        while self.next_pose < order.size and (
            until is None or stamps[order[self.next_pose]] <= until
        ):
            k = order[self.next_pose]
            header = make_header(int(stamps[k]), self.names.world, _TYPESTORE)
            self.put(self.names.pose, int(stamps[k]), _pose_msg(header, pos[k], quat[k]))
            self.next_pose += 1

    def clouds(self, clouds: Iterable[Cloud], poses: _Poses, progress: bool) -> None:
        """Write every scan, each preceded by the poses (and IMU samples) up to its stamp."""
        topic = self.names.cloud
        for cloud in progress_bar(clouds, desc=topic, unit="scan", disable=not progress):
            stamp, points = cloud[0], cloud[1]
            extra = cloud[2] if len(cloud) > 2 else None
            self.poses_until(poses, int(stamp))
            msg = encode_pointcloud2(
                points, int(stamp), self.names.sensor, _TYPESTORE, dtype=self.names.dtype,
                extra_fields=extra,
            )
            self.put(topic, int(stamp), msg)
        self.poses_until(poses, None)


_IMU_TOPIC = "/imu"


def _name(value: str) -> bool:
    return bool(value.strip())


@dataclass(frozen=True)
class BagSettings(Record):
    """How :func:`write_bag` writes a bag: topics, storage, frame names, overwrite."""

    OWNER: ClassVar[str] = "bag"
    cloud_topic: str = param("/velodyne_points", _name, "a non-empty topic",
                             "the PointCloud2 topic")
    pose_topic: str = param("/pose", _name, "a non-empty topic", "the PoseStamped topic")
    storage: str = param("sqlite3", lambda v: v in STORAGES, "|".join(STORAGES),
                         "the rosbag2 storage plugin")
    world_frame: str = param("map", _name, "a non-empty frame id", "the poses' frame")
    body_frame: str = param("base_link", _name, "a non-empty frame id", "the vehicle's frame")
    sensor_frame: str = param("velodyne", _name, "a non-empty frame id", "the clouds' frame")
    overwrite: bool = param(False, help="replace an existing bag")
    progress: bool = param(False, help="a progress bar over the scans")


def write_bag(  # noqa: PLR0917 - positional arrays as specified for the simulator
    path: str | Path,
    clouds: Iterable[Cloud],
    pose_stamps: Sequence[int] | NDArray[np.int64],
    positions: NDArray[np.float64],
    quaternions: NDArray[np.float64],
    mount: Mount | None = None,
    settings: BagSettings | None = None,
    *,
    dtype: CoordType = np.float32,
    imu: ImuSamples | None = None,
) -> Path:
    """Write scans ``(stamp_ns, points[, fields])`` plus body poses (and mount) as a ROS 2 bag
    (``settings``: :class:`BagSettings`; ``dtype``: the clouds' coordinate type).

    Messages are logged at their header stamps, poses (and ``imu`` samples, on
    ``/imu`` with their mount in ``/tf_static``) interleaved in time order with the
    scans. Refuses to replace ``path`` unless ``settings.overwrite``.
    """
    settings = settings or BagSettings()
    cloud_topic, pose_topic = settings.cloud_topic, settings.pose_topic
    world_frame, body_frame = settings.world_frame, settings.body_frame
    sensor_frame = settings.sensor_frame
    stamps, pos, quat = _pose_arrays(pose_stamps, positions, quaternions)
    order = np.argsort(stamps, kind="stable")
    target = Path(path)
    topics = {cloud_topic: _PC2, pose_topic: _POSE}
    if imu is not None:
        topics[_IMU_TOPIC] = IMU_TYPE
    if mount is not None or (imu is not None and imu.mount is not None):
        topics["/tf_static"] = _TF
    names = _Names(world_frame, sensor_frame, cloud_topic, pose_topic, dtype)
    plugin = STORAGES[settings.storage]
    with (
        atomic_dir(target, overwrite=settings.overwrite) as tmp,
        Writer(tmp, version=Writer.VERSION_LATEST, storage_plugin=plugin) as writer,
    ):
        out = _BagOut(writer, topics, names)
        out.imu = imu
        first = int(stamps[order[0]]) if stamps.size else 0
        statics = [] if mount is None else [_transform(mount, first, body_frame, sensor_frame)]
        if imu is not None and imu.mount is not None:
            statics.append(_transform(imu.mount, first, body_frame, imu.frame_id))
        if statics:
            out.put("/tf_static", first, _TYPESTORE.types[_TF](transforms=statics))
        out.clouds(clouds, (stamps, pos, quat, order), settings.progress)
    return target


def write_frames(path: str | Path, frames: Sequence[Frame], mount: Mount | None,
                 settings: BagSettings | None = None, *, dtype: CoordType = np.float32
                 ) -> Path:
    """Write frames as a bag, each pose at its frame's stamp (as :func:`write_bag`)."""
    if not frames:
        raise BagError(f"{path}: no frames to write")
    return write_bag(
        path,
        ((f.stamp, f.points) for f in frames),
        np.array([f.stamp for f in frames], dtype=np.int64),
        np.array([f.position for f in frames], dtype=np.float64),
        np.array([f.quaternion for f in frames], dtype=np.float64),
        mount,
        settings,
        dtype=dtype,
    )
