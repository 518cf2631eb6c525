"""Mass properties: closed forms for solids, the print model, the inertial algebra and the validation gate."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from build123d import Axis, Box, Cylinder, Location, Pos

from swiftfin.layout import geometry as layout
from swiftfin.cad.part import PartSpec
from swiftfin.exports import massprops as mp
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

RHO = 1240.0


def box_inertia(m, a, b, c):
    return np.diag([m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12])


@pytest.fixture(scope="module")
def pm():
    return mp.PrintModel.from_params(Params())


# The side wall the slicer leaves before its infill, by hand: the outer loop's centre line half a 0.45 mm line
# in, two more loops one spacing apart, the infill half a spacing beyond; spacing = width - height (1 - pi/4)
# (two 0.2 mm high beads with round sides overlap by that much) = 0.45 - 0.2 x 0.214602 = 0.407080 mm.
# W = 0.225 + 2.5 x 0.407080 = 1.242699 mm.
W = 0.225 + 2.5 * (0.45 - 0.2 * (1 - math.pi / 4))


def test_side_wall_is_half_a_line_and_two_and_a_half_spacings(pm):
    assert W == pytest.approx(1.242699, abs=1e-6)
    assert pm.wall_mm == pytest.approx(W, rel=1e-12)


# ----------------------------------------------------------------------------------------------- solids
def test_brep_inertia_of_a_rotated_offset_box_is_the_closed_form():
    solid = Box(10, 20, 30).rotate(Axis.Z, 30).moved(Location((5, 6, 7)))
    it = mp.solid_volume_props(solid).inertial(RHO)
    m = RHO * 10e-3 * 20e-3 * 30e-3
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    assert it.mass_kg == pytest.approx(m, rel=1e-12)
    assert np.allclose(it.com, [5e-3, 6e-3, 7e-3], rtol=1e-12)
    assert np.allclose(it.inertia, R @ box_inertia(m, 0.01, 0.02, 0.03) @ R.T, rtol=1e-9, atol=1e-15)


def test_mesh_and_brep_agree_for_a_cylinder():
    cyl = Pos(3, -4, 5) * Cylinder(10, 40)
    a = mp.solid_volume_props(cyl)
    b = mp.mesh_volume_props(mp.tessellate(cyl, 0.01, 5))
    assert b.volume_mm3 == pytest.approx(a.volume_mm3, rel=2e-3)
    assert np.allclose(b.centroid_mm, a.centroid_mm, atol=1e-6)
    assert np.allclose(b.second_moment_mm5, a.second_moment_mm5, rtol=5e-3, atol=1e-6 * np.abs(a.second_moment_mm5).max())


# ----------------------------------------------------------------------------------------------- inertial algebra
def test_combine_two_masses_parallel_axis_closed_form():
    """Two equal boxes 0.1 m apart on x: COM in the middle, Iyy = Izz gain 2 m (0.05)^2."""
    I0 = box_inertia(1.0, 0.02, 0.02, 0.02)
    a = mp.make_inertial(1.0, (0.0, 0, 0), I0)
    b = mp.make_inertial(1.0, (0.1, 0, 0), I0)
    c = mp.combine([a, b])
    assert c.mass_kg == 2.0
    assert np.allclose(c.com, [0.05, 0, 0])
    assert np.allclose(c.inertia, 2 * I0 + np.diag([0.0, 2 * 0.05**2, 2 * 0.05**2]), rtol=1e-12)


def test_subtracting_a_core_equals_the_hollow_solid():
    """Solid minus an off-centre core (negative mass) == OCC's own hollow solid."""
    outer = Box(40, 30, 20)
    inner = Pos(2, -1, 1.5) * Box(30, 20, 10)
    a = mp.solid_volume_props(outer).inertial(RHO)
    b = mp.solid_volume_props(inner).inertial(RHO)
    hollow = mp.combine([a, b.scaled_mass(-1.0)])
    ref = mp.solid_volume_props(outer - inner).inertial(RHO)
    assert hollow.mass_kg == pytest.approx(ref.mass_kg, rel=1e-9)
    assert np.allclose(hollow.com, ref.com, rtol=1e-9, atol=1e-12)
    assert np.allclose(hollow.inertia, ref.inertia, rtol=1e-8, atol=1e-14)


