"""PrusaSlicer's command line as a function: slice an STL with the parameter file's print settings and read
the filament used and the print time from the G-code comments.

Settings passed (``[print]`` of the parameter file): layer height (also the first layer's), perimeters,
solid top and bottom layers, sparse infill density and pattern, nozzle and filament diameter, filament
density, bed shape and build height, and one extrusion width for every extrusion role (so the slicer and a
volume model built on ``print.line_width_mm`` speak of the same lines). Skirt and brim are off: the filament
reported is the part's own. Supports stay off (the slicer's default): parts are oriented to print without.

``filament_mm3`` is computed from the reported length and the filament diameter (the slicer's own
``[cm3]`` line is rounded to 0.01 cm^3); the ``[cm3]`` and ``[g]`` lines are kept as reported.
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

SLICER = "prusa-slicer"
TIMEOUT_S = 600

_PATTERNS = {"gyroid": "gyroid", "grid": "grid", "rectilinear": "rectilinear", "cubic": "cubic",
             "honeycomb": "honeycomb", "line": "line"}


class SlicerError(RuntimeError):
    """The slicer is missing, failed, or wrote G-code without the expected summary."""


@dataclass(frozen=True)
class SliceResult:
    stl: str
    filament_mm: float           # filament length [mm]
    filament_mm3: float          # filament volume from the length [mm^3]
    filament_cm3_reported: float
    filament_g: float | None
    print_time_s: float
    print_time_text: str

    @property
    def filament_cm3(self) -> float:
        return self.filament_mm3 / 1000.0


def slicer_config(p) -> dict[str, str]:
    """PrusaSlicer's configuration keys and values for the ``[print]`` section of a Params: what the command
    line passes (:func:`slicer_args`) and what every 3MF carries in ``Metadata/Slic3r_PE.config``."""
    pr = p.print
    w = f"{pr.line_width_mm:g}"
    cfg = {
        "layer_height": f"{pr.layer_height_mm:g}",
        "first_layer_height": f"{pr.layer_height_mm:g}",
        "perimeters": str(pr.perimeters),
        "top_solid_layers": str(pr.top_layers),
        "bottom_solid_layers": str(pr.bottom_layers),
        "fill_density": f"{100 * pr.infill_fraction:g}%",
        "fill_pattern": _PATTERNS[pr.infill_pattern],
        "nozzle_diameter": f"{pr.nozzle_diameter_mm:g}",
        "filament_diameter": f"{pr.filament_diameter_mm:g}",
        "filament_density": f"{pr.filament_density_kg_m3 / 1000:g}",
        "bed_shape": f"0x0,{pr.bed_x_mm:g}x0,{pr.bed_x_mm:g}x{pr.bed_y_mm:g},0x{pr.bed_y_mm:g}",
        "max_print_height": f"{pr.bed_z_mm:g}",
        "skirts": "0",
        "brim_width": "0",
    }
    for role in ("extrusion_width", "first_layer_extrusion_width", "perimeter_extrusion_width",
                 "external_perimeter_extrusion_width", "infill_extrusion_width",
                 "solid_infill_extrusion_width", "top_infill_extrusion_width"):
        cfg[role] = w
    return cfg


def slicer_args(p) -> list[str]:
    """Command-line options for the ``[print]`` section of a Params (:func:`slicer_config` as flags)."""
    args = []
    for key, value in slicer_config(p).items():
        args += [f"--{key.replace('_', '-')}", value]
    return args


_TIME_RE = re.compile(r"(\d+)\s*([dhms])")


def parse_duration_s(text: str) -> float:
    """'1d 2h 3m 4s' -> seconds."""
    mult = {"d": 86400, "h": 3600, "m": 60, "s": 1}
    parts = _TIME_RE.findall(text)
    if not parts:
        raise SlicerError(f"cannot read the print time {text!r}")
    return float(sum(int(n) * mult[u] for n, u in parts))


def parse_gcode_summary(text: str, filament_diameter_mm: float, stl: str = "") -> SliceResult:
    """Filament and time from PrusaSlicer's G-code comments."""
    def grab(pattern: str) -> str | None:
        m = re.search(pattern, text, re.MULTILINE)
        return m.group(1).strip() if m else None

    length = grab(r"^; filament used \[mm\] = ([0-9.eE+-]+)")
    cm3 = grab(r"^; filament used \[cm3\] = ([0-9.eE+-]+)")
    grams = grab(r"^; filament used \[g\] = ([0-9.eE+-]+)")
    ptime = grab(r"^; estimated printing time \(normal mode\) = (.+)$")
    if length is None or ptime is None:
        raise SlicerError(f"{stl}: the G-code has no filament/time summary (did the slicer finish?)")
    mm = float(length)
    return SliceResult(stl, mm, mm * math.pi * filament_diameter_mm**2 / 4, float(cm3) if cm3 else float("nan"),
                       float(grams) if grams else None, parse_duration_s(ptime), ptime)


def slice_stl(stl: str | Path, p, gcode_out: str | Path | None = None, slicer: str | None = None,
              settings: bool = True) -> SliceResult:
    """Slice one STL (or 3MF) with the print settings of ``p``; raise SlicerError with the slicer's message on
    failure. ``settings`` False: pass no settings at all, as a user who opens the file would (a 3MF then slices
    with the settings it carries, exports.files.threemf_bytes; ``p`` only gives the filament diameter)."""
    exe = slicer or shutil.which(SLICER)
    if exe is None:
        raise SlicerError(f"{SLICER} not found on PATH (Debian/Ubuntu: apt-get install prusa-slicer)")
    stl = Path(stl)
    if not stl.is_file():
        raise SlicerError(f"{stl}: no such file")
    with tempfile.TemporaryDirectory(prefix="swiftfin-slice-") as tmp:
        out = Path(gcode_out) if gcode_out else Path(tmp) / (stl.stem + ".gcode")
        cmd = [exe, "--loglevel", "1", "--export-gcode", *(slicer_args(p) if settings else []), "--output", str(out),
               str(stl)]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S,
                                  env={"HOME": tmp, "PATH": "/usr/bin:/bin", "LC_ALL": "C"})
        except subprocess.TimeoutExpired:
            raise SlicerError(f"{stl.name}: {SLICER} did not finish in {TIMEOUT_S} s") from None
        if proc.returncode != 0 or not out.is_file():
            msg = "\n".join(line for line in (proc.stderr + proc.stdout).splitlines()
                            if line.strip() and "[trace]" not in line)[-2000:]
            raise SlicerError(f"{stl.name}: {SLICER} failed (exit {proc.returncode}): {msg.strip()}")
        return parse_gcode_summary(out.read_text(errors="replace"), p.print.filament_diameter_mm, stl.name)
