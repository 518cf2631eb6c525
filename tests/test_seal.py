"""The seam gasket (cad/seal.py): it fills the gap the sealed pieces' lower halves leave under the seam plane, the dry
check refuses the head without it, its numbers are worked by hand and measured on its solid by a method checked on
shapes whose answer is known, and its outline drawing has the solid's area."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from swiftfin.cad.seal import GASKET_LABEL
from swiftfin.exports.gasket import (compression_range, gasket_numbers, gasket_outline_svg_of, narrowest_strip_mm,
                                     ring_survives_opening, sponge_stress_kpa)
from swiftfin.catalogues.seals import compression_limiter, seal_limits, seam_gasket
from tests.conftest import manifold_of


@pytest.fixture(scope="module")
def by_label(default_parts):
    return {s.label: s for s in default_parts}


@pytest.fixture(scope="module")
def gasket(by_label):
    return by_label[GASKET_LABEL]


def _mesh_manifold(solid, p):
    return manifold_of(solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)


def _circle(r, c=(0.0, 0.0), n=720, ccw=True):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    pts = np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t)])
    return pts if ccw else pts[::-1]


# ----------------------------------------------------------------------------------------------- numbers by hand
def test_the_gap_and_the_compression_band_worked_by_hand(default_params):
    """Sheet t = 2.4 mm, band 25-50 %: the limiter stops the faces at the band's middle, t (1 - 0.375) = 1.5 mm.
    The gap's worst case is the limiter's +/- 0.05 plus each printed face's +/- 0.1: 1.25-1.75 mm, so the sheet is
    compressed (2.4 - 1.75) / 2.4 = 27.1 % to (2.4 - 1.25) / 2.4 = 47.9 %."""
    sheet, lim = seam_gasket(), compression_limiter()
    assert (sheet.sheet_thickness_mm, sheet.compression_min_fraction,
            sheet.compression_max_fraction) == (2.4, 0.25, 0.5)
    assert (lim.length_tolerance_mm, seal_limits().print_tolerance_mm) == (0.05, 0.1)
    assert sheet.limiter_length_mm() == pytest.approx(1.5)
    lo, hi = compression_range(default_params, 1.5)
    assert lo == pytest.approx(0.65 / 2.4) and hi == pytest.approx(1.15 / 2.4)
    # the contact stress is linear through the catalogue's 27 kPa at 25 %
    assert sponge_stress_kpa(0.25) == pytest.approx(27.0) and sponge_stress_kpa(lo) == pytest.approx(27.0 * lo / 0.25)
    # a brass sleeve 3.0 x 2.1 mm, 1.5 mm long: pi/4 (9 - 4.41) 1.5 mm^3 of brass at 8500 kg/m^3
    assert lim.mass_kg(1.5) == pytest.approx(8500 * math.pi / 4 * (9 - 4.41) * 1.5e-9)


def test_the_strip_measure_recovers_known_widths():
    """The ring's narrowest strip (the widest disc that travels round it), checked where the answer is known: an
    annulus of radii 10 and 13 mm (3 mm), and the same annulus with a 1.2 mm neck bitten out of its side (a circle of radius 1.8 mm centred on
    the outer edge leaves 13 - 1.8 - 10 = 1.2 mm), which a wider disc cannot pass."""
    ring = [_circle(13.0), _circle(10.0, ccw=False)]
    assert narrowest_strip_mm(ring, 10.0) == pytest.approx(3.0, abs=0.03)
    assert ring_survives_opening(ring, 2.9)[0] and not ring_survives_opening(ring, 3.1)[0]
    import manifold3d as m3d
    cs = m3d.CrossSection(ring, m3d.FillRule.EvenOdd) - m3d.CrossSection([_circle(1.8, (13.0, 0.0))])
    necked = [np.asarray(pl) for pl in cs.to_polygons()]
    assert narrowest_strip_mm(necked, 10.0) == pytest.approx(1.2, abs=0.05)
    ok, where = ring_survives_opening(necked, 1.5)
    assert not ok and where is not None and where[0] > 10.0 and abs(where[1]) < 3.0


def test_swiftfin_check_seats_the_gasket_from_the_parameters(default_params):
    """``seal.seam_gasket`` in ``swiftfin check``: 27 kPa x 0.2708 / 0.25 = 29.25 kPa at the least compression,
    against 2 x 1000 x 9.81 x 0.5 Pa = 9.81 kPa; at 2 m the water needs 39.2 kPa and it fails; a hull not split in
    halves has no gasket (not evaluated). The vectorised twin agrees (tests/test_vectorised_rules.py)."""
    import dataclasses
    from swiftfin.design_rules import RULES, RuleContext, Severity, run_rules
    rule = [r for r in RULES if r.rule_id == "seal.seam_gasket"]
    p = default_params

    def finding(q):
        (f,) = run_rules(RuleContext(q), rule)
        return f
    f = finding(p)
    assert f.severity is Severity.PASS and f.unit == "kPa"
    assert f.value == pytest.approx(27.0 * (0.65 / 2.4) / 0.25) and f.limit == pytest.approx(9.81)
    deep = dataclasses.replace(p, environment=dataclasses.replace(p.environment, design_depth_m=2.0))
    assert finding(deep).severity is Severity.FAIL and finding(deep).limit == pytest.approx(39.24)
    whole = dataclasses.replace(p, hull=dataclasses.replace(p.hull, split_halves=False))
    assert finding(whole).severity is Severity.NOT_EVALUATED


# ----------------------------------------------------------------------------------------------- on the solids
def test_the_gasket_fills_the_gap_under_the_seam_plane(default_params, by_label, gasket):
    """Each sealed piece's lower half stops the gap below the seam plane from its front to its rear end, the upper
    half starts at the plane, and the gasket is the slab between them: 1.5 mm thick, touching both halves, its
    volume its section's area times the gap."""
    from swiftfin.cad.dry_check import sealed_pieces
    p = default_params
    g = gasket.meta["gap_mm"]
    assert g == pytest.approx(1.5)
    assert gasket.family == "seal" and not gasket.printed
    bb = gasket.solid.bounding_box()
    assert bb.min.Z == pytest.approx(-g, abs=1e-6) and bb.max.Z == pytest.approx(0.0, abs=1e-6)
    gm = _mesh_manifold(gasket.solid, p)
    for pc in sealed_pieces(p):
        up, lo = by_label[f"{pc.name}_upper"], by_label[f"{pc.name}_lower"]
        assert up.solid.bounding_box().min.Z == pytest.approx(0.0, abs=1e-6)
        # the lower half's material ahead of the piece's rear end stays under -g: a slab from -g to 0 over the
        # piece holds none of it
        from swiftfin.cad.link import box
        slab = box(-pc.s_end_mm + 0.01, -pc.s_start_mm + 60, -200, 200, -g + 0.01, 0.0)
        res = lo.solid.intersect(slab)
        shapes = [] if not res else (res if isinstance(res, (list, tuple)) else [res])
        assert sum(s.volume for sh in shapes for s in sh.solids()) < 1e-6, lo.label
        for half in (up, lo):
            assert gm.min_gap(_mesh_manifold(half.solid, p), 0.5) < 0.02, half.label
    # its area from the B-rep's faces in the seam plane, against the mesh's section at mid-gap and its volume
    area = gasket.meta["area_mm2"]
    assert gm.slice(-g / 2).area() == pytest.approx(area, rel=0.003)
    assert gm.volume() == pytest.approx(area * g, rel=0.003)


