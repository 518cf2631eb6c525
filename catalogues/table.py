"""What the catalogue tables share: finding an entry by name and telling a positive number from anything else."""
from __future__ import annotations

from collections.abc import Iterable
from typing import Any, TypeVar

T = TypeVar("T")


def by_name(entries: Iterable[T], name: str, what: str, file: str) -> T:
    """The entry called ``name``; KeyError naming the file and every name it holds otherwise."""
    entries = tuple(entries)
    for e in entries:
        if e.name == name:
            return e
    raise KeyError(f"no {what} {name!r} in catalogues/{file} (it holds {', '.join(e.name for e in entries)})")


def is_positive_number(v: Any) -> bool:
    """An int or float above zero (a TOML boolean is not a number here)."""
    return not isinstance(v, bool) and isinstance(v, (int, float)) and v > 0
