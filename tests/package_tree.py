"""The installed package's tree, assembled from the repository as the wheel would (pyproject's package-dir).

The folders users know (cad/, exports/, ...) sit at the top of the repository and install as swiftfin.cad,
swiftfin.exports, ...; tools that read a package from its directory (import-linter, grimp) need the installed
shape, which this copies (Python sources only) into a temporary folder.
"""
from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def package_dirs() -> dict[str, Path]:
    """Installed package name -> repository folder, from pyproject.toml."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    mapping = cfg.get("package-dir", {})
    out = {}
    for pkg in cfg["packages"]:
        if pkg in mapping:
            out[pkg] = ROOT / mapping[pkg]
        else:   # a sub-package inside its parent's folder
            parent, _, leaf = pkg.rpartition(".")
            out[pkg] = out[parent] / leaf
    return out


def assemble(dest: Path) -> Path:
    """Copy every package's .py (and .toml data) files to ``dest/<dotted path>``; returns ``dest`` (put it first on sys.path)."""
    for pkg, src in package_dirs().items():
        target = dest.joinpath(*pkg.split("."))
        target.mkdir(parents=True, exist_ok=True)
        for f in [*src.glob("*.py"), *src.glob("*.toml")]:   # sources and the data tables they read
            shutil.copy2(f, target / f.name)
    return dest
