"""``swiftfin build``: every part of a design as STEP, STL and 3MF, an assembly STEP and a manifest."""
from __future__ import annotations

import sys
from pathlib import Path
from swiftfin.commands import DESIGN_HELP



def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    ap.add_argument("params_file", nargs="?", default=None, help=DESIGN_HELP)
    ap.add_argument("--out", default="build", help="output folder, replaced atomically (default: build/)")
    ap.add_argument("--cache-dir", default=None,
                    help="rebuild cache (default: $SWIFTFIN_CACHE_DIR or .cache/swiftfin/ here)")
    ap.add_argument("--no-cache", action="store_true",
                    help="build every part afresh; do not read or write the cache (the build keeps its own results "
                         "in a temporary folder, removed after)")
    ap.add_argument("--ros2-package", action="store_true",
                    help="also write robot/swiftfin_description/: a ROS 2 description package (package.xml, "
                         "CMakeLists.txt, the URDF with package:// mesh URIs, the meshes; no launch files)")
    ap.add_argument("--swim", action="store_true",
                    help="also swim the exported fish in MuJoCo at 1, 2 and 3 Hz (quasi-steady, and with Lighthill's "
                         "reactive force) and show speed, stride and slip in the report (about 20 s of CPU)")
    ap.add_argument("--calibration", metavar="FILE",
                    help="a calibration file (swiftfin fit joint writes one): the measured hinge damping, friction "
                         "and cable stiffness go into the simulator files, the measured cable modulus into the "
                         "design, and the report's rules use them")
    ap.set_defaults(func=run)


def run(args) -> int:
    from swiftfin.cache import command_cache
    from swiftfin.pipeline import build, stderr_progress, summary_table

    print(f"swiftfin build: {args.params_file} -> {args.out}/", file=sys.stderr, flush=True)
    # --no-cache builds through an empty cache of its own: with none at all (no prefetch processes, no proved pairs or
    # stage results shared within the build) the default design took 13 min 48 s of wall clock and 1 475 s of CPU,
    # through an empty cache 4 min 15 s and 424 s (2026-11-28, idle)
    with command_cache(args.no_cache, args.cache_dir) as cache:
        result = build(args.params_file, args.out, cache=cache, progress=stderr_progress,
                       ros2_package=args.ros2_package, swim=args.swim, calibration=args.calibration)
    print(summary_table(result))
    import json
    listed = json.loads((Path(args.out) / "manifest.json").read_text())["files"]
    print(f"wrote {len(listed) + 1} files to {Path(args.out)}/: parts, assembly.step, robot/, mass_properties.json, "
          f"report.html and manifest.json (which lists the others with their SHA-256)")
    return 0
