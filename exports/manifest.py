"""``manifest.json``: every file of a build with its SHA-256, the parameter file's SHA-256 and the tool version.

The manifest holds nothing that changes from run to run (no dates, no timings), so the same parameter file
gives the same manifest entries; STEP files carry a fixed header date (exports/files.py) for the same reason.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from swiftfin import __version__

MANIFEST_NAME = "manifest.json"


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def make_manifest(files: list[dict], parts: list[dict], params_file: Path, params_sha256: str | None = None) -> dict:
    """``files``: dicts with path (relative, '/'-separated), sha256 and bytes; ``parts``: one dict per part;
    ``params_sha256``: the hash of the bytes the build parsed (read again from ``params_file`` when None)."""
    return {
        "tool": "swiftfin",
        "version": __version__,
        "params_file": Path(params_file).name,
        "params_sha256": params_sha256 or sha256_bytes(Path(params_file).read_bytes()),
        "units": "mm",
        "files": sorted(files, key=lambda f: f["path"]),
        "parts": parts,
    }


def manifest_text(manifest: dict) -> str:
    return json.dumps(manifest, indent=1, sort_keys=True) + "\n"


def verify_manifest(folder: str | Path) -> list[str]:
    """Problems found comparing a build folder with its manifest (empty when every hash matches and no file
    is missing or unlisted)."""
    folder = Path(folder)
    manifest = json.loads((folder / MANIFEST_NAME).read_text())
    problems = []
    listed = set()
    for f in manifest["files"]:
        listed.add(f["path"])
        path = folder / f["path"]
        if not path.is_file():
            problems.append(f"{f['path']}: listed but missing")
            continue
        data = path.read_bytes()
        if sha256_bytes(data) != f["sha256"] or len(data) != f["bytes"]:
            problems.append(f"{f['path']}: SHA-256 or size differs from the manifest")
    on_disk = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
    for extra in sorted(on_disk - listed - {MANIFEST_NAME}):
        problems.append(f"{extra}: on disk but not in the manifest")
    return problems
