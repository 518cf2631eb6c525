"""Robot exports: one model -> URDF, MJCF, SDF; loaded by the real simulators (MuJoCo, PyBullet, Drake).

``mini``: a stand-in design of boxes at the real layout's stations (fast); ``default``: the real parts of the
default design (slow). Masses and inertias read back from every simulator are compared with ours.
"""
from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from swiftfin.layout import geometry as layout
from swiftfin.exports import massprops
from swiftfin.exports.mjcf import buoyancy_split
from swiftfin.exports.robot import write_robot
from swiftfin.core.errors import BuildError
from tests.conftest import require_module
from tests.robot_helpers import mini_parts, mujoco_link_inertial


@pytest.fixture(scope="module", params=["mini", pytest.param("default", marks=pytest.mark.slow)])
def built(request, tmp_path_factory, default_params):
    p = default_params
    # the real parts come from the session fixture (built once for every test module that needs them)
    if request.param == "default":      # written once per session (conftest.default_robot)
        out, res = request.getfixturevalue("default_robot")
        return p, request.getfixturevalue("default_parts"), out, res
    parts = mini_parts(p)
    out = tmp_path_factory.mktemp(f"robot_{request.param}")
    res = write_robot(p, parts, out)
    return p, parts, out, res


def _links(res):
    return {lk.name: lk for lk in res["report"].links}


def test_flooded_links_carry_the_water_their_envelope_holds(built):
    """A flooded link's displaced volume (its parts' solids) plus the volume of the water it carries is its hull
    envelope between its joints (plus, for the fin's link, the fin behind the hull end); the water's inertia is a
    valid tensor. The last sealed link too: dry up to its rear wall, then the joint gap's water round its lugs."""
    from swiftfin.layout.hull_plan import dry_bulkhead
    p, parts, out, res = built
    rep = res["report"]
    rho = p.environment.water_density_kg_m3
    bounds = [0.0, *layout.joint_stations_mm(p), layout.hull_end_mm(p)]
    V_fin, _, fin_link, _ = massprops._fin_outside_volume(p, parts)
    assert any(rep.link_flooded) and not rep.link_flooded[0]
    last_sealed = p.hull.flooded_from_joint - 1
    for j, (flooded, V, w) in enumerate(zip(rep.link_flooded, rep.link_displaced_volume_m3, rep.link_entrained_water)):
        if not flooded and (j != last_sealed or dry_bulkhead(p).rear_joint is None):
            assert w is None
            continue
        assert w is not None, j
        env_m3 = massprops.envelope_volume_mm3(p, bounds[j], bounds[j + 1])[0] * 1e-9
        fin_m3 = V_fin * 1e-9 if j == fin_link else 0.0
        assert V + w.mass_kg / rho == pytest.approx(env_m3 + fin_m3, rel=2e-3), j
        massprops.check_tensor(f"water {j}", w.inertia, w.mass_kg)


def test_files_written(built):
    p, parts, out, res = built
    for name in ("swiftfin.urdf", "swiftfin.xml", "swiftfin.sdf"):
        assert (out / "robot" / name).is_file()
    for lk in res["report"].links:
        assert (out / "robot" / "meshes" / f"{lk.name}_visual.obj").is_file()
        assert (out / "robot" / "meshes" / f"{lk.name}_collision_0.obj").is_file()
    data = json.loads((out / "mass_properties.json").read_text())
    labels = {pt["label"] for pt in data["parts"]}
    assert labels - {pt.label for pt in parts} == ({c.label for c in massprops.cable_masses(p)}
                                                   | {t.label for t in massprops.ptfe_tube_masses(p)}
                                                   | {f.label for f in massprops.fastener_masses(p)}
                                                   | {h.label for h in massprops.harness_masses(p)}
                                                   | ({"trim_ballast"} if data["trim"].get("possible")
                                                      and not data["trim"].get("placed") else set()))
    assert sum(lk["mass_kg"] for lk in data["links"]) == pytest.approx(data["total"]["mass_kg"], rel=1e-12)
    for lk in data["links"]:
        lo, hi = lk["ranges"]["mass_kg"]
        assert lo < lk["mass_kg"] < hi
        lo, hi = lk["ranges"]["izz_kg_m2"]
        assert lo < lk["inertia_kg_m2"]["izz"] < hi
    assert data["total"]["paper_mass_kg"] == 1.2
    assert data["print_settings"]["perimeters"] == p.print.perimeters