def test_the_gasket_numbers_on_the_default_head(default_params, gasket):
    """Measured on the gasket's solid: compression in band, seated over twice the water's pressure at the design
    depth, the sealing ring never narrower than the sheet's least strip (the lands widen the seam face where
    the wall's 2 mm is not enough, more where the skin's line slopes near the nose; the sheet's least strip is its
    2.4 mm thickness), and every hole (a limiter round
    each of the 14 seam screws, a dowel's) leaves at least 1 mm of sponge to an edge."""
    n = gasket_numbers(default_params, gasket)
    assert n.ok, n.problems
    assert n.screws == 14 and len(gasket.meta["holes"]) == 18
    env = default_params.environment
    assert (env.water_density_kg_m3, env.gravity_m_s2, env.design_depth_m) == (1000.0, 9.81, 0.5)
    assert n.water_pressure_kpa == pytest.approx(1000 * 9.81 * 0.5 / 1000)
    assert 2.4 <= n.strip_mm < 3.0              # the least strip + the land's 0.25 mm margin, less the tessellation
    assert 1.0 <= n.web_mm < 2.0
    assert n.contact_stress_min_kpa > 2 * n.water_pressure_kpa


def test_the_dry_check_refuses_the_head_without_its_gasket(default_params, by_label):
    """The gap under the seam plane is an opening of the dry wall all round the head unless the gasket fills it:
    without the gasket the check finds it unsealed, in a hull_head part, between the gap's faces."""
    from swiftfin.cad.dry_check import check_dry_wall, dry_wall_problems, sealed_part_labels
    p = default_params
    labels = sealed_part_labels(p)
    assert GASKET_LABEL in labels
    mans = {lb: _mesh_manifold(by_label[lb].solid, p) for lb in labels}
    with_it = check_dry_wall(p, mans)
    assert not with_it.unsealed and not dry_wall_problems(p, with_it)
    without = check_dry_wall(p, {lb: m for lb, m in mans.items() if lb != GASKET_LABEL})
    problems = dry_wall_problems(p, without)
    assert without.unsealed and problems
    g = by_label[GASKET_LABEL].meta["gap_mm"]
    big = max(without.unsealed, key=lambda o: o.volume_mm3)
    assert big.part.startswith("hull_head") and -g - 0.3 <= big.centre_mm[2] <= 0.3
    assert big.size_mm[0] > 100 and big.volume_mm3 > 100    # it runs along the head
    assert "not a declared sealed crossing" in problems[0]


