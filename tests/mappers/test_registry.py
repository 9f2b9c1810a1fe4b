"""The registry: plugins found by entry point (a distribution's metadata on sys.path, as pip
installs it), loaded only when used, refused with a clear error when they break the
contract; ALTE_MAPPERS; ``alte info --mappers``; names resolved in one place."""

import re
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from alte.cli import main
from alte.errors import ContractError, MapperError
from alte.mappers import registry
from alte.pipeline import MapSettings

ROOT = Path(__file__).parents[2]
EXAMPLES = ROOT / "docs" / "examples"
#: A plugin module built on the documented example (docs/examples on sys.path).
MODULE = '''
from mean_grid import MeanGrid


class Fake(MeanGrid):
    name = "fakemap"
    title = "Fake map"


class Future(MeanGrid):
    name = "future"
    title = "From the future"
    api_version = 2
'''


def _install(folder: Path, points: str) -> None:
    """A distribution as pip leaves it: its module and its .dist-info with entry points."""
    (folder / "fakeplugin.py").write_text(MODULE)
    info = folder / "fake_alte_plugin-0.3.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-alte-plugin\n"
                                   "Version: 0.3\n")
    (info / "entry_points.txt").write_text(f"[alte.mappers]\n{points}\n")


@pytest.fixture
def plugin_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A folder on sys.path for a fake distribution; the registry forgets it afterwards."""
    monkeypatch.syspath_prepend(str(EXAMPLES))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delenv(registry.ENV, raising=False)
    registry.refresh()
    yield tmp_path
    sys.modules.pop("fakeplugin", None)
    registry.refresh()


def test_found_by_entry_point_and_loaded_on_use(plugin_path: Path) -> None:
    _install(plugin_path, "fakemap = fakeplugin:Fake")
    registry.refresh()
    assert registry.names()[:4] == ("quadtree", "octomap", "alte2d", "alte3d")
    assert "fakemap" in registry.names()
    assert "fakeplugin" not in sys.modules  # listing a name reads metadata only
    entry = next(e for e in registry.entries() if e.name == "fakemap")
    assert (entry.origin, entry.target, entry.builtin) == ("fake-alte-plugin 0.3",
                                                           "fakeplugin:Fake", False)
    spec = MapSettings("fakemap", {"cell": "0.5"})
    assert spec.cls.__name__ == "Fake" and spec.record.as_dict() == {"cell": 0.5}
    assert registry.title("fakemap") == "Fake map" and registry.title("gone") == "gone"


@pytest.mark.parametrize(("points", "name", "match"), [
    ("ghost = nosuch:Thing", "ghost",
     r"mapper plugin 'ghost' \(entry point alte.mappers: ghost = nosuch:Thing, from "
     r"fake-alte-plugin 0.3\): cannot load nosuch:Thing \(ModuleNotFoundError"),
    ("future = fakeplugin:Future", "future",
     r"mapper plugin 'future' .* breaks the mapper contract \(version 1\): written against "
     r"mapper contract version 2"),
    ("other = fakeplugin:Fake", "other",
     r"the class is named 'fakemap'; the entry point must carry the class's name"),
    ("bad = fakeplugin", "bad", r"'fakeplugin' is not 'module:Class'"),
])
def test_refused_plugins(plugin_path: Path, points: str, name: str, match: str) -> None:
    _install(plugin_path, points)
    registry.refresh()
    with pytest.raises(ContractError, match=match):
        registry.resolve(name)


def test_a_builtin_name_is_not_taken(plugin_path: Path) -> None:
    _install(plugin_path, "quadtree = fakeplugin:Fake")
    registry.refresh()
    assert registry.resolve("quadtree") is registry.BUILTIN[0]
    (why,) = registry.refused().values()
    assert re.search(r"the name 'quadtree' is taken by built-in mapper 'quadtree'", why)


def test_unknown_name_lists_the_mappers() -> None:
    with pytest.raises(MapperError, match=r"unknown mapper 'octree'; valid: quadtree, octomap, "
                                          r"alte2d, alte3d"):
        registry.resolve("octree")


def test_environment_variable(plugin_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(registry.ENV, "mean_grid:MeanGrid, nosuch:Thing")
    registry.refresh()
    assert "meangrid" in registry.names()
    assert registry.resolve("meangrid").title == "Mean grid"
    assert any("nosuch:Thing" in why for why in registry.refused().values())


def test_info_lists_and_refuses(plugin_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _install(plugin_path, "fakemap = fakeplugin:Fake\nghost = nosuch:Thing")
    registry.refresh()
    assert main(["info", "--mappers"]) == 1
    out = capsys.readouterr().out
    assert re.search(r"fakemap\s+2D\s+Fake map\s+\(fake-alte-plugin 0\.3: fakeplugin:Fake\)", out)
    assert re.search(r"ghost\s+REFUSED\s+mapper plugin 'ghost'", out)
    assert "alte3d     3D  3D-ALTE" in out


#: The modules where a mapper's name given by a user or by the thesis' data becomes a
#: class, through the registry: the map specification, the sweep spec, the thesis'
#: claims on properties of its own mappers, and display titles of table rows.
BOUNDARIES = {"alte/mappers/registry.py", "alte/pipeline/spec.py", "alte/lab/studies/sweep/spec.py",
              "alte/lab/studies/analysis/evidence.py", "alte/lab/studies/analysis/tradeoff.py"}


def test_names_are_resolved_in_the_registry_only() -> None:
    """No dict of mapper classes outside the registry, and every lookup of a name goes
    through it from one of the boundary modules."""
    lookups = re.compile(r"registry\.(resolve|title)\(|\bMAPPERS\b|mapper_class\(|"
                         r"make_mapper\([\"']")
    found = {str(p.relative_to(ROOT)) for p in (ROOT / "alte").rglob("*.py")
             if lookups.search(p.read_text())}
    assert found <= BOUNDARIES, found - BOUNDARIES


V1_MODULE = '''
from dataclasses import dataclass
from typing import ClassVar

from mean_grid import MeanGrid
from alte.mappers.api import Record, param


@dataclass(frozen=True)
class OldGridParams(Record):
    OWNER: ClassVar[str] = "oldgrid"
    cell: float = param(1.0, lambda v: v > 0, "cell > 0")


class OldGrid(MeanGrid):
    """Written against contract v1 as first documented: its record is named Params."""

    name = "oldgrid"
    title = "Old grid"
    Params = OldGridParams
'''


def test_a_v1_plugin_naming_its_record_params_still_loads(plugin_path: Path) -> None:
    (plugin_path / "oldplugin.py").write_text(V1_MODULE)
    try:
        with pytest.warns(DeprecationWarning, match=r"OldGrid: the settings record is named "
                                                    r"Settings now; Params .* deprecated"):
            cls = registry.MapperEntry("oldgrid", "oldplugin:OldGrid", "test").load()
        assert cls.Settings is cls.Params and cls.Settings.__name__ == "OldGridParams"
        assert registry.create(cls, {"cell": "2"}).params.cell == 2.0
    finally:
        sys.modules.pop("oldplugin", None)


def test_the_first_names_of_the_settings_records_still_import() -> None:
    from alte.mappers import alte2d, quadtree

    with pytest.warns(DeprecationWarning, match=r"quadtree.QuadtreeParams is deprecated; "
                                                r"use QuadtreeSettings"):
        old = quadtree.QuadtreeParams
    assert old is quadtree.QuadtreeSettings and quadtree.Quadtree.Params is old
    with pytest.warns(DeprecationWarning, match="Alte2DSettings"):
        from alte.mappers.alte2d import Alte2DParams  # noqa: F401
    with pytest.raises(AttributeError, match="no attribute 'NoSuch'"):
        alte2d.NoSuch  # noqa: B018
