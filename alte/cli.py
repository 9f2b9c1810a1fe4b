"""Command-line entry point: ``alte COMMAND ...`` (:data:`DESCRIPTION` is what it says).

Each command lives in its own module under ``alte.commands`` exposing
``add_parser(subparsers)`` and ``run(args) -> int``; :data:`COMMANDS` lists them
explicitly. ``sys.exit`` happens only here: errors become one line on stderr.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from alte import __version__
from alte.errors import AlteError

__all__ = ["COMMANDS", "DESCRIPTION", "build_parser", "main"]

#: What ``alte --help`` says first: plain text, as a terminal shows it.
DESCRIPTION = ("alte: UAV terrain mapping from LiDAR. Map a ROS bag, a point file or a "
               "terrain tile with Quadtree, Octomap, 2D-ALTE or 3D-ALTE; run the thesis' "
               "experiments into a report. 'alte COMMAND --help' explains each command.")

#: Command name -> module implementing it.
COMMANDS: dict[str, str] = {
    "map": "alte.commands.map",
    "info": "alte.commands.info",
    "export": "alte.commands.export",
    "odometry": "alte.commands.odometry",
    "report": "alte.commands.report",
    "register": "alte.commands.register",
    "simulate": "alte.commands.simulate",
    "bench": "alte.commands.bench",
    "sweep": "alte.commands.sweep",
    "warmup": "alte.commands.warmup",
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every registered command."""
    parser = argparse.ArgumentParser(prog="alte", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"alte {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in COMMANDS.items():
        cmd = importlib.import_module(module)
        cmd.add_parser(sub)
        if name not in sub.choices:
            raise RuntimeError(f"{module}.add_parser did not register {name!r}")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the process exit code."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except AlteError as err:
        print(f"alte {args.command}: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"alte {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
