"""STL / 3MF / STEP writers: closed forms on a known solid, then every part of the default design."""
from __future__ import annotations

import io
import math
import zipfile

import build123d as bd
import lib3mf
import manifold3d
import numpy as np
import pytest
import trimesh

from swiftfin.exports.files import (Mesh, export_part, is_closed, print_transform, rotation_matrix, step_bytes, stl_bytes,
                           tessellate, threemf_bytes)
from swiftfin.exports.manifest import verify_manifest
from swiftfin.cache import FamilyCache
from swiftfin.pipeline import build_parts, write_outputs
from swiftfin.core.schema import Params
from tests.conftest import DEFAULT_DESIGN, session_cache_dir
from tests.golden_check import precise_volume_mm3

F32_SLACK_MM = 1e-4  # float32 rounding of STL/3MF coordinates (< 500 mm x 2^-24 = 3e-5 mm)


def tube(r_out=10.0, r_in=4.0, h=20.0):
    return bd.Cylinder(r_out, h) - bd.Cylinder(r_in, h)


def volume_bound_mm3(area_mm2: float, tol_mm: float) -> float:
    """Every triangle lies within the linear deflection ``tol`` of the surface, so the volume between mesh and
    B-rep is at most area x tol (plus the float32 rounding of the file's coordinates)."""
    return area_mm2 * (tol_mm + F32_SLACK_MM)


def read_3mf(data: bytes, tmp_path) -> Mesh:
    """Read a 3MF with lib3mf (the 3MF consortium's reference library)."""
    path = tmp_path / "x.3mf"
    path.write_bytes(data)
    model = lib3mf.get_wrapper().CreateModel()
    model.QueryReader("3mf").ReadFromFile(str(path))
    it = model.GetMeshObjects()
    assert it.MoveNext()
    obj = it.GetCurrentMeshObject()
    assert not it.MoveNext(), "one object per part"
    v = np.array([p.Coordinates[0:3] for p in obj.GetVertices()], dtype=float)
    f = np.array([t.Indices[0:3] for t in obj.GetTriangleIndices()], dtype=np.int64)
    return Mesh(v, f)


def read_stl(data: bytes) -> trimesh.Trimesh:
    return trimesh.load(io.BytesIO(data), file_type="stl")


def manifold_ok(m: trimesh.Trimesh) -> bool:
    mm = manifold3d.Mesh(vert_properties=np.asarray(m.vertices, dtype=np.float32),
                         tri_verts=np.asarray(m.faces, dtype=np.uint32))
    return manifold3d.Manifold(mm).status() == manifold3d.Error.NoError


# --------------------------------------------------------------------------------------------- closed forms
@pytest.mark.parametrize("tol", [0.2, 0.05, 0.01])
def test_tessellated_tube_volume_within_area_times_tolerance(tol):
    solid = tube()
    exact = math.pi * (10**2 - 4**2) * 20
    assert solid.volume == pytest.approx(exact, rel=1e-9)
    m = tessellate(solid, tol, 10.0)
    assert is_closed(m)
    assert abs(m.volume_mm3 - exact) <= volume_bound_mm3(solid.area, tol)
    assert m.volume_mm3 < exact  # chords of a convex outer circle cut inside it: the mesh is smaller


def test_print_orientation_rotates_then_drops_onto_the_bed_centre():
    solid = bd.Box(30, 10, 4).moved(bd.Location((-100, 7, 3)))
    m = tessellate(solid, 0.05, 10.0)
    # build123d Rotation(90, 0, 0): +y -> +z, so the 10 mm side stands up
    r = rotation_matrix((90, 0, 0))
    assert r[:3, :3] @ [0, 1, 0] == pytest.approx([0, 0, 1], abs=1e-12)
    t = print_transform(m, (90, 0, 0), 250, 210)
    lo, hi = m.transformed(t).bbox_mm
    assert lo[2] == pytest.approx(0.0, abs=1e-9)
    assert hi - lo == pytest.approx([30, 4, 10], abs=1e-9)
    assert (lo + hi)[:2] / 2 == pytest.approx([125, 105], abs=1e-9)


