"""Command-line entry point: ``alte COMMAND ...`` (:data:`DESCRIPTION` is what it says).

Each command lives in its own module under ``alte.commands`` exposing
``add_parser(subparsers)`` and ``run(args) -> int``; :data:`COMMANDS` lists them
explicitly, with the one-line help ``alte --help`` shows (the same as the module's, a
test checks). Only the module of the command given is imported, and a module imports
its heavy parts (mappers, studies, report, open3d, dask, pyvista) when it runs, so
``alte --help``, ``alte --version`` and ``alte info`` answer at once (like kiss-icp's
CLI, which imports its pipeline only when it runs). ``sys.exit`` happens only here:
errors become one line on stderr.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from alte import __version__
from alte.errors import AlteError

__all__ = ["COMMANDS", "DESCRIPTION", "build_parser", "full_parser", "main"]

#: What ``alte --help`` says first: plain text, as a terminal shows it.
DESCRIPTION = ("alte: UAV terrain mapping from LiDAR. Map a ROS bag, a point file or a "
               "terrain tile with Quadtree, Octomap, 2D-ALTE or 3D-ALTE; run the thesis' "
               "experiments into a report. 'alte COMMAND --help' explains each command.")

#: Command name -> (module implementing it, its one-line help).
COMMANDS: dict[str, tuple[str, str]] = {
    "map": ("alte.commands.map",
            "build a terrain map from a bag, a terrain folder or a point cloud file"),
    "info": ("alte.commands.info",
             "show a bag's topics (or a point file's contents) and what alte detects"),
    "export": ("alte.commands.export",
               "map an input and write the result as a ROS 2 MCAP (Foxglove, RViz)"),
    "ground": ("alte.commands.ground",
               "classify a terrain tile's ground points (ASPRS class 2) into LAS/LAZ"),
    "odometry": ("alte.commands.odometry",
                 "score recorded, odometry and refined poses against reference poses"),
    "report": ("alte.commands.report", "execute the notebooks and build reports/index.html"),
    "register": ("alte.commands.register",
                 "register a bag's scans into one inertial point cloud"),
    "simulate": ("alte.commands.simulate",
                 "simulate the benchmark terrains, or import real terrain tiles and fly "
                 "them, as ROS 2 bags with ground truth"),
    "bench": ("alte.commands.bench", "run the performance benchmark"),
    "sweep": ("alte.commands.sweep",
              "run a grid of terrains x mappers x parameters (resumable, Dask)"),
    "warmup": ("alte.commands.warmup",
               "compile the mappers' kernels into the package cache (once per install)"),
}


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser: ``command``'s own (its module imported), every other command
    by name and help only. ``None``: none imported (``alte --help``); ``"*"``: all."""
    parser = argparse.ArgumentParser(prog="alte", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"alte {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, (module, summary) in COMMANDS.items():
        if command not in (name, "*"):
            sub.add_parser(name, help=summary)
            continue
        importlib.import_module(module).add_parser(sub)
        if name not in sub.choices:
            raise RuntimeError(f"{module}.add_parser did not register {name!r}")
    return parser


def _command(argv: Sequence[str]) -> str | None:
    """The command named on the line (the first word that is not an option), if any."""
    return next((word for word in argv if not word.startswith("-")), None)


def full_parser() -> argparse.ArgumentParser:
    """The parser with every command's own options (each command module imported): what
    the documentation's command-line reference and the help tests read."""
    return build_parser("*")


def _options(parser: argparse.ArgumentParser, args: argparse.Namespace) -> set[str]:
    """The option strings of the command that ran (its flags, for error messages)."""
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    command = actions[0].choices[args.command] if actions else parser
    return set(command._option_string_actions)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the process exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(_command(argv))
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except AlteError as err:
        from alte.commands.flags import flag_message

        print(f"alte {args.command}: error: {flag_message(err, _options(parser, args))}",
              file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"alte {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
