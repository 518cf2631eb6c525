"""The output folder of ``swiftfin build``: the tool writes and replaces only what it owns.

* ``--out DIR`` is checked before any work (:func:`check_out_dir`): a missing folder is made; an existing one
  is replaced only when it is empty or holds a previous swiftfin build and nothing else (its ``manifest.json``
  lists every file in it, each with the hash it was written with). Anything else (a file, a folder with a
  user's files, the working folder, a folder holding the parameter file, the home folder, ``/``) exits 2
  with the reason, before anything is built.
* The build is written into a temporary folder beside ``DIR`` (:func:`make_temp_dir`) that carries a marker
  naming this process; it is swapped into place at the end (:func:`swap_into_place`), after checking ``DIR``
  again (a user may have put a file in it during the build).
* A temporary folder left by a killed build is removed by the next build into the same place
  (:func:`remove_stale_temp_dirs`) only when its marker proves it is the tool's and its process is gone.

The other commands' output places are checked before their work too (:func:`check_output_dir` for
``fit --out``, :func:`check_output_file` for ``synth --out``): a fit or a simulation is not run only to fail at
the end on a path it cannot write. Each check leaves nothing behind: what it creates to probe, it removes.
"""
from __future__ import annotations

import json
import os
import shutil
import socket
import tempfile
from pathlib import Path

from swiftfin.core.errors import UserError
from swiftfin.exports.manifest import MANIFEST_NAME, verify_manifest

MARKER = ".swiftfin-temporary"        # inside a temporary folder: {"tool", "pid", "host"}
TEMP_KINDS = ("tmp", "old")           # .<name>.tmp-XXXX (the build being written), .<name>.old-XXXX (the last one)


def _is_previous_build(folder: Path) -> tuple[bool, str]:
    """Whether ``folder`` holds a swiftfin build and nothing else; otherwise the reason."""
    manifest = folder / MANIFEST_NAME
    if not manifest.is_file():
        return False, f"it holds files and no {MANIFEST_NAME} of a swiftfin build"
    try:
        data = json.loads(manifest.read_text(encoding="utf-8"))
        ok = isinstance(data, dict) and data.get("tool") == "swiftfin" and isinstance(data.get("files"), list)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        ok = False
    if not ok:
        return False, f"its {MANIFEST_NAME} is not a swiftfin build's"
    try:
        problems = verify_manifest(folder)
    except (OSError, KeyError, TypeError, ValueError) as exc:
        return False, f"its {MANIFEST_NAME} cannot be checked ({exc})"
    if problems:
        shown = "; ".join(problems[:4]) + (f"; and {len(problems) - 4} more" if len(problems) > 4 else "")
        return False, f"it holds more than (or other than) the build its {MANIFEST_NAME} lists: {shown}"
    return True, ""


def check_out_dir(out: Path, keep: tuple[Path, ...] = ()) -> None:
    """Raise UserError (exit 2) unless ``out`` may be written: missing, empty, or a previous build only.

    ``keep``: files the build reads (the parameter file): ``out`` must not contain them.
    """
    shown = str(out)
    try:
        target = out.resolve()
        cwd = Path.cwd().resolve()
        home = Path.home().resolve()
    except (OSError, RuntimeError) as exc:
        raise UserError(f"--out {shown}: cannot resolve the path ({exc})") from None
    hint = "give a folder of its own, such as build/ (swiftfin replaces its output folder whole)"
    if target == Path(target.anchor) or target == home:
        raise UserError(f"--out {shown}: refusing to replace {'the home folder' if target == home else '/'}; {hint}")
    if target == cwd or target in cwd.parents:
        raise UserError(f"--out {shown} is the working folder or holds it; {hint}")
    for f in keep:
        try:
            fr = Path(f).resolve()
        except (OSError, RuntimeError):
            continue
        if target == fr or target in fr.parents:
            raise UserError(f"--out {shown} holds {f}, which this build reads; {hint}")
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise UserError(f"--out {shown} exists and is not a folder; {hint}")
    if out.is_dir():
        try:
            empty = not any(out.iterdir())
        except OSError as exc:
            raise UserError(f"--out {shown}: cannot read the folder ({exc})") from None
        if not empty:
            ok, why = _is_previous_build(out)
            if not ok:
                raise UserError(f"--out {shown} is not replaced: {why}. Nothing was written; move those files "
                                f"or {hint}")
    # writability is proven by make_temp_dir, which makes the build's folder beside ``out`` before any work
    anc = next(a for a in (target.parent, *target.parent.parents) if a.exists())
    if not anc.is_dir():
        raise UserError(f"--out {shown}: {anc} is not a folder")


def _marker(pid: int | None = None) -> str:
    return json.dumps({"tool": "swiftfin", "pid": pid or os.getpid(), "host": socket.gethostname()})


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _temp_dirs(out: Path) -> list[Path]:
    parent = out.parent
    if not parent.is_dir():
        return []
    return [d for kind in TEMP_KINDS for d in parent.glob(f".{out.name}.{kind}-*") if d.is_dir()]


def remove_stale_temp_dirs(out: Path) -> list[Path]:
    """Remove the temporary folders of killed builds into ``out``: only those whose marker names this tool on
    this host and a process that no longer runs. Returns the folders removed."""
    removed = []
    for d in _temp_dirs(out):
        try:
            m = json.loads((d / MARKER).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            continue        # not provably ours: leave it
        if not isinstance(m, dict) or m.get("tool") != "swiftfin" or m.get("host") != socket.gethostname():
            continue
        pid = m.get("pid")
        if not isinstance(pid, int) or _pid_alive(pid):
            continue
        shutil.rmtree(d, ignore_errors=True)
        removed.append(d)
    return removed


def make_temp_dir(out: Path, kind: str = "tmp") -> Path:
    """A marked temporary folder beside ``out`` (an ordinary folder's permissions)."""
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.{kind}-", dir=out.parent))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; the build folder is an ordinary folder
        (tmp / MARKER).write_text(_marker(), encoding="utf-8")
    except OSError as exc:
        raise UserError(f"--out {out}: cannot write beside it ({exc})") from None
    return tmp


def swap_into_place(tmp: Path, out: Path, keep: tuple[Path, ...] = ()) -> None:
    """Move the finished build ``tmp`` to ``out``, replacing a previous build there (checked again first)."""
    (tmp / MARKER).unlink(missing_ok=True)
    check_out_dir(out, keep)
    if out.is_dir():
        old = make_temp_dir(out, "old")
        os.rename(out, old / out.name)
        try:
            os.rename(tmp, out)
        except OSError:
            os.rename(old / out.name, out)  # put the old build back
            raise
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.rename(tmp, out)


# --------------------------------------------------------------------------------------------- fit, synth
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


def write_text_atomic(path, text: str, new_only: bool = False) -> None:
    """Write ``text`` to ``path`` whole or not at all: a temporary file beside it (its folders made as needed),
    renamed into place. ``new_only``: never over a file that exists (UserError, the file untouched)."""
    write_bytes_atomic(path, text.encode("utf-8"), new_only)


def write_bytes_atomic(path, data: bytes, new_only: bool = False) -> None:
    """:func:`write_text_atomic` for bytes."""
    path = Path(path)
    path.absolute().parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.absolute().parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        if new_only and path.exists():
            raise UserError(f"{path}: appeared while it was being written; not overwritten")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