def test_writers_are_deterministic_and_read_back(tmp_path):
    solid = tube()
    m = tessellate(solid, 0.05, 10.0)
    m2 = tessellate(tube(), 0.05, 10.0)
    assert stl_bytes(m, "tube") == stl_bytes(m2, "tube")
    assert threemf_bytes(m, "tube") == threemf_bytes(m2, "tube")
    stl = read_stl(stl_bytes(m, "tube"))
    assert stl.is_watertight and stl.is_winding_consistent and manifold_ok(stl)
    assert stl.volume == pytest.approx(m.volume_mm3, rel=1e-5)
    tm = read_3mf(threemf_bytes(m, "tube"), tmp_path)
    assert tm.volume_mm3 == pytest.approx(m.volume_mm3, rel=1e-6)
    with zipfile.ZipFile(io.BytesIO(threemf_bytes(m, "tube"))) as z:
        assert {i.date_time for i in z.infolist()} == {(1980, 1, 1, 0, 0, 0)}
        assert 'unit="millimeter"' in z.read("3D/3dmodel.model").decode()
    step = tmp_path / "tube.step"
    step.write_bytes(step_bytes(solid, "tube"))
    back = bd.import_step(str(step))
    assert back.volume == pytest.approx(solid.volume, rel=1e-6)
    assert "PRODUCT('tube'" in step.read_text()


def test_step_is_in_millimetres(tmp_path):
    step = tmp_path / "b.step"
    step.write_bytes(step_bytes(bd.Box(10, 20, 30), "b"))
    text = step.read_text()
    assert "SI_UNIT(.MILLI.,.METRE.)" in text
    assert bd.import_step(str(step)).bounding_box().size.Z == pytest.approx(30, abs=1e-6)


# --------------------------------------------------------------------------------------------- the default design
@pytest.fixture(scope="module")
def default_build(default_params, tmp_path_factory):
    """Every part of the default design, exported and written (the assembly checks are test_assembly's)."""
    cache = FamilyCache(session_cache_dir(tmp_path_factory))
    result = build_parts(default_params, cache)
    folder = tmp_path_factory.mktemp("default-build")
    write_outputs(result, folder, DEFAULT_DESIGN)
    return result, folder


def _printed(result):
    return [b for b in result.parts if b.spec.printed]


def test_every_stl_is_watertight_manifold_and_matches_the_brep(default_build):
    result, folder = default_build
    tol = result.params.export.mesh_tolerance_mm
    assert _printed(result)
    for b in _printed(result):
        stl = read_stl((folder / "parts" / f"{b.spec.label}.stl").read_bytes())
        assert stl.is_watertight and stl.is_winding_consistent, b.spec.label
        assert manifold_ok(stl), b.spec.label
        dv = abs(stl.volume - b.export.volume_mm3)
        assert dv <= volume_bound_mm3(b.export.area_mm2, tol), (b.spec.label, dv, b.export.area_mm2 * tol)
        assert stl.bounds[0][2] == pytest.approx(0.0, abs=1e-4), f"{b.spec.label} not on the bed"


def test_every_3mf_reads_back_with_the_same_volume(default_build, tmp_path):
    result, folder = default_build
    for b in _printed(result):
        m = read_3mf((folder / "parts" / f"{b.spec.label}.3mf").read_bytes(), tmp_path)
        assert is_closed(m), b.spec.label
        stl = read_stl((folder / "parts" / f"{b.spec.label}.stl").read_bytes())
        assert m.volume_mm3 == pytest.approx(stl.volume, rel=1e-5), b.spec.label


def test_every_step_reimports_with_the_brep_volume(default_build):
    result, folder = default_build
    for b in _printed(result):
        back = bd.import_step(str(folder / "parts" / f"{b.spec.label}.step"))
        assert precise_volume_mm3(back) == pytest.approx(b.export.volume_mm3, rel=1e-6), b.spec.label
        assert len(back.solids()) == 1, b.spec.label


def test_assembly_step_holds_every_part_by_name(default_build):
    result, folder = default_build
    text = (folder / "assembly.step").read_text()
    for b in result.parts:
        assert f"PRODUCT('{b.spec.label}'" in text, b.spec.label
    back = bd.import_step(str(folder / "assembly.step"))
    assert len(back.solids()) == len(result.parts)
    assert precise_volume_mm3(back) == pytest.approx(sum(b.export.volume_mm3 for b in result.parts), rel=1e-6)


