"""Builders of bad inputs for the robustness catalogue (``tests/robustness/CATALOGUE.md``).

Bags are written with rosbags itself, message by message, so a test can break
exactly one thing (a stamp, a quaternion, a ``point_step``) and feed the result
through the public entry points. ``run_cli`` runs ``alte ...`` in-process and
returns the exit code with what the user saw.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from support.bagtools import TS, Message, write_ros2  # noqa: F401 (exported through globals())

from alte.cli import main
from alte.paths import realdata_dir

NS = 1_000_000_000
REALDATA = realdata_dir()
PC2 = "sensor_msgs/msg/PointCloud2"
POSE = "geometry_msgs/msg/PoseStamped"
IDENTITY = (0.0, 0.0, 0.0, 1.0)

#: (topic, msgtype, log_time_ns, message)


def header(stamp_ns: int, frame_id: str) -> Any:
    sec, nsec = divmod(int(stamp_ns), NS)
    return TS.types["std_msgs/msg/Header"](
        stamp=TS.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec), frame_id=frame_id
    )


def cloud_msg(stamp_ns: int, points: Any, *, point_step: int = 12,
              frame_id: str = "velodyne") -> Any:
    """An x, y, z float32 PointCloud2; ``point_step`` is written as given (may lie)."""
    pts = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    field = TS.types["sensor_msgs/msg/PointField"]
    fields = [field(name=n, offset=4 * k, datatype=7, count=1) for k, n in enumerate("xyz")]
    data = np.frombuffer(pts.tobytes(), np.uint8)
    return TS.types[PC2](
        header=header(stamp_ns, frame_id), height=1, width=len(pts), fields=fields,
        is_bigendian=False, point_step=point_step, row_step=point_step * len(pts),
        data=data, is_dense=bool(np.isfinite(pts).all()),
    )


def pose_msg(stamp_ns: int, pos: Sequence[float], quat: Sequence[float]) -> Any:
    t = TS.types
    pose = t["geometry_msgs/msg/Pose"](t["geometry_msgs/msg/Point"](*map(float, pos)),
                                       t["geometry_msgs/msg/Quaternion"](*map(float, quat)))
    return t[POSE](header(stamp_ns, "map"), pose)




def scan_points(k: int, n: int = 40) -> np.ndarray:
    """A small, deterministic scan: a tilted patch 2-6 m in front of the sensor."""
    rng = np.random.default_rng(k)
    xy = rng.uniform(-2.0, 2.0, (n, 2))
    return np.column_stack([xy[:, 0], 4.0 + xy[:, 1], -1.0 + 0.1 * xy[:, 0]])


def mission(
    n_scans: int = 4,
    *,
    scan_stamps: Sequence[int] | None = None,
    pose_stamps: Sequence[int] | None = None,
    quat: Callable[[int], Sequence[float]] = lambda _i: IDENTITY,
    position: Callable[[int], Sequence[float]] = lambda i: (0.1 * i, 0.0, 2.0),
    points: Callable[[int], Any] = scan_points,
    clouds: bool = True,
    poses: bool = True,
) -> list[Message]:
    """Scans at 10 Hz from t = 10 s on /points, poses at 100 Hz around them on /pose."""
    scans = list(scan_stamps) if scan_stamps is not None else [
        10 * NS + k * NS // 10 for k in range(n_scans)]
    if pose_stamps is None:
        pose_stamps = [10 * NS + k * NS // 100 for k in range(-2, 10 * len(scans) + 2)]
    msgs: list[Message] = []
    if poses:
        msgs += [("/pose", POSE, s, pose_msg(s, position(i), quat(i)))
                 for i, s in enumerate(pose_stamps)]
    if clouds:
        msgs += [("/points", PC2, s, cloud_msg(s, points(k))) for k, s in enumerate(scans)]
    return sorted(msgs, key=lambda m: m[2])


def run_cli(capsys: pytest.CaptureFixture[str], *argv: Any) -> tuple[int, str, str]:
    """``alte argv...`` in-process: exit code, stdout and stderr."""
    capsys.readouterr()
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(err: str, command: str) -> str:
    """The single stderr line of a failed command (asserts it is exactly one line)."""
    lines = [line for line in err.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith(f"alte {command}: error: ")]
    assert len(errors) == 1, err
    assert "Traceback" not in err, err
    return errors[0]


def realdata(*parts: str) -> Path:
    """A file of ../shared/realdata, or skip the test when it is absent."""
    path = REALDATA.joinpath(*parts)
    if not path.exists():
        pytest.skip(f"../shared/realdata/{'/'.join(parts)} absent")
    return path


@pytest.fixture(scope="session")
def bags() -> SimpleNamespace:
    """The builders of this module, for the tests."""
    names = ["TS", "NS", "PC2", "POSE", "IDENTITY", "header", "cloud_msg", "pose_msg",
             "write_ros2", "scan_points", "mission", "run_cli", "one_line_error", "realdata"]
    return SimpleNamespace(**{name: globals()[name] for name in names})
