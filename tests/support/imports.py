"""The import graph of a package, read from its source (for the cycle and layer tests)."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
from scipy.sparse import csr_array
from scipy.sparse.csgraph import connected_components

__all__ = ["cycles", "imports"]


def imports(package: Path) -> dict[str, set[str]]:
    """Module -> the package's modules it imports, anywhere in its body (function-level
    and ``TYPE_CHECKING`` imports included; ``from pkg import name`` counts ``pkg.name``
    when that is a module, else ``pkg``; a package that loads lazily imports what its
    ``__init__.pyi`` declares)."""
    modules = {".".join(p.relative_to(package.parent).with_suffix("").parts)
               .removesuffix(".__init__"): p for p in package.rglob("*.py")}

    def known(name: str) -> str:
        while name not in modules:
            name = name.rpartition(".")[0]
        return name

    graph: dict[str, set[str]] = {m: set() for m in modules}
    for module, path in modules.items():
        stub = path.with_suffix(".pyi")  # a lazily loading package's names (lazy_loader)
        text = path.read_text() + (stub.read_text() if stub.is_file() else "")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 1:
                names = [f"{module}.{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            else:
                continue
            graph[module] |= {known(n) for n in names if n.split(".")[0] == package.name}
        graph[module].discard(module)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of more than one module (each an import cycle)."""
    names = sorted(graph)
    index = {n: i for i, n in enumerate(names)}
    rows = [index[a] for a in names for _ in graph[a]]
    cols = [index[b] for a in names for b in sorted(graph[a])]
    matrix = csr_array((np.ones(len(rows)), (rows, cols)), shape=(len(names), len(names)))
    _, labels = connected_components(matrix, connection="strong")
    groups = [[n for n in names if labels[index[n]] == label] for label in set(labels)]
    return sorted(g for g in groups if len(g) > 1)