def test_rotate_then_compute_equals_compute_then_rotate():
    solid = Pos(10, 5, -3) * Box(40, 12, 7)
    R_deg = 37.0
    a = mp.solid_volume_props(solid.rotate(Axis.Z, R_deg)).inertial(RHO)
    c, s = math.cos(math.radians(R_deg)), math.sin(math.radians(R_deg))
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    b = mp.solid_volume_props(solid).inertial(RHO).rotated(R)
    assert np.allclose(a.com, b.com, atol=1e-12)
    assert np.allclose(a.inertia, b.inertia, rtol=1e-9, atol=1e-14)


# ----------------------------------------------------------------------------------------------- print model
def test_layer_core_of_a_block_with_a_hole_is_the_closed_form(pm):
    """Side walls W (3 loops, see W), skins 5 x 0.2 on top and 4 x 0.2 below: a prism core, a bigger hole."""
    solid = Box(40, 30, 20) - Cylinder(5, 20)
    core = mp.layer_core(mp.tessellate(solid, 0.01, 5), np.eye(3), pm, 0.2)
    w, h = W, 20 - 1.0 - 0.8
    V = (40 - 2 * w) * (30 - 2 * w) * h - math.pi * (5 + w) ** 2 * h
    assert core.props.volume_mm3 == pytest.approx(V, rel=2e-3)
    # the core sits 0.1 mm low: 0.8 mm skin below, 1.0 mm above
    assert core.props.centroid_mm[2] == pytest.approx(-0.1, abs=0.02)


def test_layer_core_follows_the_print_orientation(pm):
    """Printed on its side (Rx 90 deg), the 30 mm side is vertical: skins on y, walls on x and z."""
    solid = Box(40, 30, 20)
    R = mp.rotation_matrix((90, 0, 0))
    core = mp.layer_core(mp.tessellate(solid, 0.01, 5), R, pm, 0.2)
    V = (40 - 2 * W) * (30 - 1.8) * (20 - 2 * W)
    assert core.props.volume_mm3 == pytest.approx(V, rel=2e-3)
    # up in print = -y in the body frame (R maps +z to -y? no: body -> print, so print up = R^T e_z)
    up = R.T @ [0, 0, 1]
    offset = np.dot(core.props.centroid_mm, up)
    assert offset == pytest.approx(-0.1, abs=0.02)


def band_mm2(a, b, o=0.25 * 0.45):
    """Area of the infill-overlap band inside an a x b rectangle."""
    return a * b - (a - 2 * o) * (b - 2 * o)


def test_printed_box_mass_and_inertia_closed_form(pm):
    """40 x 30 x 20 block, 100 layers of 0.2 mm: solid minus 0.8 x core ((40 - 2W) x (30 - 2W) x 18.2, 0.1 mm
    low), plus the infill-overlap band inside the (40 - 2W) x (30 - 2W) inner contour (density 1 in the 9 skin layers, 0.2
    elsewhere), plus the first top skin layer laid as a bridge over the sparse infill (1.396 x plastic)."""
    solid = Box(40, 30, 20)
    part = PartSpec("block", solid, 0, "test")
    r = mp.part_mass(part, pm, mp.tessellate(solid, 0.01, 5), 0.2)
    a, b, c = 40e-3, 30e-3, 20e-3
    ca, cb, cc = a - 2 * W * 1e-3, b - 2 * W * 1e-3, c - 1.8e-3
    k = 1 - pm.infill_fraction
    z = np.array([(i + 0.5) * 0.2 - 10.0 for i in range(100)])            # layer mid-heights, body z [mm]
    wts = np.where((np.arange(100) < 4) | (np.arange(100) >= 95), 1.0, 0.2)
    band = band_mm2(40 - 2 * W, 30 - 2 * W) * 0.2 * wts                                 # [mm^3] per layer
    bridge = (mp.bridge_flow_factor(0.4, 0.2) - 1) * (40 - 2 * W) * (30 - 2 * W) * 0.2     # layer 95 [mm^3]
    assert mp.bridge_flow_factor(0.4, 0.2) == pytest.approx(math.pi * 0.04 / (0.45 * 0.2))
    V_extra = (band.sum() + bridge) * 1e-9
    m_s, m_c = RHO * a * b * c, RHO * ca * cb * cc
    m = m_s - k * m_c + RHO * V_extra
    assert r.inertial.mass_kg == pytest.approx(m, rel=1e-3)
    assert r.volume_material_m3 == pytest.approx(a * b * c - k * ca * cb * cc + V_extra, rel=1e-3)
    assert r.volume_core_m3 == pytest.approx(ca * cb * cc, rel=1e-3)
    first = k * m_c * 0.1e-3 + RHO * 1e-9 * 1e-3 * (np.dot(band, z) + bridge * z[95])
    assert r.inertial.com_m[2] == pytest.approx(first / m, abs=2e-6)
    I = box_inertia(m_s, a, b, c) - k * box_inertia(m_c, ca, cb, cc)
    assert np.allclose(np.diag(r.inertial.inertia), np.diag(I), rtol=2e-2)
    assert r.flags == ()


