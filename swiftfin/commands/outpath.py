"""Checks of an output path made before a command does its work: a fit or a simulation is not run only to fail
at the end on a path it cannot write (an existing file where a folder is wanted, a folder where a file is wanted,
a read-only place such as /proc). Each check leaves nothing behind: what it creates to probe, it removes."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from swiftfin.core.errors import UserError


def _probe_folder(folder: Path, option: str, given: Path) -> None:
    """Create (and remove) a file in an existing ``folder``: UserError if that fails."""
    try:
        fd, name = tempfile.mkstemp(prefix=".swiftfin_probe_", dir=folder)
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise UserError(f"{option} {given}: cannot write into {folder} ({exc.strerror or exc}); "
                        f"choose a writable place") from None


def _make_and_remove(folder: Path, option: str, given: Path) -> None:
    """``folder`` does not exist: check that it can be made (its parents too), by making it and removing it."""
    anc = folder
    while not anc.exists() and anc != anc.parent:
        anc = anc.parent
    if not anc.is_dir():
        raise UserError(f"{option} {given}: {anc} is a file, so no folder can be made under it; "
                        f"choose another path")
    made = []
    try:
        p = folder
        todo = []
        while p != anc:
            todo.append(p)
            p = p.parent
        for p in reversed(todo):
            p.mkdir()
            made.append(p)
        _probe_folder(folder, option, given)
    except OSError as exc:
        raise UserError(f"{option} {given}: cannot create the folder {folder} ({exc.strerror or exc}); "
                        f"choose a writable place") from None
    finally:
        for p in reversed(made):
            try:
                p.rmdir()
            except OSError:
                pass


def check_output_dir(path, option: str = "--out") -> None:
    """``path`` is, or can become, a writable folder. An existing file there is refused (not overwritten)."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise UserError(f"{option} {p}: exists and is a file; expected a folder to write into "
                        f"(give another path, or remove the file)")
    if p.is_dir():
        _probe_folder(p, option, p)
    else:
        _make_and_remove(p.absolute(), option, p)


def check_output_file(path, option: str = "--out") -> None:
    """``path`` can be written as a file: not a folder, and its folder exists or can be made and is writable."""
    p = Path(path)
    if p.is_dir():
        raise UserError(f"{option} {p}: is a folder; expected a file name to write (e.g. {p / 'log.csv'})")
    if p.exists():
        if not os.access(p, os.W_OK):
            raise UserError(f"{option} {p}: the file exists and is read-only; choose another path")
        return
    parent = p.absolute().parent
    if parent.is_dir():
        _probe_folder(parent, option, p)
    else:
        _make_and_remove(parent, option, p)
