"""PrusaSlicer wrapper: G-code summary parsing, settings passed through, and every printed part slices."""
from __future__ import annotations

import math

import build123d as bd
import pytest

from swiftfin.exports.files import print_transform, stl_bytes, tessellate
from swiftfin.exports.slicer import SlicerError, parse_duration_s, parse_gcode_summary, slice_stl, slicer_args
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params
from tests.conftest import require_tool

WHY = "slicing every printed part checks that the STLs print (issue 2, item 6)"

GCODE_TAIL = """G1 X10 Y10 E0.5
; filament used [mm] = 1000.00
; filament used [cm3] = 2.41
; filament used [g] = 2.98
; total filament used [g] = 2.98
; estimated printing time (normal mode) = 1d 2h 3m 4s
; estimated first layer printing time (normal mode) = 1m 2s
"""


def test_parse_gcode_summary_hand_worked():
    r = parse_gcode_summary(GCODE_TAIL, 1.75, "x.stl")
    assert r.filament_mm == 1000.0
    assert r.filament_mm3 == pytest.approx(1000.0 * math.pi * 0.875**2)   # 2405.28 mm^3
    assert r.filament_cm3_reported == 2.41 and r.filament_g == 2.98
    assert r.print_time_s == 86400 + 2 * 3600 + 3 * 60 + 4


def test_parse_rejects_gcode_without_summary():
    with pytest.raises(SlicerError, match="no filament/time summary"):
        parse_gcode_summary("G1 X0\n", 1.75, "x.stl")
    assert parse_duration_s("47s") == 47.0
    with pytest.raises(SlicerError):
        parse_duration_s("soon")


def test_slicer_args_carry_the_print_section():
    p = replace_key(Params(), "print.infill_fraction", 0.35)
    args = slicer_args(p)
    opt = dict(zip(args[::2], args[1::2]))
    assert opt["--fill-density"] == "35%"
    assert opt["--layer-height"] == "0.2" and opt["--perimeters"] == "3"
    assert opt["--top-solid-layers"] == "5" and opt["--bottom-solid-layers"] == "4"
    assert opt["--fill-pattern"] == "gyroid"
    assert opt["--nozzle-diameter"] == "0.4" and opt["--filament-diameter"] == "1.75"
    assert opt["--bed-shape"] == "0x0,250x0,250x210,0x210"
    assert opt["--perimeter-extrusion-width"] == "0.45"


def _cube_stl(tmp_path, side=20.0):
    m = tessellate(bd.Box(side, side, side), 0.05, 10.0)
    m = m.transformed(print_transform(m, (0, 0, 0), 250, 210))
    path = tmp_path / "cube.stl"
    path.write_bytes(stl_bytes(m, "cube"))
    return path


@pytest.mark.slicer
def test_cube_filament_follows_the_shell_and_infill_model(tmp_path):
    """A 20 mm cube: walls 3 x 0.45 mm, 5 top + 4 bottom layers of 0.2 mm, sparse infill at f.
    Solid shell V_s = 20^3 - (20 - 2.7)^2 (20 - 1.8) = 2553 mm^3, core V_c = 5447 mm^3, so the
    filament is about V_s + f V_c; raising f from 20 % to 50 % must add about 0.3 V_c = 1634 mm^3."""
    require_tool("prusa-slicer", WHY)
    stl = _cube_stl(tmp_path)
    p20 = Params()
    p50 = replace_key(p20, "print.infill_fraction", 0.5)
    r20 = slice_stl(stl, p20)
    r50 = slice_stl(stl, p50)
    core = (20 - 2 * 3 * 0.45) ** 2 * (20 - 9 * 0.2)
    shell = 20**3 - core
    assert r20.filament_mm3 == pytest.approx(shell + 0.2 * core, rel=0.15)
    assert r50.filament_mm3 - r20.filament_mm3 == pytest.approx(0.3 * core, rel=0.2)
    assert r50.print_time_s > r20.print_time_s > 0


