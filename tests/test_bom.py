"""The bill of materials (exports/bom.py): grouping, cut lengths against their sums, the CSV round trip."""
from __future__ import annotations

import math

import pytest

from swiftfin.exports.bom import (CABLE_TAIL_MM, FIELDS, BomLine, bom_csv, bought_part_lines, cable_lines,
                                  fastener_lines, read_bom_csv)
from swiftfin.layout.fastening import Fastener


def _f(label, **kw) -> Fastener:
    base = dict(label=label, size="M2", kind="cap_screw", seat="insert", head_mm=(0.0, 0.0, 0.0),
                axis=(0.0, 0.0, -1.0), length_mm=8.0, grip_mm=2.0, head_part="a", thread_part="b", joins="seam")
    base.update(kw)
    return Fastener(**base)


def test_fasteners_are_grouped_as_a_builder_orders_them():
    fs = [_f("s1"), _f("s2"), _f("s3", length_mm=10.0, joins="splice"), _f("n1", size="M3", seat="nut", grip_mm=4.0,
          length_mm=8.0, joins="mount", meta={"washer": "ISO 7089 M3"}),
          _f("p1", size="3", kind="dowel", seat="press", length_mm=12.0, head_part=None, joins="hinge 1"),
          _f("g1", size="M3", kind="set_screw", seat="nut", head_part=None, grip_mm=0.0, length_mm=6.0, joins="spool")]
    lines = {(x.item, x.spec): x for x in fastener_lines(fs)}
    assert lines[("Socket head cap screw", "ISO 4762 M2 x 8")].quantity == 2
    assert lines[("Socket head cap screw", "ISO 4762 M2 x 10")].where == "splice"
    assert lines[("Heat-set insert, brass", "M2 x 3 (OD 3.6, hole 3.2)")].quantity == 3
    assert lines[("Hex nut", "ISO 4032 M3")].quantity == 2               # the mount screw's and the set screw's
    assert lines[("Dowel pin, hardened", "ISO 8734 3 x 12 m6")].quantity == 1
    assert lines[("Set screw, flat point", "ISO 4026 M3 x 6")].quantity == 1
    assert lines[("Washer", "ISO 7089 M3")].quantity == 1
    assert sum(x.quantity for x in lines.values()) == 4 + 3 + 2 + 1 + 1 + 1    # screws, inserts, nuts, pin, set, washer


def test_cable_cut_lengths_add_up(default_params):
    from swiftfin.layout.geometry import cable_routes
    p = default_params
    lines = cable_lines(p)
    routes = cable_routes(p)
    assert len(lines) == len(routes) + 1
    wrap = (p.spool.wraps + p.spool.groove_margin_turns) / 2 * math.pi * p.spool.drum_diameter_mm
    for line, r in zip(lines, routes):
        cut = float(line.spec.rsplit("cut ", 1)[1].split()[0])
        assert cut > r.length_mm + wrap + 2 * CABLE_TAIL_MM               # plus the anchor runs
        assert cut < r.length_mm + wrap + 2 * CABLE_TAIL_MM + 100
    total = lines[-1]
    assert total.unit == "mm"
    assert total.quantity == pytest.approx(sum(float(x.spec.rsplit("cut ", 1)[1].split()[0]) for x in lines[:-1]),
                                           abs=1.0)


def test_bought_parts_list_one_motor_per_joint_and_no_mass_placeholder(default_params, default_parts):
    lines = bought_part_lines(default_params, default_parts)
    motors = [x for x in lines if x.item == "Stepper motor"]
    assert len(motors) == 1 and motors[0].quantity == default_params.joints.count
    assert not any(x.where == "fasteners" for x in lines)       # the screws are listed one by one instead


def test_csv_round_trip_keeps_every_field():
    lines = [BomLine("Cable", "nylon, 1 mm, cut 250 mm", 1, "pcs", "joint 1, left", "routes"),
             BomLine("Cable, total", "nylon", 1234.56, "mm", "all, \"quoted\"", "sum")]
    rows = read_bom_csv(bom_csv(lines))
    assert list(rows[0]) == list(FIELDS)
    assert rows[1]["where"] == "all, \"quoted\"" and rows[1]["quantity"] == "1234.6" and rows[0]["quantity"] == "1"


def test_every_ptfe_tube_is_a_cut_piece_and_the_total_adds_up(default_params):
    """Every tube of cad.cables.tube_runs on some line, its cut length its centre line rounded down to the cut step;
    the total to buy their sum; the epoxy the clearance round them filled, in mL."""
    from swiftfin.cad.cables import tube_runs
    from swiftfin.exports.bom import TUBE_CUT_STEP_MM, tube_lines
    p = default_params
    tubes = tube_runs(p)
    lines = tube_lines(p)
    pieces = [x for x in lines if x.item == "PTFE tube piece"]
    assert sum(x.quantity for x in pieces) == len(tubes)
    cuts = sorted(math.floor(t.length_mm / TUBE_CUT_STEP_MM + 1e-9) * TUBE_CUT_STEP_MM for t in tubes)
    listed = sorted(float(x.spec.rsplit("cut ", 1)[1].split()[0]) for x in pieces for _ in range(int(x.quantity)))
    assert listed == pytest.approx(cuts)
    assert all(0 <= t.length_mm - c < TUBE_CUT_STEP_MM for t, c in zip(sorted(tubes, key=lambda t: t.length_mm), cuts))
    total = next(x for x in lines if x.item == "PTFE tube, total to buy")
    assert total.unit == "mm" and total.quantity == pytest.approx(sum(cuts))
    glue = next(x for x in lines if x.item == "Adhesive")
    assert glue.unit == "mL" and 0 < glue.quantity < 5


def test_two_crimp_sleeves_per_cable_side(default_params):
    from swiftfin.exports.bom import crimp_lines
    (line,) = crimp_lines(default_params)
    assert line.quantity == 2 * 2 * default_params.joints.count
    assert f"for {default_params.cable.diameter_mm:g} mm cable" in line.spec
