"""Helpers that write small ROS bags with rosbags itself (not with alte's writer),
so the reader is tested against independently made files."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from rosbags.rosbag1 import Writer as Writer1
from scipy.spatial.transform import Rotation
from support.bagtools import TS, Message, write_ros2  # noqa: F401 (exported through globals())

from alte.paths import realdata_dir

NS = 1_000_000_000
REALDATA = realdata_dir()

PC2 = "sensor_msgs/msg/PointCloud2"
POSE = "geometry_msgs/msg/PoseStamped"
ODOM = "nav_msgs/msg/Odometry"
TF = "tf2_msgs/msg/TFMessage"

#: (topic, msgtype, log_time_ns, message)


def header(stamp_ns: int, frame_id: str) -> Any:
    sec, nsec = divmod(int(stamp_ns), NS)
    return TS.types["std_msgs/msg/Header"](
        stamp=TS.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec), frame_id=frame_id
    )


def cloud_msg(stamp_ns: int, points: np.ndarray, frame_id: str = "velodyne") -> Any:
    """A float32 x, y, z + intensity PointCloud2 built by hand (16-byte points)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    rec = np.zeros(len(pts), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("i", "<f4")])
    rec["x"], rec["y"], rec["z"] = pts.T
    field = TS.types["sensor_msgs/msg/PointField"]
    fields = [field(name=n, offset=4 * k, datatype=7, count=1)
              for k, n in enumerate(("x", "y", "z", "intensity"))]
    return TS.types["sensor_msgs/msg/PointCloud2"](
        header=header(stamp_ns, frame_id), height=1, width=len(pts), fields=fields,
        is_bigendian=False, point_step=16, row_step=16 * len(pts),
        data=np.frombuffer(rec.tobytes(), np.uint8), is_dense=bool(np.isfinite(pts).all()),
    )


def _pose(pos: Any, quat: Any) -> Any:
    t = TS.types
    return t["geometry_msgs/msg/Pose"](
        t["geometry_msgs/msg/Point"](*map(float, pos)),
        t["geometry_msgs/msg/Quaternion"](*map(float, quat)),
    )


def pose_msg(stamp_ns: int, pos: Any, quat: Any, frame_id: str = "map") -> Any:
    return TS.types["geometry_msgs/msg/PoseStamped"](header(stamp_ns, frame_id), _pose(pos, quat))


def odom_msg(stamp_ns: int, pos: Any, quat: Any, child: str = "base_link") -> Any:
    t = TS.types
    cov = np.zeros(36)
    twist = t["geometry_msgs/msg/TwistWithCovariance"](
        t["geometry_msgs/msg/Twist"](t["geometry_msgs/msg/Vector3"](0.0, 0.0, 0.0),
                                     t["geometry_msgs/msg/Vector3"](0.0, 0.0, 0.0)), cov)
    return t["nav_msgs/msg/Odometry"](
        header(stamp_ns, "odom"), child,
        t["geometry_msgs/msg/PoseWithCovariance"](_pose(pos, quat), cov), twist,
    )


def tf_msg(stamp_ns: int, transforms: list[tuple[str, str, Any, Any]]) -> Any:
    """TFMessage from ``(parent, child, translation, quaternion)`` tuples."""
    t = TS.types
    return t["tf2_msgs/msg/TFMessage"](transforms=[
        t["geometry_msgs/msg/TransformStamped"](
            header(stamp_ns, parent), child,
            t["geometry_msgs/msg/Transform"](t["geometry_msgs/msg/Vector3"](*map(float, xyz)),
                                             t["geometry_msgs/msg/Quaternion"](*map(float, q))),
        )
        for parent, child, xyz, q in transforms
    ])




def write_ros1(path: Path, messages: list[Message]) -> Path:
    """Write ``messages`` as a ROS 1 ``.bag``.

    The definitions stored are the ROS 2 ones (Header without ``seq``; the ROS 1
    Noetic store lacks tf2_msgs): a valid ROS 1 file whose reader must use them.
    """
    with Writer1(path) as writer:
        conns: dict[str, Any] = {}
        for topic, msgtype, _, _ in messages:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=TS)
        for topic, msgtype, log_time, msg in messages:
            writer.write(conns[topic], log_time, TS.serialize_ros1(msg, msgtype))
    return path


def trajectory(stamps_ns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A smooth test trajectory: positions (M, 3) and unit quaternions (M, 4)."""
    t = (np.asarray(stamps_ns) - 10 * NS) / NS
    pos = np.column_stack([2.0 * t, np.sin(t), 1.0 + 0.1 * t])
    quat = Rotation.from_euler("zyx", np.column_stack([0.8 * t, 0.1 * t, 0.05 * t])).as_quat()
    return pos, quat


def scans(n: int = 4, points: int = 30, start_ns: int = 10 * NS, step_ns: int = NS // 10,
          seed: int = 0) -> list[tuple[int, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(start_ns + k * step_ns, rng.uniform(-5, 5, (points, 3))) for k in range(n)]


def standard_messages(n_scans: int = 4, pose_topic: str = "/pose") -> list[Message]:
    """Scans at 10 Hz on /points, PoseStamped at 100 Hz covering them, /tf_static mount."""
    msgs: list[Message] = []
    stamps = 10 * NS + np.arange(0, n_scans * 10 + 1) * (NS // 100)
    pos, quat = trajectory(stamps)
    mount = ("base_link", "velodyne", (0.1, 0.0, -0.08), (0.0, 0.0, 0.3826834, 0.9238795))
    msgs.append(("/tf_static", TF, int(stamps[0]), tf_msg(int(stamps[0]), [mount])))
    msgs += [(pose_topic, POSE, int(s), pose_msg(int(s), p, q))
             for s, p, q in zip(stamps, pos, quat, strict=True)]
    msgs += [("/points", PC2, s, cloud_msg(s, pts)) for s, pts in scans(n_scans)]
    return sorted(msgs, key=lambda m: m[2])


@pytest.fixture(scope="session")
def ros() -> SimpleNamespace:
    """The helpers of this module, for the tests (``ros.write_ros2(...)`` etc.)."""
    names = ["TS", "NS", "PC2", "POSE", "ODOM", "TF", "REALDATA", "header", "cloud_msg",
             "pose_msg", "odom_msg", "tf_msg", "write_ros2", "write_ros1", "trajectory", "scans",
             "standard_messages"]
    return SimpleNamespace(**{name: globals()[name] for name in names})
