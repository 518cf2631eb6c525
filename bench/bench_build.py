"""The full ``swiftfin build``: cold, then after one parameter change, against the bare CAD work it contains.

All builds run in this process, one after the other, into one fresh cache, so the ratios are measured on the
same machine under the same load (house style rule 14):

* **cold**: an empty cache, the whole pipeline (families, assembly proof, assembly STEP, mass properties,
  simulator files, report);
* **bare CAD work** of the cold build (``BuildResult.cad_times_s``): the part families' OpenCascade work
  (booleans, lofts, fillets, the fasteners' cuts), their tessellation and the STEP/STL/3MF writes, and the assembly
  STEP's composition and write; not the cache's bookkeeping (hashing the source) nor the export's print checks
  (orientation, wall probe), which the families' times held until 2026-11-27;
* **rebuilds** into the same cache after one change each: nothing; ``caudal_fin.span_mm`` + 10 (the fin);
  ``hull.vent_hole_diameter_mm`` + 1 (the flooded hull pieces); ``spool.flange_thickness_mm`` + 0.2 (the spools).

Targets (issue 10): rebuild after the fin-span change <= 0.10 x cold; cold <= 2 x its bare CAD work.

    .venv/bin/python bench/bench_build.py [PARAMS]
"""
from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
from pathlib import Path

import tomli_w

from swiftfin.cache import FamilyCache
from swiftfin.core.errors import BuildError
from swiftfin.core.params import get_key, replace_key, to_dict
from swiftfin.layout.design import load_design
from swiftfin.pipeline import build

ROOT = Path(__file__).resolve().parents[1]
CHANGES = (("caudal_fin.span_mm", 10.0), ("hull.vent_hole_diameter_mm", 1.0), ("spool.flange_thickness_mm", 0.2))
TARGET_REBUILD = 0.10
PART_ROW = re.compile(r"^\s*\d+\s+\S+\s+\S+\s+link \d+\b")
TARGET_COLD = 2.0


def timed_build(params_file: Path, out: Path, cache: FamilyCache) -> tuple[float, float, str]:
    """(seconds, seconds of the families' CAD work, "n parts, m rebuilt: ...")."""
    lines: list[str] = []
    t0 = time.perf_counter()
    try:
        result = build(params_file, out, cache=cache, progress=lines.append)
        cad = sum(result.cad_times_s.values())
    except BuildError as exc:
        print(f"  (stopped by a failed check: {str(exc).splitlines()[0]})")
        cad = float("nan")
    dt = time.perf_counter() - t0
    part_lines = [ln for ln in lines if PART_ROW.match(ln)]   # "   33  guide_bay   guide   link 0    0.52 s"
    rebuilt = [ln.split()[1] for ln in part_lines if "(cached)" not in ln]
    which = "all" if len(rebuilt) == len(part_lines) else (", ".join(rebuilt) or "none")
    return dt, cad, f"{len(part_lines)} parts, {len(rebuilt)} rebuilt: {which}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("params_file", nargs="?", default=str(ROOT / "swiftfin.toml"))
    args = ap.parse_args(argv)
    p = load_design(args.params_file)
    with tempfile.TemporaryDirectory(prefix="swiftfin-bench-") as tmp:
        tmp = Path(tmp)
        cache = FamilyCache(tmp / "cache")
        t_cold, cad_cold, what = timed_build(Path(args.params_file), tmp / "cold", cache)
        print(f"design: {args.params_file}")
        print(f"cold build:                         {t_cold:7.1f} s  ({what})")
        print(f"  bare CAD work in it:              {cad_cold:7.1f} s  -> cold / CAD = {t_cold / cad_cold:.2f} "
              f"(target <= {TARGET_COLD:g}: {'met' if t_cold / cad_cold <= TARGET_COLD else 'NOT met'})")
        t_same, _, what = timed_build(Path(args.params_file), tmp / "same", cache)
        print(f"rebuild, nothing changed:           {t_same:7.1f} s  ratio {t_same / t_cold:.3f}  ({what})")
        for key, delta in CHANGES:
            changed = replace_key(p, key, get_key(p, key) + delta)
            f = tmp / f"{key}.toml"
            f.write_text(tomli_w.dumps(to_dict(changed)))
            t, _, what = timed_build(f, tmp / key, cache)
            target = f"  (target <= {TARGET_REBUILD:g}: {'met' if t / t_cold <= TARGET_REBUILD else 'NOT met'})" \
                if key == CHANGES[0][0] else ""
            print(f"rebuild, {key} {delta:+g}:".ljust(36) + f"{t:7.1f} s  ratio {t / t_cold:.3f}{target}  ({what})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
