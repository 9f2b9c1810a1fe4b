"""Sphinx extension of alte's documentation: pages and tables generated from the code.

- **API pages** (``reference/api/``): one page per package of ``alte``, with every public
  module below it (a module whose name does not start with ``_``), written when the build
  starts from what :func:`public_modules` finds. A new module appears without anyone
  editing the docs; the tests check that every one of them reached the built site.
- ``{alte-record} dotted.path.Record``: the settings of a :class:`alte.params.Record` as a
  table (name, type, default, rule, meaning), read from its fields.
- ``{alte-mappers}``: the settings of every mapper of the registry
  (:func:`alte.mappers.registry.classes`: the thesis' four and the installed plugins),
  one table each.
- **Short type names** in signatures (``tiles: list[Tile]``) that two modules define
  (``alte.io.points.tiles.Tile``, ``alte.sim.real.tiles.Tile``) link to the one nearest the
  signature's module (:class:`NearestTarget`), where Sphinx would warn and pick any.

The pages are written only when their text changes, through a temporary file and a
rename, so two builds of the same tree at once (``make docs`` beside ``make test``) never
read a half-written page.
"""

from __future__ import annotations

import ast
import dataclasses
import enum
import functools
import importlib
import importlib.util
import os
import pkgutil
import sys
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, ClassVar

from docutils import nodes
from docutils.statemachine import StringList
from sphinx import addnodes
from sphinx.application import Sphinx
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.util.docutils import SphinxDirective

REPO = Path(__file__).resolve().parents[2]
API_DIR = REPO / "docs" / "reference" / "api"