def test_small_core_pieces_print_solid(pm):
    """A 10 x 10 mm pillar: its core section (10 - 2W = 7.515 mm)^2, grown by the 0.1125 mm overlap the slicer
    counts, is 59.9 mm^2 < 70 mm^2, so the slicer fills it solid (and the solid infill overlaps the perimeters
    by 0.1125 mm on all 100 layers)."""
    solid = Box(10, 10, 20)
    r = mp.part_mass(PartSpec("pillar", solid, 0, "test"), pm, mp.tessellate(solid, 0.01, 5), 0.2)
    assert r.volume_core_m3 == 0.0
    V = 2000.0 + band_mm2(10 - 2 * W, 10 - 2 * W) * 0.2 * 100
    assert r.inertial.mass_kg == pytest.approx(RHO * V * 1e-9, rel=1e-4)
    assert any("empty" in f for f in r.flags)


def test_thin_shell_prints_solid(pm):
    """A square tube with walls of 2 mm < 2 W = 2.485 mm: no core at all."""
    solid = Box(40, 40, 40) - Box(36, 36, 40)
    r = mp.part_mass(PartSpec("shell", solid, 0, "test"), pm, mp.tessellate(solid, 0.01, 5), 0.2)
    assert r.volume_core_m3 == 0.0
    assert r.overlap is None
    assert r.inertial.mass_kg == pytest.approx(RHO * solid.volume * 1e-9, rel=1e-9)


def test_occ_offset_model_is_the_uniform_offset(pm):
    """The second model: uniform offset w everywhere (skins thinner than w do not matter)."""
    solid = Box(40, 30, 20)
    core = mp.occ_core(solid, np.array([0, 0, 1.0]), pm)
    assert core.props.volume_mm3 == pytest.approx((40 - 2 * W) * (30 - 2 * W) * (20 - 2 * W), rel=1e-6)


def test_voxel_fallback_is_close(pm):
    solid = Box(40, 30, 20)
    core = mp.voxel_core(mp.tessellate(solid, 0.01, 5), np.eye(3), pm)
    V = (40 - 2.7) * (30 - 2.7) * (20 - 1.8)
    assert core.props.volume_mm3 == pytest.approx(V, rel=0.08)


def test_fallback_chain_flags_the_part(pm, monkeypatch):
    """When the layer model fails the next one is used and the part says so."""
    def broken(*a, **k):
        raise ValueError("mesh is not a manifold")
    monkeypatch.setattr("swiftfin.exports.print_model.layer_core", broken)   # find_core looks it up there
    solid = Box(40, 30, 20)
    r = mp.part_mass(PartSpec("block", solid, 0, "test"), pm, mp.tessellate(solid, 0.01, 5), 0.2)
    assert any(f.startswith("core:layers failed") for f in r.flags)
    assert "offset" in r.method


def test_bought_part_uses_the_catalogue_mass(pm):
    solid = Pos(-100, 0, 5) * Box(48.5, 26.5, 17.5)
    r = mp.part_mass(PartSpec("battery", solid, 0, "bought", printed=False, mass_kg=0.046), pm)
    assert r.inertial.mass_kg == 0.046
    assert np.allclose(r.inertial.inertia, box_inertia(0.046, 0.0485, 0.0265, 0.0175), rtol=1e-9, atol=1e-14)
    with pytest.raises(BuildError, match="battery"):
        mp.part_mass(PartSpec("battery", solid, 0, "bought", printed=False, mass_kg=None), pm)


