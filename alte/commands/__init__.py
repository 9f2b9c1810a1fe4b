"""One module per ``alte`` command: ``add_parser(subparsers)`` sets ``func=run``."""