def public_modules(package: str = "alte") -> list[str]:
    """Every importable public module and package of ``package``, sorted."""
    root = importlib.import_module(package)
    found = [package]
    for info in pkgutil.walk_packages(root.__path__, prefix=f"{package}."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            found.append(info.name)
    return sorted(found)


def _packages(modules: list[str]) -> dict[str, list[str]]:
    """Each package with the plain modules directly below it (a package is its own page)."""
    packages = [m for m in modules if _is_package(m)]
    pages: dict[str, list[str]] = {p: [] for p in packages}
    for module in modules:
        if module in pages:
            continue
        parent = module.rsplit(".", 1)[0]
        pages[parent].append(module)
    return pages


def _is_package(name: str) -> bool:
    spec = importlib.util.find_spec(name)
    return bool(spec and spec.submodule_search_locations is not None)


def _write_if_changed(path: Path, text: str) -> None:
    if path.is_file() and path.read_text() == text:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as out:
        out.write(text)
    os.replace(tmp, path)


def owned_names(module: str) -> list[str]:
    """The public names ``module`` defines itself (not imports), in ``__all__`` order.

    Read from the module's source (top-level ``def``, ``class`` and assignments), so a
    name a package or module re-exports is documented once, where it is defined.
    """
    bound = _bound_names(module)
    listed = getattr(importlib.import_module(module), "__all__", None)
    names = list(listed) if listed is not None else sorted(bound)
    return [n for n in names if n in bound and not n.startswith("_")]


@functools.cache
def _bound_names(module: str) -> frozenset[str]:
    """The names the top level of ``module``'s source binds. Parsed once per module and
    build: the API pages ask again for each name a package re-exports (about 900 times)."""
    spec = importlib.util.find_spec(module)
    origin = Path(spec.origin) if spec and spec.origin else None
    tree = ast.parse(origin.read_text()) if origin and origin.suffix == ".py" else ast.Module()
    bound: set[str] = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            bound.add(node.name)
        elif isinstance(node, ast.Assign):
            bound |= {t.id for t in node.targets if isinstance(t, ast.Name)}
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            bound.add(node.target.id)
    return frozenset(bound)


def _owner(module: str, name: str, modules: list[str]) -> str | None:
    """The module below ``module`` that defines ``name`` (``None``: none does)."""
    obj = getattr(importlib.import_module(module), name, None)
    home = getattr(obj, "__module__", None)
    if isinstance(home, str) and home in modules and name in owned_names(home):
        return home
    for candidate in modules:
        if candidate.startswith(module + ".") and name in owned_names(candidate):
            return candidate
    return None


def _automodule(module: str) -> list[str]:
    names = owned_names(module)
    lines = [f".. automodule:: {module}"]
    if names:
        lines += [f"   :members: {', '.join(names)}", "   :show-inheritance:"]
    return [*lines, ""]


def _reexports(package: str, modules: list[str]) -> list[str]:
    """A line per defining module: the names ``package`` re-exports from it, linked."""
    own = set(owned_names(package))
    by_owner: dict[str, list[str]] = {}
    for name in getattr(importlib.import_module(package), "__all__", []):
        if name in own or name.startswith("_"):
            continue
        home = _owner(package, name, modules)
        if home is not None:
            by_owner.setdefault(home, []).append(name)
    if not by_owner:
        return []
    lines = ["Public names of the package, documented where they are defined:", ""]
    for home, names in by_owner.items():
        refs = ", ".join(f":py:obj:`~{home}.{n}`" for n in names)
        lines += [f"- from :py:mod:`{home}`: {refs}"]
    return [*lines, ""]


def _api_page(package: str, modules: list[str], everything: list[str]) -> str:
    lines = [f"# `{package}`", "", "```{eval-rst}", *_automodule(package),
             *_reexports(package, everything)]
    for module in modules:
        lines += _automodule(module)
    lines += ["```", ""]
    return "\n".join(lines)


def write_api_pages(_app: Sphinx) -> None:
    """The API reference: an index and one page per package (module docstring)."""
    if str(REPO) not in sys.path:
        sys.path.insert(0, str(REPO))  # bench/ sits beside alte/, not installed
    _bound_names.cache_clear()  # read afresh in each build of a long-lived process
    everything = public_modules() + public_modules("bench")
    pages = _packages(everything)
    wanted = {f"{package}.md" for package in pages} | {"index.md"}
    for package, modules in pages.items():
        _write_if_changed(API_DIR / f"{package}.md", _api_page(package, modules, everything))
    toc = "\n".join(sorted(pages))
    index = ("# Python API\n\nGenerated from the docstrings: one page per package of `alte` "
             "and of the benchmark (`bench/`, beside the package), with every public module "
             "inside it. The library's wing (`io`, `registration`, `ground`, `mappers`, "
             "`metrics`, `pipeline`, `sim`, `export`) never imports the lab (`alte.lab`: "
             "`studies`, `plot`, `report`); the command line sits on both.\n\n"
             f"```{{toctree}}\n:maxdepth: 1\n\n{toc}\n```\n")
    _write_if_changed(API_DIR / "index.md", index)
    for stale in API_DIR.glob("*.md"):
        if stale.name not in wanted:
            stale.unlink(missing_ok=True)


def _type_name(kind: object) -> str:
    if isinstance(kind, type):
        return kind.__name__
    text = str(kind).replace("typing.", "")
    for module in ("alte.types.", "alte.pipeline.spec.", "alte.mappers.", "pathlib.",
                   "alte.registration.settings."):
        text = text.replace(module, "")
    return text


def _default(spec: dataclasses.Field[Any]) -> str:
    if spec.default is not dataclasses.MISSING:
        value = spec.default
    elif spec.default_factory is not dataclasses.MISSING:
        value = spec.default_factory()
    else:
        return "(required)"
    if isinstance(value, enum.Enum):
        value = value.value
    if dataclasses.is_dataclass(value):
        return f"{type(value).__name__}()"
    return repr(value) if isinstance(value, str) else str(value)


def record_rows(record: type[Any]) -> list[tuple[str, str, str, str, str]]:
    """(name, type, default, rule, meaning) of each field a user sets."""
    from alte.params import Rule, _choices, _hints

    hints = _hints(record)
    rows = []
    for spec in dataclasses.fields(record):
        if not spec.init:
            continue
        rule = spec.metadata.get("rule")
        rule = rule if isinstance(rule, Rule) else Rule()
        kind = hints[spec.name]
        rows.append((spec.name, _type_name(kind), _default(spec),
                     rule.rule or _choices(kind), rule.help))
    return rows


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ") or "-"


def record_table(record: type[Any]) -> list[str]:
    """An RST list-table of the record's settings."""
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 15 15 12 18 40", "",
             "   * - setting", "     - type", "     - default", "     - rule", "     - meaning"]
    for row in record_rows(record):
        first, *rest = (f"``{row[0]}``", *(_literal(v) for v in row[1:3]), *row[3:])
        lines.append(f"   * - {first}")
        lines += [f"     - {_escape(v)}" if not v.startswith("``") else f"     - {v}"
                  for v in rest]
    return lines