def test_manifest_hashes_match_the_files(default_build, tmp_path):
    result, folder = default_build
    assert verify_manifest(folder) == []
    # and the check can fail: one changed byte is found
    import shutil
    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    stl = next((copy / "parts").glob("*.stl"))
    data = bytearray(stl.read_bytes())
    data[100] ^= 1
    stl.write_bytes(bytes(data))
    assert verify_manifest(copy) == [f"parts/{stl.name}: SHA-256 or size differs from the manifest"]


# Two builds give the same bytes: tests/test_build.py::test_default_design_builds_end_to_end builds the design from
# the session's cache (parts another process made) and again with --no-cache in its own, and compares every file's
# SHA-256 in the two manifests (STL, 3MF and STEP of every part, the robot, the mass properties).


def test_export_part_files_only_for_printed_parts():
    from swiftfin.cad.part import PartSpec

    p = Params()
    solid = bd.Box(10, 10, 10)
    printed = export_part(PartSpec("cube", solid, 0, "test"), p)
    bought = export_part(PartSpec("cube", solid, 0, "test", printed=False), p)
    assert set(printed.files) == {".stl", ".3mf", ".step"}
    assert bought.files == {}
    assert bought.mesh.volume_mm3 == pytest.approx(1000.0, rel=1e-9)


def _sphere_mesh():
    import trimesh

    from swiftfin.exports.brep import Mesh
    s = trimesh.creation.icosphere(subdivisions=4, radius=1.0)      # edges ~0.08 mm
    return Mesh(np.asarray(s.vertices, float), np.asarray(s.faces, np.int64))


def test_a_pinhole_under_the_tolerance_is_closed_and_a_larger_hole_is_not():
    from swiftfin.exports.brep import Mesh, close_pinholes, is_closed
    m = _sphere_mesh()
    assert is_closed(m) and close_pinholes(m, 0.05) is m
    # one triangle out (a hole ~0.08 mm across), then two neighbours (a four-edge loop)
    one = Mesh(m.vertices, m.faces[1:])
    f0 = set(m.faces[0])
    nb = next(i for i in range(1, len(m.faces)) if len(f0 & set(m.faces[i])) == 2)
    two = Mesh(m.vertices, np.delete(m.faces, [0, nb], axis=0))
    for holed, loop in ((one, 3), (two, 4)):
        assert not is_closed(holed)
        fixed = close_pinholes(holed, 0.5)
        assert is_closed(fixed) and len(fixed.faces) == len(holed.faces) + loop - 2
        assert fixed.volume_mm3 == pytest.approx(m.volume_mm3, rel=1e-6)
        assert close_pinholes(holed, 0.01) is holed        # wider than the size asked: left open, refused later


def test_a_seeded_bay_guides_sliver_face_leaves_no_hole_in_its_mesh():
    """tests/data/seeded_bay_guide_pinhole.toml (a seeded design): its bay guide's B-rep had a cylindrical sliver
    face of ~1.7 x 0.7 um where a channel meets a plane, which OpenCascade's mesher left open (7 edges, at 0.02,
    0.05 and 0.1 mm alike); the build refused the part. Its mesh is closed now, and its volume the B-rep's.
    Since joint 1's pair was lifted over the passing cables (2026-11-29) this design's channels lie elsewhere and
    the mesher closes its guide unaided: the repair itself is tested on a mesh opened by hand (above)."""
    from pathlib import Path

    from swiftfin.cad.kernel import precise_volume_mm3
    from swiftfin.cad.registry import family_function
    from swiftfin.exports.brep import is_closed, tessellate
    from swiftfin.layout.design import load_design
    p = load_design(Path(__file__).parent / "data" / "seeded_bay_guide_pinhole.toml")
    bay = next(q for q in family_function("guide")(p) if q.label == "guide_bay")
    m = tessellate(bay.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
    assert is_closed(m)
    assert m.volume_mm3 == pytest.approx(precise_volume_mm3(bay.solid), rel=0.01)
