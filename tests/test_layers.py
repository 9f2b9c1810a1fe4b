"""The layering the code keeps, stated so it stays kept.

Data flows one way: bag -> frames -> registered cloud -> map -> metrics -> tables. The
package has two wings and a command line over both:

- the **library** a user of the field imports: the foundations (errors, types, settings
  records, paths), the stages (io, registration, ground, mappers, metrics, sim), the
  pipeline that chains them, and what runs on a finished map (export, the mapper
  conformance check);
- the **lab** (``alte.lab``) that reproduces and extends the thesis (studies, plot,
  report); the benchmark sits outside the package, in ``bench/``;
- the **CLI** (``alte.cli``, ``alte.commands``) over both.

A module may import its own layer and the layers below it, never one above: the library
never imports the lab, no stage imports the pipeline, nothing but the CLI imports the CLI.
Between stages only the edges of :data:`STAGE_EDGES` exist.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from support.imports import imports

#: Top-level parts of ``alte`` from the bottom layer up ("" is the package itself).
LAYERS: tuple[tuple[str, ...], ...] = (
    ("", "errors", "types", "params", "paths", "fsutil", "tensors", "progress", "_numba",
     "_kernels"),
    ("io", "registration", "ground", "mappers", "metrics", "sim"),
    ("pipeline",),
    ("export", "testing"),
    ("lab", "lab.entry", "lab.machine", "lab.plot", "lab.studies", "lab.report", "lab.notebook"),
    ("cli", "commands", "__main__"),
)
#: The library's layers (the lab and the CLI sit above them).
LIBRARY = frozenset(part for layer in LAYERS[:4] for part in layer)
#: The stages that may import one another: importer -> imported.
STAGE_EDGES = frozenset({("registration", "io"), ("sim", "io"), ("sim", "ground"),
                         ("mappers", "ground"), ("metrics", "mappers")})


def _part(module: str) -> str:
    """``alte.io.bags.bag`` -> ``io``; ``alte.lab.plot.figure`` -> ``lab.plot``; ``alte`` ->
    ``""``."""
    parts = module.split(".")
    return ".".join(parts[1:3]) if parts[1:2] == ["lab"] else ".".join(parts[1:2])


def breaches(graph: dict[str, set[str]]) -> list[str]:
    """Every import that runs up a layer, or between stages outside :data:`STAGE_EDGES`."""
    level = {part: i for i, layer in enumerate(LAYERS) for part in layer}
    found = []
    for module, targets in sorted(graph.items()):
        a = _part(module)
        for target in sorted(targets):
            b = _part(target)
            if b not in level or a not in level:
                found.append(f"{module} -> {target}: {a or b!r} is in no layer")
            elif level[b] > level[a]:
                found.append(f"{module} -> {target}: runs up from {a} to {b}")
            elif level[a] == level[b] == 1 and a != b and (a, b) not in STAGE_EDGES:
                found.append(f"{module} -> {target}: stage {a} imports stage {b}")
    return found


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    import alte

    return imports(Path(alte.__file__).parent)


def test_every_part_of_alte_is_in_a_layer(graph: dict[str, set[str]]) -> None:
    level = {part for layer in LAYERS for part in layer}
    assert {_part(m) for m in graph} <= level


def test_imports_run_down_the_layers(graph: dict[str, set[str]]) -> None:
    assert "alte.pipeline" in graph["alte.export.run"]  # the graph is read
    assert breaches(graph) == []


def test_the_library_never_imports_the_lab_or_the_cli(graph: dict[str, set[str]]) -> None:
    lab_or_cli = [(m, t) for m, ts in graph.items() for t in ts
                  if _part(m) in LIBRARY and _part(t) not in LIBRARY]
    assert lab_or_cli == []


@pytest.mark.parametrize(("edge", "says"), [
    (("alte.io.bags.bag", "alte.pipeline.run"), "runs up from io to pipeline"),
    (("alte.mappers.quadtree", "alte.lab.studies.landing"), "runs up from mappers to lab.studies"),
    (("alte.lab.report.build", "alte.commands.map"), "runs up from lab.report to commands"),
    (("alte.ground.filters", "alte.mappers.registry"), "stage ground imports stage mappers"),
    (("alte.newpart", "alte.io"), "'newpart' is in no layer"),
])
def test_the_check_finds_a_breach(edge: tuple[str, str], says: str) -> None:
    module, target = edge
    assert [says in b for b in breaches({module: {target}})] == [True]
    assert breaches({"alte.registration.odometry": {"alte.io.bags.bag"}}) == []