def _literal(text: str) -> str:
    return f"``{text}``" if text and text != "-" else "-"


def _escape(text: str) -> str:
    if not text:
        return "-"
    for char in ("\\", "*", "`", "|", "_"):
        text = text.replace(char, "\\" + char)
    return text


class RecordDirective(SphinxDirective):
    """``{alte-record} module.Class``: a settings table (module docstring)."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        module, _, name = self.arguments[0].rpartition(".")
        record = getattr(importlib.import_module(module), name)
        return self._parse(record_table(record))

    def _parse(self, lines: list[str]) -> list[nodes.Node]:
        """The reST ``lines`` as nodes. In a MyST page a nested parse reads Markdown, so
        the lines go through MyST's ``eval-rst`` block there (reST pages parse them as is)."""
        if "myst" in type(self.state).__module__.lower():
            lines = ["````{eval-rst}", *lines, "````"]
        node = nodes.section()
        node.document = self.state.document
        self.state.nested_parse(StringList(lines, source="alte-record"), 0, node)
        return list(node.children)


class MappersDirective(RecordDirective):
    """``{alte-mappers}``: every registered mapper's settings, one table each."""

    required_arguments = 0

    def run(self) -> list[nodes.Node]:
        from alte.mappers import registry

        lines: list[str] = []
        for cls in registry.classes():
            said = (cls.__doc__ or "").strip().splitlines()[0]
            lines += [f"**{cls.name}** (:class:`{cls.__module__}.{cls.__name__}`): {said}",
                      "", *record_table(cls.Settings), ""]
        return self._parse(lines)


class CsvDirective(RecordDirective):
    """``{alte-csv} path.csv`` (from the repository root) with ``:columns: a, b`` and an
    optional ``:where: column=value``: a committed table, as a list-table, with the row
    count and the file named under it, so a page quotes the numbers from their file."""

    option_spec: ClassVar[dict[str, Callable[[str], object]]] = {
        "columns": lambda text: [c.strip() for c in text.split(",")],
        "where": str, "caption": str}

    def run(self) -> list[nodes.Node]:
        import csv

        path = REPO / self.arguments[0]
        self.env.note_dependency(str(path))
        with path.open(newline="") as handle:
            rows = list(csv.DictReader(handle))
        if "where" in self.options:
            key, _, value = self.options["where"].partition("=")
            rows = [r for r in rows if r.get(key.strip()) == value.strip()]
        columns = self.options.get("columns") or (list(rows[0]) if rows else [])
        missing = [c for c in columns if rows and c not in rows[0]]
        if missing:
            raise self.error(f"{path.name} has no column(s) {missing}")
        lines = [".. list-table:: " + self.options.get("caption", ""), "   :header-rows: 1", "",
                 "   * - " + columns[0], *(f"     - {c}" for c in columns[1:])]
        for row in rows:
            cells = [_escape(row[c]) for c in columns]
            lines += [f"   * - {cells[0]}", *(f"     - {c}" for c in cells[1:])]
        lines += ["", f"{len(rows)} rows, read from ``{self.arguments[0]}``."]
        return self._parse(lines)


class ProvenanceDirective(RecordDirective):
    """``{alte-provenance} path.json``: the command, commit, dates and cost a committed
    result was written with (a sweep's or a study's ``provenance.json``), and its note."""

    def run(self) -> list[nodes.Node]:
        import json

        path = REPO / self.arguments[0]
        self.env.note_dependency(str(path))
        said = json.loads(path.read_text())
        machine = said.get("machine", {})
        count = said.get("runs", said.get("rows"))
        items = [("command", f"``{said.get('command', '-')}``"),
                 ("commit", f"``{str(said.get('commit', '-'))[:10]}``"),
                 ("started", said.get("started", "-")), ("finished", said.get("finished", "-")),
                 ("runs" if "runs" in said else "rows",
                  f"{count:,}" if isinstance(count, int) else "-"),
                 ("CPU", _cpu(said.get("cpu_s"))),
                 ("machine", f"{machine.get('cpu', machine.get('platform', '-'))}, "
                             f"{machine.get('cores', machine.get('cpus', '-'))} cores"),
                 ("file", f"``{self.arguments[0]}``")]
        if said.get("note"):
            items.append(("note", _escape(str(said["note"])).replace("--", "\\-\\-")))
        lines = [".. list-table::", "   :stub-columns: 1", ""]
        for key, value in items:
            shown = "(not recorded)" if value in ("-", "") else value
            lines += [f"   * - {key}", f"     - {shown}"]
        return self._parse(lines)


