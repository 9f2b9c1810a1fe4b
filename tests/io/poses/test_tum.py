"""TUM trajectory files: exact stamps, round trip, errors that name the line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from alte.errors import AlteError, PoseError
from alte.io.poses.tum import read_tum, write_tum


def test_round_trip_keeps_nanoseconds(tmp_path: Path) -> None:
    stamps = np.array([1_630_577_808_570_040_832, 1_630_577_809_069_524_001], np.int64)
    positions = np.array([[-12.354499, 7.115946, -0.257147], [1.0, 2.0, 3.0]])
    quats = np.array([[-0.082812071, -0.031559248, -0.242562923, 0.966079398],
                      [0.0, 0.0, 0.0, 1.0]])
    path = write_tum(tmp_path / "poses.txt", stamps, positions, quats)
    track = read_tum(path)
    assert np.array_equal(track.stamps, stamps)
    assert np.allclose(track.positions, positions) and np.allclose(track.quaternions, quats)
    with pytest.raises(AlteError, match="already exists"):
        write_tum(path, stamps, positions, quats)


def test_balm_style_text(tmp_path: Path) -> None:
    path = tmp_path / "poses_tum.txt"
    path.write_text("# timestamp x y z qx qy qz qw\n\n"
                    "1630577808.570041 -12.35 7.11 -0.25 0 0 0 1\n"
                    "1630577809.069524 -11.86 6.64 -0.31 0 0 0.2 0.98\n")
    track = read_tum(path)
    assert track.stamps.tolist() == [1_630_577_808_570_041_000, 1_630_577_809_069_524_000]


@pytest.mark.parametrize(("text", "match"), [
    ("1.0 2 3 4 0 0 0\n", r"poses.txt:1: expected 8 values t x y z qx qy qz qw, got 7"),
    ("# only a header\n", r"pose file .*poses.txt: no poses"),
    ("1.0 2 3 x 0 0 0 1\n", r"poses.txt:1: not numbers"),
    ("1.0 2 3 4 0 0 0 0\n", r"sample 0 .* has an unusable pose"),
])
def test_bad_files_name_the_line(tmp_path: Path, text: str, match: str) -> None:
    path = tmp_path / "poses.txt"
    path.write_text(text)
    with pytest.raises(PoseError, match=match):
        read_tum(path)
    with pytest.raises(PoseError, match="cannot read it"):
        read_tum(tmp_path / "absent.txt")