def test_meshes_are_in_metres_and_within_budget(built):
    p, parts, out, res = built
    L = p.body.length_mm / 1000
    for f in (out / "robot" / "meshes").glob("*.obj"):
        lines = f.read_text().splitlines()
        v = np.array([[float(x) for x in ln.split()[1:]] for ln in lines if ln.startswith("v ")])
        nf = sum(1 for ln in lines if ln.startswith("f "))
        assert 0.001 < np.abs(v).max() < L, f.name       # link frame, metres: nothing beyond a body length
        if "visual" in f.name:
            assert nf <= p.export.visual_triangle_budget


def test_urdf_inertials_at_com_full_tensor_every_digit(built):
    p, parts, out, res = built
    root = ET.parse(out / "robot" / "swiftfin.urdf").getroot()
    links = _links(res)
    for el in root.findall("link"):
        lk = links[el.get("name")]
        org = el.find("inertial/origin")
        assert [float(v) for v in org.get("xyz").split()] == list(lk.inertial.com_m)   # exact round trip
        assert [float(v) for v in org.get("rpy").split()] == [0.0, 0.0, 0.0]
        assert float(el.find("inertial/mass").get("value")) == lk.inertial.mass_kg
        I = el.find("inertial/inertia")
        M = lk.inertial.inertia
        for k, (i, j) in {"ixx": (0, 0), "iyy": (1, 1), "izz": (2, 2), "ixy": (0, 1), "ixz": (0, 2),
                          "iyz": (1, 2)}.items():
            assert float(I.get(k)) == M[i, j]
    stops = layout.joint_stop_angles_rad(p)
    for j, el in enumerate(root.findall("joint")):
        assert el.get("type") == "revolute"
        assert float(el.find("limit").get("upper")) == pytest.approx(stops[j], rel=1e-12)
        x = float(el.find("origin").get("xyz").split()[0])
        prev = 0.0 if j == 0 else layout.joint_stations_mm(p)[j - 1]
        assert x == pytest.approx(-(layout.joint_stations_mm(p)[j] - prev) / 1000, rel=1e-12)


def test_link_with_products_of_inertia(built):
    """link_1's tensor is not diagonal (the mini design's block is turned 30 deg; the real link_1 carries parts
    above and behind its axis): the exports must carry its products of inertia."""
    p, parts, out, res = built
    I = _links(res)["link_1"].inertial.inertia
    assert np.abs(I - np.diag(np.diag(I))).max() > 1e-3 * np.abs(I).max()


def _mujoco_model(out):
    mujoco = require_module("mujoco", "MuJoCo (the mujoco package) is needed to load the MJCF")
    return mujoco, mujoco.MjModel.from_xml_path(str(out / "robot" / "swiftfin.xml"))


def test_mujoco_compiles_without_warnings_and_matches(built):
    p, parts, out, res = built
    mujoco, model = _mujoco_model(out)
    data = mujoco.MjData(model)
    for _ in range(200):
        mujoco.mj_step(model, data)
    assert all(w.number == 0 for w in data.warning), [mujoco.mjtWarning(i).name for i, w in
                                                      enumerate(data.warning) if w.number]
    root = ET.parse(out / "robot" / "swiftfin.xml").getroot()
    rho = p.environment.water_density_kg_m3
    for name, lk_dry in _links(res).items():
        # MuJoCo's model is the fish in water: a flooded link carries the water inside it
        inertial, V, cob = res["robot"].link(name).in_water(rho)
        # each link is its body plus a welded buoyancy body at its centre of buoyancy (exports/mjcf.py)
        got = mujoco_link_inertial(mujoco, model, name)
        assert got.mass_kg == pytest.approx(inertial.mass_kg, rel=1e-6)
        assert np.allclose(got.com, inertial.com, rtol=1e-6, atol=1e-12)
        I = inertial.inertia
        assert np.allclose(got.inertia, I, rtol=1e-6, atol=1e-6 * np.abs(I).max())
        # MuJoCo's fullinertia order: ixx iyy izz ixy ixz iyz, of the link body's share
        main, buoy, gravcomp = buoyancy_split(inertial, cob, V, rho)
        el = root.find(f".//body[@name='{name}']/inertial")
        full = [float(v) for v in el.get("fullinertia").split()]
        Im = main.inertia
        assert full == [Im[0, 0], Im[1, 1], Im[2, 2], Im[0, 1], Im[0, 2], Im[1, 2]]
        # buoyancy: the buoyancy body at the COB lifts rho_w V g (V: the link's displacement plus its water's)
        b = model.body(f"{name}_buoyancy")
        assert model.body_gravcomp[b.id] * b.mass[0] == pytest.approx(rho * V, rel=1e-9)
        assert np.allclose(b.pos, cob, atol=1e-12)
        assert model.body_gravcomp[model.body(name).id] == 0.0
        assert np.allclose(model.site(f"{name}_cob").pos, cob, atol=1e-12)
        if res["robot"].link(name).entrained_water is None:
            assert inertial is lk_dry.inertial
    assert model.opt.density == p.environment.water_density_kg_m3
    assert model.opt.viscosity == p.environment.water_viscosity_pa_s
    stops = layout.joint_stop_angles_rad(p)
    for j in range(p.joints.count):
        jt = model.joint(f"joint_{j + 1}")
        assert np.allclose(jt.range, [-stops[j], stops[j]])
        assert model.tendon(f"cable_{j + 1}") is not None
    assert model.nu == p.joints.count
    assert sum(1 for g in range(model.ngeom) if model.geom_fluid[g, 0] > 0) >= p.joints.count + 1


