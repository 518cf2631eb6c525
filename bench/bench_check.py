"""Start-up of the kernel-free commands: ``swiftfin check`` (and ``params``, ``--help``) of the default design
as whole processes, against a bare ``python -c pass`` and an ``import numpy`` run side by side (house style
rule 14: ratios in one run). Target (issue 10): ``swiftfin check`` under 0.5 s on an idle machine.

    .venv/bin/python bench/bench_check.py [--runs 7]
"""
from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET_S = 0.5


def timed(cmd: list[str], cwd: Path, runs: int) -> tuple[float, float]:
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t0)
    return min(times), statistics.median(times)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=7)
    args = ap.parse_args(argv)
    py = sys.executable
    with tempfile.TemporaryDirectory() as tmp:            # an empty folder: the shipped default design
        cwd = Path(tmp)
        rows = [("python -c pass", [py, "-c", "pass"]),
                ("python -c 'import numpy'", [py, "-c", "import numpy"]),
                ("swiftfin --help", [py, "-m", "swiftfin", "--help"]),
                ("swiftfin params", [py, "-m", "swiftfin", "params"]),
                ("swiftfin check", [py, "-m", "swiftfin", "check"]),
                ("python -c 'import build123d'", [py, "-c", "import build123d"])]
        timed(rows[0][1], cwd, 2)                          # warm the file cache
        results = [(name, *timed(cmd, cwd, args.runs)) for name, cmd in rows]
    base = results[0][1]
    print(f"{'command':32s} {'min s':>7s} {'median s':>9s} {'min / python':>13s}")
    for name, tmin, tmed in results:
        print(f"{name:32s} {tmin:7.3f} {tmed:9.3f} {tmin / base:13.1f}")
    check = dict((n, m) for n, m, _ in results)["swiftfin check"]
    print(f"swiftfin check: {check:.3f} s (target < {TARGET_S} s: {'met' if check < TARGET_S else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
