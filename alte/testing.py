"""The conformance test alte ships for mapper authors: :func:`check_mapper`.

``check_mapper(MyMapper)`` raises :class:`~alte.errors.ContractError` listing every way
the class breaks the mapper contract (:mod:`alte.mappers.api`), or returns None. It
checks the class (what the registry checks before it takes a plugin: version, names,
parameter record, capabilities), then makes maps of a small synthetic scene (a flat
16 m square with a 2 m x 2 m x 1.5 m block, two scans from 10 m up) and reads them the
way alte does: frame by frame and in one build, ``cells()`` with its layers, counts,
corners, cost, ``reread`` with every view parameter, ``.npz`` export, refused
parameters and refused points. A plugin's test suite calls it on its classes::

    from alte.testing import check_mapper

    def test_contract():
        check_mapper(MyMapper)
"""

from __future__ import annotations

import itertools
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Protocol, cast

import numpy as np
from numpy.typing import NDArray

from alte.errors import AlteError, ContractError
from alte.mappers import export_map, registry
from alte.mappers.api import VARIANCE, CellCounts, Cells, Domain, DomainUse, Mapper
from alte.mappers.contract import PROPERTIES

__all__ = ["SCENE_DOMAIN", "check_mapper", "scene"]

#: The root cell the scene is mapped in (mappers that use a domain).
SCENE_DOMAIN = Domain(0.0, 0.0, -2.0, 20.0)
_Z_RANGE = (-1.0, 2.5)