def test_pybullet_loads_the_urdf_with_the_same_masses(built):
    p, parts, out, res = built
    pybullet = require_module("pybullet", "PyBullet is needed to load the URDF")
    cid = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(out / "robot" / "swiftfin.urdf"), flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                 physicsClientId=cid)
        names = {-1: pybullet.getBodyInfo(body, physicsClientId=cid)[0].decode()}
        for j in range(pybullet.getNumJoints(body, physicsClientId=cid)):
            names[j] = pybullet.getJointInfo(body, j, physicsClientId=cid)[12].decode()
        links = _links(res)
        assert set(names.values()) == set(links)
        for idx, name in names.items():
            info = pybullet.getDynamicsInfo(body, idx, physicsClientId=cid)
            lk = links[name]
            assert info[0] == pytest.approx(lk.inertial.mass_kg, rel=1e-6)
            assert sorted(info[2]) == pytest.approx(sorted(np.linalg.eigvalsh(lk.inertial.inertia)), rel=1e-5)
    finally:
        pybullet.disconnect(cid)


@pytest.mark.parametrize("fname", ["swiftfin.sdf", "swiftfin.urdf"])
def test_drake_parses(built, fname):
    p, parts, out, res = built
    require_module("pydrake", "Drake (the drake package) is needed to parse the SDF/URDF")
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.SetStrictParsing()          # warnings become errors
    parser.AddModels(str(out / "robot" / fname))
    plant.Finalize()
    for name, lk in _links(res).items():
        b = plant.GetBodyByName(name)
        assert b.default_mass() == pytest.approx(lk.inertial.mass_kg, rel=1e-9)
        si = b.default_spatial_inertia()
        assert np.allclose(si.get_com(), lk.inertial.com_m, rtol=1e-9, atol=1e-12)
    assert plant.num_positions() == 7 + p.joints.count


def test_failed_gate_leaves_no_robot_folder(default_params, tmp_path, monkeypatch):
    def fail(*a, **k):
        raise BuildError("link head: inertia tensor not positive-definite")
    monkeypatch.setattr(massprops, "validate", fail)
    with pytest.raises(BuildError, match="positive-definite"):
        write_robot(default_params, mini_parts(default_params), tmp_path)
    assert not (tmp_path / "robot").exists()
    assert not (tmp_path / "mass_properties.json").exists()
    assert not any(tmp_path.iterdir())


def test_gate_catches_a_mesh_that_disagrees(default_params, tmp_path):
    """The exported mesh of a part scaled by 1.02 (6 % volume) is refused, naming the part."""
    p = default_params
    parts = mini_parts(p)
    meshes = {pt.label: massprops.tessellate(pt.solid, 0.05, 10) for pt in parts}
    bad = parts[0].label
    m = meshes[bad].copy()
    m.apply_scale(1.02)
    meshes[bad] = m
    with pytest.raises(BuildError, match=bad):
        write_robot(p, parts, tmp_path, meshes=meshes)
    assert not (tmp_path / "robot").exists()


def test_units_in_the_files_are_si(built):
    """Total mass ~ kilograms, link COMs within a body length of the nose, in metres."""
    p, parts, out, res = built
    L = p.body.length_mm / 1000
    for lk in res["report"].links:
        assert np.all(np.abs(lk.com_body_m) < L)
    assert 0.01 < res["total_mass_kg"] < 10
    assert math.isfinite(res["buoyancy_n"])


