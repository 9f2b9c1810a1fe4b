"""Mutation score per module from mutmut's results in ``mutants/`` (``make mutants``).

A mutant counts as *killed* when a test failed or it timed out (a mutant that makes the
code loop is caught); *survived* when every covering test passed; *no tests* when no
selected test calls the mutated function; *not checked* when the run has not reached
it. The score is killed / (killed + survived + no tests) over the checked mutants; the
mutants listed in ``mutation_equivalent.txt`` beside this file (equivalent to the
original: no test can tell them apart) are left out of it. Run from the repository:
``.venv/bin/python tests/mutation_score.py [--survivors | --diff]`` (``--diff``: each
surviving mutant's changed lines).
"""

from __future__ import annotations

import ast
import difflib
import json
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_STATUS = {1: "killed", 3: "killed", 0: "survived", 5: "no tests", 33: "no tests",
           24: "killed", -24: "killed", 36: "killed", 152: "killed", 255: "killed",
           None: "not checked"}
_COLUMNS = ("killed", "survived", "no tests", "not checked")


def equivalent() -> set[str]:
    """Mutant names declared equivalent (first word of each non-comment line)."""
    path = Path(__file__).with_name("mutation_equivalent.txt")
    if not path.exists():
        return set()
    lines = (line.split("#")[0].split() for line in path.read_text().splitlines())
    return {words[0] for words in lines if words}


def results(root: Path = ROOT) -> dict[str, dict[str, str]]:
    """Module -> mutant name -> status, from every ``*.py.meta`` under ``mutants/``."""
    out: dict[str, dict[str, str]] = {}
    for meta in sorted((root / "mutants").rglob("*.py.meta")):
        codes = json.loads(meta.read_text())["exit_code_by_key"]
        if codes:
            # mutants/<name>/mutants/alte/x.py.meta (tests/mutation_run.py) -> alte/x.py
            module = str(meta.relative_to(root / "mutants")).removesuffix(".meta")
            module = module.split("/mutants/")[-1]
            out[module] = {k: _STATUS.get(v, "survived") for k, v in codes.items()}
    return out


def table(found: dict[str, dict[str, str]], skip: set[str]) -> list[str]:
    """One line per module: counts per status and the score."""
    lines = [f"{'module':36} {'mutants':>7} " + " ".join(f"{c:>11}" for c in _COLUMNS)
             + f" {'equivalent':>10} {'score':>7}"]
    for module, names in found.items():
        counts = Counter(s for n, s in names.items() if n not in skip)
        same = sum(n in skip for n in names)
        checked = counts["killed"] + counts["survived"] + counts["no tests"]
        score = f"{100 * counts['killed'] / checked:6.1f}%" if checked else "    n/a"
        lines.append(f"{module:36} {len(names):7d} " + " ".join(f"{counts[c]:11d}"
                                                                for c in _COLUMNS)
                     + f" {same:10d} {score:>7}")
    return lines


def _functions(mutated: Path) -> dict[str, str]:
    """Every function of a mutated module (mutmut's copy), by name, as source."""
    tree = ast.parse(mutated.read_text())
    out = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            name, node.name = node.name, "f"   # the same first line for every variant
            out[name] = ast.unparse(node)
    return out


def diffs(root: Path = ROOT) -> dict[str, str]:
    """Mutant name -> the changed lines against the original function (what survived)."""
    out: dict[str, str] = {}
    for meta in sorted((root / "mutants").rglob("*.py.meta")):
        found = _functions(meta.with_suffix(""))
        for name in json.loads(meta.read_text())["exit_code_by_key"]:
            short = name.rsplit(".", 1)[-1]
            original = found.get(short.rsplit("__mutmut_", 1)[0] + "__mutmut_orig", "")
            lines = difflib.unified_diff(original.splitlines(),
                                         found.get(short, "").splitlines(), n=0,
                                         lineterm="")
            out[name] = "\n".join(f"    {line}" for line in lines
                                  if line[:1] in "+-" and line[:3] not in ("+++", "---"))
    return out


def main(argv: list[str]) -> int:
    found = results()
    if not found:
        print("no mutmut results under mutants/: run `make mutants` first", file=sys.stderr)
        return 1
    skip = equivalent()
    print("\n".join(table(found, skip)))
    if "--survivors" in argv or "--diff" in argv:
        changes = diffs() if "--diff" in argv else {}
        for names in found.values():
            for n, status in names.items():
                if status == "survived" and n not in skip:
                    print(f"  survived: {n}" + (f"\n{changes[n]}" if n in changes else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
