"""The ``swiftfin`` command. Each sub-command lives in ``swiftfin/commands/<name>.py`` and exposes
``register(subparsers)`` (adds its parser, sets ``func``) and a ``run(args) -> int``.

Bad input (ParamError, UserError) prints one clear message on stderr and exits 2; a failed build check
(BuildError) exits 1. Tracebacks are for bugs only.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from swiftfin import __version__
from swiftfin.errors import BuildError, UserError
from swiftfin.params import ParamError

COMMANDS = ("build", "check", "audit", "fit", "synth", "report", "params")


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="swiftfin", description=__doc__.split("\n")[0])
    parser.add_argument("--version", action="version", version=f"swiftfin {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"swiftfin.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"swiftfin.commands.{name}":
                continue  # command not part of this installation
            raise
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = make_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except ParamError as exc:
        print(f"swiftfin {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except UserError as exc:
        print(f"swiftfin {args.command}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except BuildError as exc:
        print(f"swiftfin {args.command}: build check failed: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"swiftfin {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` etc.: stop quietly, like other Unix tools
        import os
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