def test_collision_shapes_fit_the_parts(built, capsys):
    """One convex hull per part (issue 15): each link's collision volume (the hulls' volumes added, overlaps
    counted twice) within 4x its parts' solid volume, and the tail link's, where one hull over the stem and the
    fin was 6.3x, within 3x. The hulls of hull shells fill the shells: a contact shape of the outside."""
    import trimesh

    p, parts, out, res = built
    labels = {pt.label for pt in parts}
    rows = []
    for lk in res["report"].links:
        files = sorted((out / "robot" / "meshes").glob(f"{lk.name}_collision_*.obj"))
        members = [pt for pt in res["report"].parts if pt.link == lk.index and pt.label in labels]
        assert len(files) == len(members)
        meshes = [trimesh.load(f, force="mesh") for f in files]
        assert all(m.is_watertight and m.is_convex for m in meshes)
        v_coll = sum(m.volume for m in meshes)
        v_solid = sum(pt.volume_solid_m3 for pt in members)
        rows.append((lk.name, len(files), v_coll, v_solid))
    with capsys.disabled():
        print("\n  link  | collision shapes | collision cm^3 | solid cm^3 | ratio")
        for name, n, vc, vs in rows:
            print(f"  {name:6s}| {n:16d} | {vc * 1e6:14.1f} | {vs * 1e6:10.1f} | {vc / vs:5.2f}")
    for name, n, vc, vs in rows:
        assert vc / vs < 4.0, name
    if "fin_plate" not in labels:                       # the real design (the mini one has a stand-in plate)
        assert rows[-1][2] / rows[-1][3] < 3.0


@pytest.mark.slow
def test_the_joint_fits_link_prior_agrees_with_the_built_links(default_robot, default_params):
    """The joint fit's prior for the link on hinge j (layout.loads.hinge_inertia: thin shells, bulkheads and a solid
    fin, no joint hardware) against the built solids' mass properties (B-rep volumes at the print model's
    densities) of the links behind the joint, about the same hinge axis (yaw, held straight), and in water the
    water the built flooded links carry. Two computations that share no code; the shells leave out the joint
    hardware, screws and inserts, so the prior is expected low, by up to 35 %."""
    from swiftfin.layout.loads import hinge_inertia
    p = default_params
    rep = default_robot[1]["report"]
    for j in range(p.joints.count):
        x_hinge = -layout.joint_stations_mm(p)[j] / 1000.0
        built = carried = 0.0
        for k, lk in enumerate(rep.links):
            if k <= j:                      # the head is link 0; links j+1.. lie behind hinge j (0-based)
                continue
            c = lk.com_body_m
            built += lk.inertial.inertia[2, 2] + lk.inertial.mass_kg * ((c[0] - x_hinge) ** 2 + c[1] ** 2)
            w = rep.link_entrained_water[k]
            if w is not None:
                cw = w.com
                carried += w.inertia[2, 2] + w.mass_kg * ((cw[0] - x_hinge) ** 2 + cw[1] ** 2)
        prior = hinge_inertia(p, j)
        assert 0.65 * built <= prior.links_kg_m2 <= built, (j, prior.links_kg_m2, built)
        assert prior.entrained_kg_m2 == pytest.approx(carried, rel=0.6), (j, prior.entrained_kg_m2, carried)


def test_coarsening_rounds_start_where_decimation_reaches_the_budget():
    from swiftfin.exports.robot import REDUCTION_REACHED, coarsening_rounds
    assert coarsening_rounds(19_000, 20_000) == 0
    assert coarsening_rounds(int(REDUCTION_REACHED * 20_000), 20_000) == 0
    assert coarsening_rounds(320_516, 20_000) == 2          # the default head: 320 516 -> ~104 000 expected
    assert coarsening_rounds(10**12, 20_000) == 7            # bounded: the last round always decimates


@pytest.mark.slow
def test_the_head_visual_mesh_skips_only_passes_that_stall(default_params, default_parts):
    """The rounds skipped on the default head would not have reached the budget: decimating the last skipped
    tessellation (deflection x2) stalls above it, so starting coarser changes no output, only the time."""
    import trimesh
    from swiftfin.exports.robot import as_trimesh, coarsening_rounds, decimate
    e = default_params.export
    head = [q for q in default_parts if q.link == 0]
    meshes = {q.label: massprops.tessellate(q.solid, e.mesh_tolerance_mm, e.mesh_angular_tolerance_deg)
              for q in head}
    n = sum(len(m.faces) for m in meshes.values())
    first = coarsening_rounds(n, e.visual_triangle_budget)
    assert first >= 1, n
    tol = e.mesh_tolerance_mm * 2 ** (first - 1)
    ang = min(45.0, e.mesh_angular_tolerance_deg * 1.5 ** (first - 1))
    finer = trimesh.util.concatenate([as_trimesh(massprops.tessellate(q.solid, tol, ang)) for q in head])
    assert len(decimate(finer, e.visual_triangle_budget).faces) > e.visual_triangle_budget
    # the round it starts from reaches the budget: test_meshes_are_in_metres_and_within_budget (the default robot)
