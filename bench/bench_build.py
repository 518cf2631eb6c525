"""Cold build of a design vs a rebuild after one parameter changes (default: caudal_fin.span_mm + 10 mm).

Both builds run in this process, one after the other, into a fresh cache, so the ratio is measured on the
same machine under the same load (house style rule 14). Target: rebuild / cold <= 0.20.

    .venv/bin/python bench/bench_build.py [PARAMS] [--key caudal_fin.span_mm] [--delta 10]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import tomli_w

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from swiftfin.cache import FamilyCache  # noqa: E402
from swiftfin.layout.design import load_design  # noqa: E402
from swiftfin.core.errors import BuildError  # noqa: E402
from swiftfin.core.params import get_key, replace_key, to_dict  # noqa: E402
from swiftfin.pipeline import build  # noqa: E402

TARGET_RATIO = 0.20


def timed_build(params_file: Path, out: Path, cache: FamilyCache) -> tuple[float, str, str]:
    """Seconds, "n parts, m rebuilt", and a note if a check stopped the build (the time is still the
    build's up to and including the checks; only writing the files is then missing)."""
    lines: list[str] = []
    t0 = time.perf_counter()
    try:
        build(params_file, out, cache=cache, progress=lines.append)
        note = ""
    except BuildError as exc:
        note = f"stopped by a failed check ({str(exc).splitlines()[0]})"
    dt = time.perf_counter() - t0
    part_lines = [ln for ln in lines if " link " in ln]
    rebuilt = [ln.split()[1] for ln in part_lines if "(cached)" not in ln]
    which = "all" if len(rebuilt) == len(part_lines) else (", ".join(rebuilt) or "none")
    return dt, f"{len(part_lines)} parts, {len(rebuilt)} rebuilt: {which}", note


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("params_file", nargs="?", default=str(ROOT / "swiftfin.toml"))
    ap.add_argument("--key", default="caudal_fin.span_mm", help="the parameter changed for the rebuild")
    ap.add_argument("--delta", type=float, default=10.0, help="added to that parameter")
    args = ap.parse_args(argv)

    p = load_design(args.params_file)
    with tempfile.TemporaryDirectory(prefix="swiftfin-bench-") as tmp:
        tmp = Path(tmp)
        cache = FamilyCache(tmp / "cache")
        changed = replace_key(p, args.key, get_key(p, args.key) + args.delta)
        changed_file = tmp / "changed.toml"
        changed_file.write_text(tomli_w.dumps(to_dict(changed)))
        load_design(changed_file)  # the changed design must itself be valid

        t_cold, r_cold, note_cold = timed_build(Path(args.params_file), tmp / "cold", cache)
        t_re, r_re, note_re = timed_build(changed_file, tmp / "rebuild", cache)

    ratio = t_re / t_cold
    print(f"design: {args.params_file}")
    print(f"cold build:            {t_cold:8.2f} s  ({r_cold}) {note_cold}")
    print(f"rebuild ({args.key} {'+' if args.delta >= 0 else ''}{args.delta:g}): {t_re:8.2f} s  ({r_re}) {note_re}")
    print(f"ratio rebuild / cold:  {ratio:8.3f}  (target <= {TARGET_RATIO:.2f}: {'met' if ratio <= TARGET_RATIO else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