def scene(seed: int = 0) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Two scans (points (N, 3), sensor origin (3,)) of a flat 16 m square holding a
    1.5 m high block, with 1 cm of height noise."""
    rng = np.random.default_rng(seed)
    scans = []
    for origin in ((8.0, 8.0, 10.0), (6.0, 9.0, 10.0)):
        xy = rng.uniform(1.0, 15.0, (1500, 2))
        block = (np.abs(xy[:, 0] - 9.0) < 1.0) & (np.abs(xy[:, 1] - 7.0) < 1.0)
        z = np.where(block, 1.5, 0.0) + rng.normal(0.0, 0.01, len(xy))
        scans.append((np.column_stack([xy, z]), np.array(origin)))
    return scans


class _Make(Protocol):
    """A mapper class called with parameters by name, as ``--set`` gives them."""

    def __call__(self, domain: Domain | None, /, **given: object) -> object: ...


def _cells_problems(cls: type[Mapper], cells: object) -> list[str]:
    """What is wrong with one ``cells()`` result."""
    if not isinstance(cells, Cells):
        return [f"cells() returned {type(cells).__name__}, not alte.mappers.api.Cells"]
    k, out = len(cells.centers), []
    shapes = {"centers": (cells.centers, (k, 3), "f"), "sizes": (cells.sizes, (k, 3), "f"),
              "value": (cells.value, (k,), "f"), "occupied": (cells.occupied, (k,), "b"),
              "level": (cells.level, (k,), "i")}
    for name, (array, shape, kind) in shapes.items():
        arr = np.asarray(array)
        if arr.shape != shape or arr.dtype.kind != kind:
            out.append(f"cells().{name} is {arr.dtype} {arr.shape}, expected kind {kind!r} "
                       f"shape {shape}")
    if out:
        return out
    if not np.isfinite(cells.sizes).all() or (cells.sizes < 0).any():
        out.append("cells().sizes must be finite and >= 0")
    if cls.dims == 2 and np.any(cells.sizes[:, 2] != 0):
        out.append("a 2D map's cells have sizes[:, 2] == 0 (the height is centers[:, 2])")
    return out + _layer_problems(cls, cells)


def _layer_problems(cls: type[Mapper], cells: Cells) -> list[str]:
    """What is wrong with the layers of one ``cells()`` result."""
    k, out = len(cells.centers), []
    if set(cells.layers) != set(cls.layers):
        out.append(f"cells().layers has {sorted(cells.layers)}, the class declares "
                   f"layers={sorted(cls.layers)}")
    for name, values in cells.layers.items():
        arr = np.asarray(values)
        if arr.shape != (k,) or arr.dtype != np.float64:
            out.append(f"layer {name!r} is {arr.dtype} {arr.shape}, expected float64 ({k},)")
        elif name == VARIANCE and np.any(arr[np.isfinite(arr)] < 0):
            out.append("the variance layer holds negative values")
    return out


def _map_problems(cls: type[Mapper], mapper: Mapper, what: str) -> list[str]:
    """What is wrong with a finished map ``mapper`` (made by ``what``)."""
    out = [f"after {what}: {p}" for p in _cells_problems(cls, mapper.cells())]
    if out:
        return out
    cells = mapper.cells()
    known = np.isfinite(cells.centers).all(axis=1)
    if not known.any():
        out.append(f"after {what}: no cell with a finite centre (the scene has 3000 points)")
    heights = cells.centers[known, 2]
    if cls.dims == 2 and known.any() and (heights.min() < _Z_RANGE[0]
                                          or heights.max() > _Z_RANGE[1]):
        out.append(f"after {what}: cell heights {heights.min():.3g}..{heights.max():.3g} m "
                   f"lie outside the scene's {_Z_RANGE} m")
    if mapper.cell_counts() != CellCounts.of(cells):
        out.append(f"after {what}: cell_counts() {mapper.cell_counts()} differs from cells() "
                   f"{CellCounts.of(cells)}")
    for name in ("basis_functions", "memory_bytes", "cost", "points_outside"):
        value = getattr(mapper, name)
        if not isinstance(value, int | np.integer) or isinstance(value, bool) or value < 0:
            out.append(f"after {what}: {name}={value!r} must be an int >= 0")
    corners = np.asarray(mapper.corners())
    if corners.ndim != 2 or corners.shape[1:] != (3,) or not np.isfinite(corners).all():
        out.append(f"after {what}: corners() must be finite (M, 3), got {corners.shape}")
    if not isinstance(mapper.params, cls.Settings):
        out.append(f"params is a {type(mapper.params).__name__}, not {cls.Settings.__name__}")
    return out


def _same(a: Cells, b: Cells) -> bool:
    return all(np.array_equal(x, y, equal_nan=x.dtype.kind == "f")
               for x, y in zip(a.as_dict().values(), b.as_dict().values(), strict=False))


def _attempt(out: list[str], what: str, call: Callable[[], object]) -> object:
    """``call()``, or None with ``what`` and the exception noted in ``out``."""
    try:
        return call()
    except Exception as err:  # the author's code may raise anything: report it
        out.append(f"{what} raised {type(err).__name__}: {err}")
        return None


def _refuses(out: list[str], what: str, call: Callable[[], object]) -> None:
    """Note in ``out`` unless ``call()`` raises an :class:`AlteError`."""
    try:
        call()
    except AlteError:
        return
    except Exception as err:  # an untyped error is a contract breach too
        out.append(f"{what} raised {type(err).__name__}, not an alte.errors.AlteError: {err}")
        return
    out.append(f"{what} was accepted")


def _construct(cls: type[Mapper], out: list[str]) -> Domain | None:
    """Construction checks; the domain the scene is mapped in."""
    domain = None if cls.domain_use is DomainUse.UNUSED else SCENE_DOMAIN
    made = _attempt(out, f"{cls.__name__}(domain, record=Settings())",
                    lambda: cls(domain, record=cls.Settings()))
    if made is not None and not isinstance(made, Mapper):
        missing = [p for p in PROPERTIES if not hasattr(made, p)]
        out.append(f"an instance does not meet the Mapper protocol (missing {missing})")
    make = cast(_Make, cls)  # parameters by name, as --set gives them
    _refuses(out, f"{cls.__name__}(unknown parameter)",
             lambda: make(domain, no_such_parameter_=1))
    grid = cls.settings_grid
    for row in itertools.islice(itertools.product(*grid.values()), 4):
        given = dict(zip(grid, row, strict=True))
        _attempt(out, f"{cls.__name__}(**{given}) from settings_grid",
                 lambda given=given: make(domain, **given))  # type: ignore[misc]
    return domain


def _feed(cls: type[Mapper], domain: Domain | None, out: list[str]) -> None:
    """Frame-by-frame and batch maps of the scene, re-reads, export and bad points."""
    scans = scene()
    framed = cls(domain)
    _refuses(out, "insert() of NaN points", lambda: framed.insert(
        np.full((4, 3), np.nan), scans[0][1]))
    _refuses(out, "insert() of (N, 2) points", lambda: framed.insert(np.zeros((4, 2)),
                                                                      scans[0][1]))
    _attempt(out, "insert() of no points", lambda: framed.insert(np.empty((0, 3)), scans[0][1]))
    costs = []
    for points, origin in scans:
        try:
            framed.insert(points, origin)
        except Exception as err:  # the author's code may raise anything: report it
            out.append(f"insert() of the scene raised {type(err).__name__}: {err}")
            return
        costs.append(framed.cost)
    if costs != sorted(costs):
        out.append(f"cost decreased while inserting: {costs}")
    out += _map_problems(cls, framed, "two inserts")
    cloud = np.vstack([p for p, _ in scans])
    origins = np.vstack([np.broadcast_to(o, p.shape) for p, o in scans])
    built = cls(domain)
    for _ in range(2):
        _attempt(out, "build()", lambda: built.build(cloud, origins))
    out += _map_problems(cls, built, "build()")
    fresh = cls(domain)
    _attempt(out, "build()", lambda: fresh.build(cloud, origins))
    if not _same(built.cells(), fresh.cells()) or built.cost != fresh.cost:
        out.append("a second build() differs from the first (build must start afresh)")
    _reread(cls, built, out)
    _export(built, out)


def _reread(cls: type[Mapper], mapper: Mapper, out: list[str]) -> None:
    """``reread`` with the current value of every view parameter equals the map; another
    parameter is refused."""
    params = mapper.params.as_dict()
    view = {name: params[name] for name in cls.view_params}
    again = _attempt(out, f"reread(**{view})", lambda: mapper.reread(**view))
    if isinstance(again, Mapper) and not _same(again.cells(), mapper.cells()):
        out.append("reread() with the same view parameters changed the cells")
    stored = sorted(set(params) - cls.view_params)
    if stored:
        _refuses(out, f"reread({stored[0]}=...) of a stored parameter",
                 lambda: mapper.reread(**{stored[0]: params[stored[0]]}))


def _export(mapper: Mapper, out: list[str]) -> None:
    with tempfile.TemporaryDirectory(prefix="alte-check-") as tmp:
        path = Path(tmp) / "cells.npz"
        if _attempt(out, "export to .npz", lambda: export_map(mapper, path)) is not None:
            with np.load(path, allow_pickle=False) as data:
                if len(data["centers"]) != len(mapper.cells()):
                    out.append("the .npz export lost cells")


def check_mapper(cls: object) -> None:
    """Raise :class:`ContractError` listing every way ``cls`` breaks the mapper contract
    (module docstring); return None when it meets it."""
    registry.check_contract(cls)
    assert isinstance(cls, type)  # check_contract refuses anything else
    mapper_cls: type[Mapper] = cls
    out: list[str] = []
    domain = _construct(mapper_cls, out)
    if not out:
        _feed(mapper_cls, domain, out)
    if out:
        raise ContractError(f"{cls.__qualname__} breaks the mapper contract: "
                            + "; ".join(dict.fromkeys(out)))
