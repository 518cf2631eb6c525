"""The registry of calibration families: look a family up by name (``swiftfin fit NAME``).

The names and their modules are in :data:`swiftfin.calibration.FAMILY_MODULES`; a family's module is imported
on first use, so a family whose dependencies are missing does not break the others.
"""
from __future__ import annotations

import importlib

from swiftfin.calibration import FAMILY_MODULES
from swiftfin.calibration.model import Family


def get_family(name: str) -> Family:
    """The registered family ``name``. Raises KeyError naming the known families."""
    if name not in FAMILY_MODULES:
        raise KeyError(f"unknown family {name!r}; known: {', '.join(sorted(FAMILY_MODULES))}")
    return importlib.import_module(FAMILY_MODULES[name]).FAMILY


def available_families() -> list[str]:
    """Families whose module can be imported here."""
    out = []
    for name, mod in FAMILY_MODULES.items():
        try:
            importlib.import_module(mod)
        except ModuleNotFoundError as exc:
            if exc.name == mod:
                continue
            raise
        out.append(name)
    return out


__all__ = ["FAMILY_MODULES", "get_family", "available_families"]