def test_the_outline_drawing_has_the_solids_area(default_params, gasket):
    """The SVG the builder orders the gasket from: its path's even-odd area (the shoelace sum of its contours, holes
    counted negative) is the solid's section area, and it is drawn 1:1 in millimetres."""
    svg = gasket_outline_svg_of(gasket)
    assert re.search(r'width="[\d.]+mm"', svg)
    d = re.search(r'd="([^"]+)"', svg).group(1)
    contours = []
    for part in d.split("Z"):
        pts = re.findall(r"(-?[\d.]+),(-?[\d.]+)", part)
        if pts:
            contours.append(np.array(pts, float))
    areas = [0.5 * (np.dot(c[:, 0], np.roll(c[:, 1], -1)) - np.dot(c[:, 1], np.roll(c[:, 0], -1))) for c in contours]
    outer = max(areas, key=abs)
    total = sum(areas)
    assert abs(total) == pytest.approx(gasket.meta["area_mm2"], rel=0.01)
    assert len(contours) == 2 + len(gasket.meta["holes"])          # the outline, the cavity, the holes


def test_the_bill_lists_the_gasket_its_limiters_and_the_splice_epoxy(default_params, default_parts):
    from swiftfin.cad.fastening import all_fasteners
    from swiftfin.exports.bom import bom_lines
    lines = bom_lines(default_params, default_parts, all_fasteners(default_params))
    by_item = {}
    for ln in lines:
        by_item.setdefault(ln.item, []).append(ln)
    (gl,) = by_item["Seam gasket, die-cut"]
    assert gl.quantity == 1 and "2.4 mm" in gl.spec and "seam_gasket.svg" in gl.spec
    (lim,) = by_item["Compression limiter"]
    assert lim.quantity == 14 and "cut 1.50" in lim.spec
    assert any("splice" in ln.where for ln in by_item["Adhesive"])


def test_each_sealed_link_has_its_own_gasket(default_params):
    """A joint moves, so a hull sealed behind joint 1 (``hull.flooded_from_joint = 2``) has a gasket per sealed link
    in its dry wall; a hull not split in halves has none (its pieces print whole)."""
    import dataclasses
    from swiftfin.cad.dry_check import sealed_part_labels
    p = default_params
    assert [lb for lb in sealed_part_labels(p) if lb.startswith("seam_gasket")] == ["seam_gasket"]
    two = dataclasses.replace(p, hull=dataclasses.replace(p.hull, flooded_from_joint=2))
    assert [lb for lb in sealed_part_labels(two) if lb.startswith("seam_gasket")] == ["seam_gasket", "seam_gasket_1"]
    whole = dataclasses.replace(p, hull=dataclasses.replace(p.hull, split_halves=False))
    assert not [lb for lb in sealed_part_labels(whole) if lb.startswith("seam_gasket")]


def test_the_lower_halves_print_on_their_seam_face(default_params, by_label):
    """A sealed piece's lower half prints cut face down: with the gap cut over the splice tabs too, nothing stands
    above the gasket's face, so that face is the bed contact (a tab left 1.5 mm proud once lifted the whole face off
    the bed: a 317 mm bridge)."""
    from swiftfin.cad.dry_check import sealed_pieces
    from swiftfin.exports.brep import tessellate
    p = default_params
    for pc in sealed_pieces(p):
        spec = by_label[f"{pc.name}_lower"]
        assert spec.print_rotation[0] == 180.0
        m = tessellate(spec.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
        v = np.asarray(m.vertices, float) * np.array([1.0, -1.0, -1.0])      # 180 deg about x
        v[:, 2] -= v[:, 2].min()
        tri = v[np.asarray(m.faces)]
        a, b = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        areas = 0.5 * np.linalg.norm(np.cross(a, b), axis=1)
        on_bed = areas[tri[:, :, 2].max(axis=1) <= 0.05].sum()
        assert on_bed > 1000.0, (pc.name, on_bed)
