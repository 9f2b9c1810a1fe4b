import pytest

from alte.errors import AlteError
from alte.fsutil import atomic_dir, atomic_path


def test_atomic_path_writes_on_success(tmp_path):
    target = tmp_path / "sub" / "out.txt"
    with atomic_path(target) as tmp:
        tmp.write_text("done")
        assert not target.exists()
    assert target.read_text() == "done"
    assert list(target.parent.iterdir()) == [target]


def test_atomic_path_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "out.txt"
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("killed")
    assert list(tmp_path.iterdir()) == []


def test_atomic_path_refuses_overwrite(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("user data")
    with pytest.raises(AlteError, match=r"out\.txt already exists"), atomic_path(target):
        pass
    assert target.read_text() == "user data"
    with atomic_path(target, overwrite=True) as tmp:
        tmp.write_text("new")
    assert target.read_text() == "new"


def test_atomic_dir(tmp_path):
    target = tmp_path / "bag"
    with atomic_dir(target) as tmp:
        assert not tmp.exists()
        tmp.mkdir()
        (tmp / "a").write_text("x")
    assert (target / "a").read_text() == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"]
    with pytest.raises(AlteError, match="already exists"), atomic_dir(target):
        pass
    with pytest.raises(RuntimeError), atomic_dir(tmp_path / "other") as tmp:
        tmp.mkdir()
        raise RuntimeError("boom")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"]


def test_atomic_path_uses_umask_mode(tmp_path):
    target = tmp_path / "cloud.ply"
    with atomic_path(target) as tmp:
        tmp.write_text("x")
    import os

    mask = os.umask(0)
    os.umask(mask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~mask
