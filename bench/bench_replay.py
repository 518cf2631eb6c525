"""The closed loop on simulated bench logs (issue 14, item 4): for each effect of ``swiftfin synth joint`` alone
(and none), fit the log, write its calibration and replay the command in MuJoCo through an exported MJCF's joint,
as exported and as calibrated. Prints the effects the fit named and both replay errors beside the fit's own
held-out error (the noise floor is ~1.1e-3 rad), and the time a replay takes.

    .venv/bin/python bench/bench_replay.py [build/robot/swiftfin.xml] [--seed 1]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

from swiftfin.cli import main as swiftfin

ROOT = Path(__file__).resolve().parents[1]
EFFECTS = ("none", "viscous_friction", "coulomb_friction", "cable_compliance", "added_mass", "backlash", "offset",
           "effective_radius", "sensor_delay", "quadratic_drag", "capstan_creep")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mjcf", nargs="?", default=str(ROOT / "build" / "robot" / "swiftfin.xml"),
                    help="an exported MJCF (default: build/robot/swiftfin.xml, which `make build` writes)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    if not Path(args.mjcf).is_file():
        print(f"{args.mjcf}: no such MJCF; run `make build` first or name a build's robot/swiftfin.xml",
              file=sys.stderr)
        return 2
    print(f"{'effect':<18} {'named':<24} {'fit held-out':>12} {'replay exported':>16} {'replay calibrated':>18}  "
          f"not replayed")
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for e in EFFECTS:
            log, out = Path(tmp) / f"{e}.csv", Path(tmp) / e
            with contextlib.redirect_stdout(io.StringIO()):
                swiftfin(["synth", "joint", "--out", str(log), "--seed", str(args.seed)]
                         + ([] if e == "none" else ["--effect", e]))
                t0 = time.perf_counter()
                swiftfin(["fit", "joint", str(log), "--out", str(out), "--no-plots", "--mjcf", args.mjcf])
                times.append(time.perf_counter() - t0)
            rep = json.loads((out / "fit_report.json").read_text())
            named = ", ".join(x["name"] for x in rep["added_effects"]) or "-"
            r = rep["replay"]
            print(f"{e:<18} {named:<24} {rep['final']['rmse_holdout']:12.4f} {r['before']['rmse_rad']:16.4f} "
                  f"{r['after']['rmse_rad']:18.4f}  {', '.join(r['not_replayed']) or '-'}")
    print(f"fit + calibration + replay per 40 000-sample log: {min(times):.1f}-{max(times):.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