def _cpu(seconds: object) -> str:
    """CPU seconds as hours or minutes ("-" when not recorded)."""
    if not isinstance(seconds, int | float):
        return "-"
    return f"{seconds / 3600:.2f} h" if seconds >= 3600 else f"{seconds / 60:.1f} min"


def _shared_prefix(name: str, module: str) -> int:
    """How many leading dotted parts ``name`` shares with ``module``."""
    count = 0
    for mine, theirs in zip(name.split("."), module.split("."), strict=False):
        if mine != theirs:
            break
        count += 1
    return count


def _suffixes(names: Iterable[str]) -> set[str]:
    """Every dotted tail of every name (``a.b.c``: ``c``, ``b.c``, ``a.b.c``)."""
    tails = set()
    for name in names:
        parts = name.split(".")
        tails.update(".".join(parts[i:]) for i in range(len(parts)))
    return tails


class NearestTarget(SphinxPostTransform):
    """A short Python name a signature refers to (``Tile``) that several documented
    objects end with: the one whose module is nearest the signature's own (the longest
    shared dotted prefix), set before Sphinx resolves it (it would warn and pick any).

    A target no documented object ends with (``ndarray``, ``Path``, ``float``) resolves
    to nothing whichever way Sphinx searches, so it is searched exactly: Sphinx marks
    every annotation's reference "specific", and its search for one scans every object
    of the site (once per reference and type, thousands of times a build)."""

    default_priority = 5  # before sphinx's ReferencesResolver (10)
    _cached: ClassVar[tuple[object, int, dict[str, list[str]], set[str]] | None] = None

    @classmethod
    def _indexes(cls, objects: dict[str, Any]) -> tuple[dict[str, list[str]], set[str]]:
        """The documented objects by last name, and every dotted tail of theirs: built
        once per build (the objects do not change while pages are written), not per page."""
        cached = cls._cached
        if cached is not None and cached[0] is objects and cached[1] == len(objects):
            return cached[2], cached[3]
        by_last: dict[str, list[str]] = {}
        for name in objects:
            by_last.setdefault(name.rpartition(".")[2], []).append(name)
        tails = _suffixes(objects)
        cls._cached = (objects, len(objects), by_last, tails)
        return by_last, tails

    def run(self, **_kwargs: object) -> None:
        """Qualify each ambiguous short target of this document."""
        objects = self.env.get_domain("py").objects
        by_last, tails = self._indexes(objects)
        for node in self.document.findall(addnodes.pending_xref):
            target = str(node.get("reftarget", ""))
            if node.get("refdomain") != "py":
                continue
            if target not in tails and node.hasattr("refspecific"):
                del node["refspecific"]  # nothing to find: the exact search, same result
                continue
            module = str(node.get("py:module") or "")
            if "." in target or target in objects or f"{module}.{target}" in objects:
                continue
            found = by_last.get(target, [])
            if len(found) > 1:
                node["reftarget"] = max(found, key=lambda name: _shared_prefix(name, module))


def setup(app: Sphinx) -> dict[str, object]:
    """Register the page generator, the directives and the reference transform."""
    app.connect("builder-inited", write_api_pages)
    app.add_post_transform(NearestTarget)
    app.add_directive("alte-record", RecordDirective)
    app.add_directive("alte-mappers", MappersDirective)
    app.add_directive("alte-csv", CsvDirective)
    app.add_directive("alte-provenance", ProvenanceDirective)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


__all__ = ["NearestTarget", "owned_names", "public_modules", "record_rows", "record_table", "setup",
           "write_api_pages"]
