"""``swiftfin params``: validate a parameter file, or print the documented default file."""
from __future__ import annotations

import sys

from swiftfin.layout.design import load_design
from swiftfin.core.params import dump_toml
from swiftfin.commands import DESIGN_HELP


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    ap.add_argument("params_file", nargs="?", default=None, help=DESIGN_HELP)
    ap.add_argument("--dump", action="store_true", help="print the default design (the paper's SwiftFin) as TOML")
    ap.set_defaults(func=run)


def run(args) -> int:
    if args.dump:
        sys.stdout.write(dump_toml())
        return 0
    load_design(args.params_file)
    print(f"{args.params_file}: valid")
    return 0