# ----------------------------------------------------------------------------------------------- gate
def test_check_tensor_refuses_bad_tensors():
    good = box_inertia(1, 0.1, 0.2, 0.3)
    mp.check_tensor("ok", good, 1.0)
    with pytest.raises(BuildError, match="positive-definite"):
        mp.check_tensor("neg", np.diag([1e-3, 1e-3, -1e-5]), 1.0)
    with pytest.raises(BuildError, match="triangle"):
        mp.check_tensor("tri", np.diag([1e-3, 1e-3, 3e-3]), 1.0)
    with pytest.raises(BuildError, match="symmetric"):
        bad = good.copy()
        bad[0, 1] += 1e-4
        mp.check_tensor("asym", bad, 1.0)


def test_tiny_inertia_survives_the_json_round_trip():
    import json
    tiny = 3.141592653589793e-11
    assert json.loads(json.dumps({"i": tiny}))["i"] == tiny


# ----------------------------------------------------------------------------------------------- cables
def test_rod_inertia_closed_form():
    it = mp.rod_inertial(0.01, (0, 0, 0), (0.3, 0, 0), 0.0005)
    assert np.allclose(it.com, [0.15, 0, 0])
    across = 0.01 * (3 * 0.0005**2 + 0.09) / 12
    assert np.allclose(np.diag(it.inertia), [0.01 * 0.0005**2 / 2, across, across], rtol=1e-12)


def test_cable_mass_is_linear_density_times_length(default_params):
    from swiftfin.layout import geometry as layout
    p = default_params
    cables = mp.cable_masses(p)
    length = sum(r.length_mm for r in layout.cable_routes(p)) / 1000
    wraps = p.joints.count * 2 * p.spool.wraps * math.pi * p.spool.drum_diameter_mm / 1000
    total = sum(c.inertial.mass_kg for c in cables)
    assert total == pytest.approx(p.cable.linear_density_g_m / 1000 * (length + wraps), rel=1e-9)
    # cables run from the head through every link ahead of the last joint; they end on the last joint's
    # tendon sector, on its axis, so the last link carries none
    assert {c.link for c in cables} == set(range(p.joints.count))