@pytest.mark.slicer
def test_slicer_failure_is_a_clear_error(tmp_path):
    require_tool("prusa-slicer", WHY)
    bad = tmp_path / "broken.stl"
    bad.write_bytes(b"solid nothing here\n")
    with pytest.raises(SlicerError, match="broken.stl: prusa-slicer failed"):
        slice_stl(bad, Params())
    with pytest.raises(SlicerError, match="no such file"):
        slice_stl(tmp_path / "missing.stl", Params())


@pytest.mark.slow
@pytest.mark.slicer
def test_every_printed_part_of_the_default_design_slices(default_parts, default_slices):
    """Every printed part's 3MF slices (the session's slices, conftest.default_slices: the 3MF alone, with the
    settings it carries; test_a_3mf_alone_slices_with_the_design_settings_not_the_defaults and the cube tests cover
    the settings passed on the command line)."""
    printed = [part.label for part in default_parts if part.printed]
    assert sorted(default_slices) == sorted(printed) and printed
    rows = []
    for label in printed:
        ex, r = default_slices[label]
        # the filament cannot exceed the solid part (plus the slicer's line overlap) nor vanish
        assert 0.05 * ex.volume_mm3 < r.filament_mm3 < 1.15 * ex.volume_mm3, (label, r)
        assert r.print_time_s > 0, (label, r)
        rows.append((label, ex.volume_mm3, r.filament_mm3, r.print_time_s))
    print("\npart                         solid cm^3  filament cm^3  time min")
    for label, v, f, t in rows:
        print(f"{label:<28} {v / 1000:10.2f} {f / 1000:14.2f} {t / 60:9.1f}")


def test_every_3mf_carries_the_print_settings_prusaslicer_reads(default_params):
    """The 3MF's Metadata/Slic3r_PE.config holds the [print] section as PrusaSlicer's own keys: the same values
    the command line passes (one table, exports.slicer.slicer_config)."""
    import io
    import zipfile

    from swiftfin.exports.files import PRUSA_CONFIG, threemf_bytes
    from swiftfin.exports.slicer import slicer_config

    p = replace_key(default_params, "print.infill_fraction", 0.35)
    m = tessellate(bd.Box(10, 10, 10), 0.05, 10.0)
    with zipfile.ZipFile(io.BytesIO(threemf_bytes(m, "cube", slicer_config(p)))) as z:
        text = z.read(PRUSA_CONFIG).decode()
    cfg = dict(line[2:].split(" = ", 1) for line in text.splitlines()[1:])
    assert cfg["fill_density"] == "35%" and cfg["perimeters"] == "3" and cfg["layer_height"] == "0.2"
    assert cfg == slicer_config(p)
    args = slicer_args(p)
    assert dict(zip(args[::2], args[1::2])) == {f"--{k.replace('_', '-')}": v for k, v in cfg.items()}


@pytest.mark.slicer
def test_a_3mf_alone_slices_with_the_design_settings_not_the_defaults(tmp_path):
    """Sliced with nothing on the command line, a part's 3MF extrudes what its STL does with the design's
    settings (to 0.1 %), and not what the STL does with PrusaSlicer's defaults."""
    require_tool("prusa-slicer", WHY)
    from swiftfin.exports.files import threemf_bytes
    from swiftfin.exports.slicer import slicer_config

    p = replace_key(Params(), "print.infill_fraction", 0.40)     # far from PrusaSlicer's default 15 %
    m = tessellate(bd.Box(30, 30, 20), 0.05, 10.0)
    m = m.transformed(print_transform(m, (0, 0, 0), 250, 210))
    (tmp_path / "b.stl").write_bytes(stl_bytes(m, "b"))
    (tmp_path / "b.3mf").write_bytes(threemf_bytes(m, "b", slicer_config(p)))
    alone = slice_stl(tmp_path / "b.3mf", p, settings=False).filament_mm3
    with_args = slice_stl(tmp_path / "b.stl", p).filament_mm3
    defaults = slice_stl(tmp_path / "b.stl", p, settings=False).filament_mm3
    assert alone == pytest.approx(with_args, rel=1e-3)
    assert abs(defaults / with_args - 1) > 0.05
