"""``swiftfin params``: validate a parameter file, or print the documented default file."""
from __future__ import annotations

import sys

from swiftfin.config import DEFAULT_DESIGN, load_design
from swiftfin.params import dump_toml


def register(sub) -> None:
    ap = sub.add_parser("params", help="validate a parameter file or print the documented defaults")
    ap.add_argument("params_file", nargs="?", default=DEFAULT_DESIGN, help="parameter file (default: swiftfin.toml)")
    ap.add_argument("--dump", action="store_true", help="print the default design (the paper's SwiftFin) as TOML")
    ap.set_defaults(func=run)


def run(args) -> int:
    if args.dump:
        sys.stdout.write(dump_toml())
        return 0
    load_design(args.params_file)
    print(f"{args.params_file}: valid")
    return 0