# ----------------------------------------------------------------------------------------------- slicer
@pytest.mark.slow
@pytest.mark.slicer
def test_printed_volume_matches_prusaslicer_for_every_printed_part(default_params, default_parts, default_slices,
                                                                   capsys):
    """The predicted plastic volume of every printed part of the default design is within 5 % of the
    filament PrusaSlicer extrudes for it, slicing the part's 3MF alone: no settings on the command line, only
    the [print] settings the 3MF carries (issue 15; exports/files.threemf_bytes, exports/slicer.py). The slices
    are the session's (conftest.default_slices)."""
    p = default_params
    pm = mp.PrintModel.from_params(p)
    rows = []
    for part in default_parts:
        if not part.printed:
            continue
        export, sliced = default_slices[part.label]
        part = dataclasses.replace(part, print_rotation=tuple(export.print_rotation))   # as sliced (the pipeline's)
        mesh = mp.tessellate(part.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
        pred = mp.part_mass(part, pm, mesh, p.print.layer_height_mm).volume_material_m3 * 1e9
        got = sliced.filament_mm3
        rows.append((part.label, pred, got, 100 * (pred / got - 1)))
    assert len(rows) == len(default_slices)
    with capsys.disabled():
        print("\n| part | predicted [mm^3] | PrusaSlicer [mm^3] | error [%] |\n|---|---:|---:|---:|")
        for label, pred, got, err in rows:
            print(f"| {label} | {pred:.0f} | {got:.0f} | {err:+.2f} |")
    bad = [r for r in rows if abs(r[3]) > 5.0]
    assert not bad, bad


def test_ptfe_tube_mass_is_tube_section_times_the_tubes_length(default_params):
    """The PTFE pieces (cad.cables.tube_runs: the guide channels and the bulkhead bores, mouth to seat): mass =
    rho pi (OD^2 - ID^2) / 4 x their length. The guides' share is checked against the channel centre lines
    measured independently on the B-rep wire (build123d) clipped by a slab of each block's x range: a tube stops a
    shoulder short of the face it leaves by and starts at the face (or the spool's keep-out) it comes in by, so each
    one is shorter than its channel's clipped length by at least the shoulder and at most the shoulder plus two tube
    diameters (a slanted face)."""
    import build123d as bd
    from swiftfin.cad.cables import tube_runs
    from swiftfin.cad.guide import channel_path
    from swiftfin.layout.guide_plan import guide_blocks
    from swiftfin.layout.geometry import tube_seat_shoulder_mm
    p = default_params
    g = p.guides
    rho_l = g.ptfe_density_kg_m3 * math.pi * (g.ptfe_tube_od_mm**2 - g.ptfe_tube_id_mm**2) / 4 * 1e-6   # kg/m
    runs = tube_runs(p)
    tubes = mp.ptfe_tube_masses(p)
    total = sum(t.inertial.mass_kg for t in tubes)
    assert total == pytest.approx(rho_l * sum(t.length_mm for t in runs) / 1000, rel=1e-9)
    by_link = {}
    for t in runs:
        by_link[t.link] = by_link.get(t.link, 0.0) + rho_l * t.length_mm / 1000
    assert {t.link: t.inertial.mass_kg for t in tubes} == pytest.approx(by_link, rel=1e-9)
    shoulder = tube_seat_shoulder_mm(p)
    for b in guide_blocks(p):
        x_lo, x_hi = b.x_mm
        slab = bd.Solid.make_box(x_hi - x_lo, 2000, 2000).translate((x_lo, -1000, -1000))
        for joint, side in {(ch.joint, ch.side) for ch in b.channels}:
            chans = [ch for ch in b.channels if (ch.joint, ch.side) == (joint, side)]
            brep = sum(e.length for ch in chans for e in channel_path(ch).intersect(slab).edges())
            for a, c in zip(chans[:-1], chans[1:]):      # a lane's drop and turn share the straight between them
                if np.allclose(a.p_out, c.t1):
                    brep -= sum(e.length for e in bd.Edge.make_line(a.t2, c.t1).intersect(slab).edges())
            (tube,) = [t for t in runs if t.holder == b.label and (t.joint, t.side) == (joint, side)]
            assert shoulder - 1e-6 <= brep - tube.length_mm <= shoulder + 2 * g.ptfe_tube_od_mm, (tube.label, brep)
    for t in tubes:
        mp.check_tensor(t.label, t.inertial.inertia, t.inertial.mass_kg)     # raises if not a valid tensor


# ----------------------------------------------------------------------------------------------- flooding & trim
def test_envelope_inertial_matches_the_envelope_volume_and_centroid(default_params):
    """Two independent integrations of the hull envelope (slice discs here, 4001-point quadrature in
    envelope_volume_mm3) agree; the inertia is positive-definite and slender (I_xx the smallest)."""
    p = default_params
    s0, s1 = layout.joint_stations_mm(p)[0], layout.joint_stations_mm(p)[1]
    it = mp.envelope_inertial(p, s0, s1, 1000.0)
    V_mm3, s_c = mp.envelope_volume_mm3(p, s0, s1)
    assert it.mass_kg == pytest.approx(1000.0 * V_mm3 * 1e-9, rel=1e-4)
    assert it.com[0] == pytest.approx(-s_c / 1000, rel=1e-5)
    mp.check_tensor("envelope", it.inertia, it.mass_kg)


@pytest.mark.parametrize("ballast_link_flooded", [True, False])
def test_trim_ballast_makes_the_fish_neutral_and_level(default_params, ballast_link_flooded):
    """The ballast solves both equations exactly: M + m = rho (V + v) and COM_x = COB_x after adding it
    (v = m / rho_fill in a flooded link, 0 in a sealed one; the fill is lead shot at a 0.60 packing in epoxy of
    1150 kg/m^3, worked here by hand from the lead's density)."""
    p = default_params
    rho = p.environment.water_density_kg_m3
    rho_b = 0.6 * p.environment.ballast_density_kg_m3 + 0.4 * 1150.0
    M, V = 1.70, 1.72e-3
    com, cob = np.array([-0.170, 0, -0.008]), np.array([-0.172, 0, 0.0])
    flooded = (False,) + (ballast_link_flooded,) * p.joints.count
    t = mp.trim_ballast(p, M, com, V, cob, flooded)
    assert t["possible"] and t["in_flooded_link"] == ballast_link_flooded
    m = t["mass_kg"]
    v = m / rho_b if ballast_link_flooded else 0.0
    assert M + m == pytest.approx(rho * (V + v), rel=1e-12)
    x = t["x_m"]
    assert (M * com[0] + m * x) / (M + m) == pytest.approx((V * cob[0] + v * x) / (V + v), abs=1e-12)
    assert x < cob[0]                                    # nose-heavy: the ballast goes aft of the COB
    assert t["z_m"] < 0                                  # on the hull floor


def _sphere(m, c, r):
    return mp.make_inertial(m, c, 0.4 * m * r * r * np.eye(3))


@pytest.mark.parametrize("ixz", [3.2e-4, -1.5e-4, 4e-3])
def test_ballast_height_zeroes_its_links_product_of_inertia(ixz):
    """The ballast goes where its link (a body with a given I_xz) and it have no product of inertia about
    their common COM, checked by summing the two bodies here with the parallel-axis sum (combine); where the
    room does not reach that height, it sits at the room's edge on the side that helps, and does better than
    the floor."""
    link = mp.make_inertial(1.5, (-0.15, 0.0, -0.008), [[1.1e-3, 0, ixz], [0, 7.8e-3, 0], [ixz, 0, 7.4e-3]])
    m, r = 0.056, 0.0106
    trim = {"mass_kg": m, "x_m": -0.052, "z_room_m": 0.036, "sphere_radius_mm": 1000 * r}
    t = mp.ballast_height(trim, link)
    both = mp.combine([link, _sphere(m, (trim["x_m"], 0.0, t["z_m"]), r)])
    floor = mp.combine([link, _sphere(m, (trim["x_m"], 0.0, -0.036), r)])
    assert -0.036 <= t["z_m"] <= 0.036
    assert t["link_ixz_kg_m2"] == pytest.approx(both.inertia[0, 2], abs=1e-12)
    assert t["link_ixz_on_floor_kg_m2"] == pytest.approx(floor.inertia[0, 2], abs=1e-12)
    if abs(t["z_m"]) < 0.036 - 1e-12:
        assert abs(both.inertia[0, 2]) < 1e-12 * abs(ixz) + 1e-15
    else:                                                # out of reach (4e-3): as near as the room allows
        assert abs(both.inertia[0, 2]) < abs(floor.inertia[0, 2]) or t["z_m"] == -0.036
        assert abs(both.inertia[0, 2]) < abs(ixz)


def test_the_ballast_keeps_clear_of_the_parts_and_refuses_when_boxed_in():
    """A part's box across the wanted height pushes the sphere to the nearest free height (the gap: its radius and
    the clearance); boxes filling the room leave no height, and the trim says so with the part's name."""
    link = mp.make_inertial(1.5, (-0.15, 0.0, -0.008), [[1.1e-3, 0, 1.5e-4], [0, 7.8e-3, 0], [1.5e-4, 0, 7.4e-3]])
    trim = {"possible": True, "mass_kg": 0.056, "x_m": -0.052, "z_room_m": 0.036, "sphere_radius_mm": 10.6}
    free = mp.ballast_height(trim, link)
    box = ("board", ((-0.067, -0.0075, -0.0225), (-0.037, 0.0075, 0.0225)))
    t = mp.ballast_height(trim, link, [box], 0.0005)
    assert t["possible"] and t["clear_of"] == ("board",)
    assert t["z_m"] == pytest.approx(0.0225 + 0.0106 + 0.0005, abs=1e-12)     # above the board: nearer the want
    assert abs(free["z_m"] - t["z_m"]) > 0.01
    aside = ("aside", ((-0.067, 0.02, -0.03), (-0.037, 0.03, 0.03)))           # beside the sphere's path: no bar
    assert mp.ballast_height(trim, link, [aside], 0.0005)["z_m"] == free["z_m"]
    full = ("block", ((-0.067, -0.0075, -0.03), (-0.037, 0.0075, 0.03)))
    t = mp.ballast_height(trim, link, [full], 0.0005)
    assert not t["possible"] and "block" in t["reason"]


def test_the_default_ballast_leaves_its_link_without_yaw_roll_coupling(default_robot, default_params):
    """Default design: the trim ballast is the fill of lead shot poured into the nose (swiftfin/ballast.py), the
    highest the trim's level station allows (the height that would zero its link's I_xz is above the nose's room);
    the head (with the water it carries: the body MuJoCo moves) has less than half the I_xz the same lead would give
    it on the hull floor under the fill's centre (worked here with the parallel-axis algebra, not the plan).
    What the rest costs is measured where it shows, in MuJoCo (tests/test_mujoco_swim.py: 30 s free at the design
    frequency, pitch under 5 deg)."""
    p = default_params
    _, res = default_robot
    rep = res["report"]
    t = rep.trim
    assert t["placed"] == "fill"
    wet = res["robot"].links[t["link"]].in_water(p.environment.water_density_kg_m3)[0]
    fill = next(pt for pt in rep.parts if pt.label == "trim_ballast")
    m, c = fill.inertial.mass_kg, np.asarray(fill.inertial.com, float)
    assert c[2] > 0                                              # in the upper half, over the electronics
    a, b = (float(v) for v in mp.envelope_section_mm(p, -1000 * c[0]))
    floor = mp.make_inertial(m, (c[0], 0.0, -(b - p.hull.wall_thickness_mm) / 1000), np.zeros((3, 3)))
    on_floor = mp.combine([wet, fill.inertial.scaled_mass(-1.0), floor])
    assert abs(on_floor.inertia[0, 2]) > 2 * abs(wet.inertia[0, 2])


def test_the_trims_margin_is_the_mass_that_pushes_the_lead_out_of_the_hull(default_params):
    """``trim_margin_kg``: the mass added at a station that the trim can still level. Just under it trim_ballast
    places its lead, just over it not; the lead it places then sits where the level condition of a sealed link puts
    it, x = (rho V x_cob - M x_com - dm x_add) / (rho V - M - dm), worked here by hand, not by trim_ballast."""
    p = default_params
    rho = p.environment.water_density_kg_m3
    M, V = 1.82, 1.857e-3
    com, cob = np.array([-0.1786, 0.0, -0.006]), np.array([-0.1757, 0.0, 0.0])
    flooded = (False,) + (True,) * p.joints.count
    x_add = -0.152                                        # the head's centre, roughly
    margin = mp.trim_margin_kg(p, M, com, V, cob, flooded, x_add)
    assert 0.0 < margin < rho * V - M

    def trim(dm):
        c = (M * com + dm * np.array([x_add, 0.0, 0.0])) / (M + dm)
        return mp.trim_ballast(p, M + dm, c, V, cob, flooded)

    for dm in (0.0, 0.5 * margin, margin - 2e-5):
        t = trim(dm)
        assert t["possible"]
        x = (rho * V * cob[0] - M * com[0] - dm * x_add) / (rho * V - M - dm)
        assert t["x_m"] == pytest.approx(x, abs=1e-12) and t["mass_kg"] == pytest.approx(rho * V - M - dm, abs=1e-12)
    assert not trim(margin + 2e-5)["possible"]
    # mass added at the lead's own station does not move it: the margin there is the whole excess buoyancy
    x0 = trim(0.0)["x_m"]
    assert mp.trim_margin_kg(p, M, com, V, cob, flooded, x0) == pytest.approx(rho * V - M)
    # no lead trims a sinking fish: no margin
    assert mp.trim_margin_kg(p, 2.0, com, 1.5e-3, cob, flooded, x_add) == 0.0


def test_trim_ballast_refuses_a_sinking_fish(default_params):
    t = mp.trim_ballast(default_params, 2.0, (-0.17, 0, 0), 1.5e-3, (-0.17, 0, 0), (False,) * 5)
    assert not t["possible"] and "sinks" in t["reason"]


@pytest.mark.parametrize("x_end", [-20.0, -40.0])
def test_the_piece_behind_a_plane_by_difference_is_the_piece_cut(x_end):
    """exports/water._outside_piece: a part mostly behind the plane is integrated ahead of it and taken from the
    whole; the same numbers as the piece cut and integrated, and as the closed form of a box."""
    from swiftfin.exports.brep import solid_volume_props
    from swiftfin.exports.water import _outside_piece
    part = PartSpec("block", Pos(-30, 2, 3) * Box(40, 20, 30), 4, "fin")     # x from -50 to -10
    whole = solid_volume_props(part.solid)
    cut = _outside_piece(part, x_end, 400.0)                       # cut and integrated
    diff = _outside_piece(part, x_end, 400.0, lambda: whole)       # the whole less the piece ahead
    a, b, c = x_end + 50, 20.0, 30.0                                # the box behind the plane
    V = a * b * c
    closed = np.diag([V * (b * b + c * c), V * (a * a + c * c), V * (a * a + b * b)]) / 12
    for pr in (cut, diff):
        assert pr.volume_mm3 == pytest.approx(V, rel=1e-9)
        assert np.allclose(pr.centroid_mm, (-50 + a / 2, 2, 3), atol=1e-7)
        assert np.allclose(pr.second_moment_mm5, closed, rtol=1e-9, atol=1e-6 * closed.max())
