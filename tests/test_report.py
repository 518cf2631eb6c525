"""The design report: the off-screen renderer against closed forms, the plots' numbers against hand-worked
values, and the page (self-contained, every section, failing rules first, every image decodes)."""
from __future__ import annotations

import base64
import hashlib
import io
import functools
import json
import math
import re
import shutil

import numpy as np
import pytest

from swiftfin.design_rules import Finding, Severity
from swiftfin.report import plots
from swiftfin.report.html import SECTIONS, Progress, ReportPart, sorted_findings, write_report
from swiftfin.report.render import camera_axes, cluster_decimate, corner_normals, render
from swiftfin.report.render import MeshItem
from tests.conftest import DEFAULT_DESIGN


# ----------------------------------------------------------------------------------------------- meshes
def box_mesh(sx, sy, sz, centre=(0.0, 0.0, 0.0)):
    """Closed, outward-wound box [mm]."""
    c = np.asarray(centre, float)
    v = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]) * [sx, sy, sz] + c
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f


def sphere_mesh(r, n_lat=48, n_lon=96, centre=(0.0, 0.0, 0.0)):
    """UV sphere, closed and outward-wound."""
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    v = [[0, 0, r]] + [[r * math.sin(t) * math.cos(q), r * math.sin(t) * math.sin(q), r * math.cos(t)]
                       for t in th for q in ph] + [[0, 0, -r]]
    v = np.asarray(v) + np.asarray(centre, float)
    f = []
    idx = lambda i, j: 1 + i * n_lon + (j % n_lon)   # noqa: E731
    for j in range(n_lon):
        f.append([0, idx(0, j), idx(0, j + 1)])
        f.append([len(v) - 1, idx(n_lat - 2, j + 1), idx(n_lat - 2, j)])
    for i in range(n_lat - 2):
        for j in range(n_lon):
            f.append([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)])
            f.append([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)])
    f = np.asarray(f)
    # orient outward: the normal of each face must point away from the centre
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), (a + b + c) / 3 - centre) < 0
    f[inward] = f[inward][:, ::-1]
    return v, f


def signed_volume(v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


# ----------------------------------------------------------------------------------------------- renderer
def test_camera_axes_are_orthonormal_and_look_where_documented():
    for az, el in ((0, 0), (62, 24), (90, 0), (200, -35)):
        R = camera_axes(az, el)
        assert R @ R.T == pytest.approx(np.eye(3), abs=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
    # azimuth 90, elevation 0: the viewer is on +y (the fish's left), +x (the nose) is on the screen's left
    R = camera_axes(90, 0)
    assert R[2] == pytest.approx([0, 1, 0], abs=1e-12)
    assert R[0] @ np.array([1.0, 0, 0]) == pytest.approx(-1.0)
    assert R[1] == pytest.approx([0, 0, 1], abs=1e-12)


def test_box_silhouette_matches_the_projected_rectangle():
    """Looking along -x at a 30 x 60 x 20 box: the silhouette is the y-z rectangle, scaled to fit the frame."""
    v, f = box_mesh(30, 60, 20)
    W, H, margin = 400, 300, 0.06
    img = render([MeshItem(v, f, (0.5, 0.5, 0.5))], W, H, azimuth_deg=0, elevation_deg=0, margin=margin)
    scale = min(W * (1 - 2 * margin) / 60, H * (1 - 2 * margin) / 20)
    expected = (60 * scale) * (20 * scale)
    coverage = img[..., 3].astype(float).sum() / 255
    assert coverage == pytest.approx(expected, rel=0.01)
    cols = np.flatnonzero(img[..., 3].max(axis=0) > 127)
    rows = np.flatnonzero(img[..., 3].max(axis=1) > 127)
    assert cols.size == pytest.approx(60 * scale, abs=1.5)
    assert rows.size == pytest.approx(20 * scale, abs=1.5)


def test_sphere_silhouette_is_a_disc_and_lit_from_the_key_light():
    r = 25.0
    v, f = sphere_mesh(r)
    assert signed_volume(v, f) == pytest.approx(4 / 3 * math.pi * r**3, rel=0.01)
    W = H = 300
    img = render([MeshItem(v, f, (0.8, 0.8, 0.8))], W, H, azimuth_deg=30, elevation_deg=20, margin=0.1)
    scale = W * 0.8 / (2 * r)
    coverage = img[..., 3].astype(float).sum() / 255
    assert coverage == pytest.approx(math.pi * (r * scale) ** 2, rel=0.015)
    # the key light comes from the upper left: the upper-left quadrant is brighter than the lower-right one
    lum = img[..., :3].astype(float).mean(axis=2)
    inside = img[..., 3] == 255
    ul = lum[:H // 2, :W // 2][inside[:H // 2, :W // 2]].mean()
    lr = lum[H // 2:, W // 2:][inside[H // 2:, W // 2:]].mean()
    assert ul > lr + 20


def test_z_buffer_shows_the_nearer_part_whatever_the_drawing_order():
    """Two boxes overlapping on screen: the one nearer the viewer (+x, looking along -x) wins every pixel of
    the overlap, drawn first or last (a painter's algorithm on centroids would not guarantee it)."""
    far_v, far_f = box_mesh(10, 80, 80, centre=(-50, 0, 0))
    near_v, near_f = box_mesh(10, 20, 20, centre=(0, 0, 0))
    red, blue = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    for order in ((0, 1), (1, 0)):
        items = [MeshItem(far_v, far_f, blue), MeshItem(near_v, near_f, red)]
        img = render([items[k] for k in order], 200, 200, azimuth_deg=0, elevation_deg=0, outline=False)
        c = img[100, 100, :3].astype(int)
        assert c[0] > 100 and c[2] < 30, c          # the near (red) box in the middle
        e = img[100, 30, :3].astype(int)
        assert e[2] > 100 and e[0] < 30, e          # the far (blue) box around it


def test_corner_normals_of_a_sphere_are_radial_and_a_box_keeps_its_edges_sharp():
    v, f = sphere_mesh(10.0, 24, 48)
    cn = corner_normals(v, f)
    radial = v[f] / np.linalg.norm(v[f], axis=2, keepdims=True)
    assert np.einsum("mkj,mkj->mk", cn, radial).min() > 0.99
    bv, bf = box_mesh(1, 2, 3)
    cnb = corner_normals(bv, bf)
    fn = np.cross(bv[bf[:, 1]] - bv[bf[:, 0]], bv[bf[:, 2]] - bv[bf[:, 0]])
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    assert cnb == pytest.approx(np.repeat(fn[:, None, :], 3, axis=1), abs=1e-12)


def test_cluster_decimation_keeps_the_shape():
    v, f = sphere_mesh(20.0, 80, 160)
    dv, df = cluster_decimate(v, f, 4000)
    assert 500 < len(df) <= 4000 < len(f)
    assert np.linalg.norm(dv, axis=1) == pytest.approx(20.0, rel=0.03)
    assert abs(signed_volume(dv, df)) == pytest.approx(4 / 3 * math.pi * 20.0**3, rel=0.05)


def test_render_refuses_nothing_to_draw():
    with pytest.raises(ValueError, match="nothing to render"):
        render([MeshItem(np.zeros((0, 3)), np.zeros((0, 3), int), (1, 1, 1))])


# ----------------------------------------------------------------------------------------------- plots
def test_efficiency_curves_recompute_the_paper_and_the_models(default_params):
    c = plots.efficiency_curves(default_params, np.array([3.0, 5.0, 8.0]))
    assert c["capstan_paper_fit"] == pytest.approx([0.941, 0.935, 0.926])          # eq. 31, 33
    assert c["servo_paper_fit"] == pytest.approx([0.827, 0.745, 0.592])            # eq. 32, 34
    # eq. 28 with the paper's inputs and eq. 25 guides: 0.95 x e^(-0.05 pi/2)^2 x 0.98
    eta_c = 1 - 2 * 0.15 / math.pi * math.asin(0.5)
    assert c["capstan_model_paper"] == pytest.approx(eta_c * math.exp(-0.05 * math.pi) * 0.98)
    assert c["capstan_model_paper"][0] == pytest.approx(0.796, abs=5e-4)
    # eq. 18 by hand at 3 Hz: eta_g^3 x P0 f / (P0 f + P_backlash), P_backlash = 2 f (1/2) J w^2 (1 - e^2),
    # w^2 = 2 (2 pi f)^2 theta0 phi_b
    eta_g = (1 - math.pi * 0.08 / math.cos(math.radians(20)) * (1 / 12 + 1 / 48)) ** 3
    f = 3.0
    w2 = 2 * (2 * math.pi * f) ** 2 * 0.96 * 0.0175
    p_bl = 2 * f * 0.5 * 5e-6 * w2 * (1 - 0.7**2)
    p0f = 2.16 / 3.0 * f
    assert p_bl == pytest.approx(9.14e-5, rel=0.01)
    assert c["servo_model_derived"][0] == pytest.approx(eta_g * p0f / (p0f + p_bl), rel=1e-9)
    # as printed: 0.046 W at 3 Hz, x (8/3)^3 at 8 Hz
    p_pr = 0.046 * (8 / 3) ** 3
    assert c["servo_model_as_printed"][2] == pytest.approx(eta_g * 2.16 / 3 * 8 / (2.16 / 3 * 8 + p_pr), rel=1e-9)
    assert np.all(c["capstan_model_design_worst"] <= c["capstan_model_design_best"])
    assert 0.5 < c["capstan_model_design_worst"][0] < 1.0


def test_tail_beat_amplitudes_match_the_relative_joint_angles(default_params):
    """README: at 3 Hz and 0.10 m the relative joint angles peak at 20.2, 10.9, 13.1 and 33.1 deg (joint 1 at
    0.555 L; tests/test_audit.py finds the same by brute force)."""
    from swiftfin.layout.geometry import joint_stations_mm
    from swiftfin.physics.kinematics import full_step_rate, max_relative_joint_angles_rad, wave_from_params

    p = default_params
    d = plots.tail_beat(p)
    amp = np.abs(d["joint_angle_deg"]).max(axis=0)
    assert amp == pytest.approx([20.2, 10.9, 13.1, 33.1], abs=0.06)
    L = p.body.length_mm / 1000
    wave = wave_from_params(p.swimming, L)
    xs = np.asarray(joint_stations_mm(p)) / 1000
    assert amp == pytest.approx(np.degrees(max_relative_joint_angles_rad(wave, xs, L)), rel=2e-3)
    # step rate of a sinusoid-like joint: peak >= 2 pi f A r_motor / step (the fundamental's peak speed)
    peak = d["full_steps_s"].max(axis=0)
    lower = full_step_rate(2 * math.pi * 3.0 * np.radians(amp), 0.015, 0.010, math.radians(1.8))
    assert np.all(peak >= 0.9 * lower)
    assert d["microsteps_s"].max() == pytest.approx(16 * peak.max())


def test_plots_are_pngs(default_params):
    from PIL import Image

    for fn in (plots.efficiency_plot, plots.joint_plot, plots.wave_plot):
        pl = fn(default_params)
        im = Image.open(io.BytesIO(pl.png))
        assert im.format == "PNG" and im.width > 600 and im.height > 250
        assert np.asarray(im.convert("L"), float).std() > 10
        assert pl.caption


# ----------------------------------------------------------------------------------------------- page
def synthetic_parts():
    bv, bf = box_mesh(120, 40, 50, centre=(-80, 0, 0))
    sv, sf = sphere_mesh(12, 16, 32, centre=(-30, 0, 30))
    cv, cf = box_mesh(30, 10, 10, centre=(-200, 0, 0))
    return [ReportPart("hull_test_upper", "hull", 0, True, bv, bf, (120.0, 40.0, 50.0), 240000.0),
            ReportPart("spool_test", "spool", 0, True, sv, sf, (24.0, 24.0, 24.0), 7238.0, (180.0, 0.0, 0.0)),
            ReportPart("motor_test", "bought", 0, False, cv, cf, None, 3000.0, catalogue_mass_kg=0.28)]


def fake_mass_properties():
    def inert(m):
        return {"mass_kg": m, "com_m": [-0.1, 0.0, 0.0], "inertia_kg_m2": {"ixx": 1e-5, "iyy": 2e-5, "izz": 3e-5,
                                                                          "ixy": 0, "ixz": 0, "iyz": 0}}
    return {"parts": [{"label": "hull_test_upper", "link": 0, "family": "hull", "printed": True,
                       "volume_solid_m3": 2.4e-4, "volume_material_m3": 1.1e-4, **inert(0.1234)},
                      {"label": "spool_test", "link": 0, "family": "spool", "printed": True,
                       "volume_solid_m3": 7.2e-6, "volume_material_m3": 5e-6, **inert(0.0061)},
                      {"label": "motor_test", "link": 0, "family": "bought", "printed": False,
                       "volume_solid_m3": 3e-6, "volume_material_m3": 3e-6, **inert(0.28)}],
            "links": [{"index": 0, "name": "head", "parts": ["hull_test_upper", "spool_test", "motor_test"],
                       "displaced_volume_m3": 4e-4, "com_m_body": [-0.1, 0, 0], **inert(0.4123)}],
            "total": {**inert(0.4123), "paper_mass_kg": 1.2, "displaced_volume_m3": 4e-4, "cob_m": [-0.1, 0, 0.001],
                      "buoyancy_n": 3.924, "weight_n": 4.0447, "net_buoyancy_n": 3.924 - 4.0447,
                      "cob_above_com_m": 0.001}}


@functools.lru_cache(maxsize=1)
def _paper_audit() -> tuple:
    from swiftfin.design_rules.paper_audit import audit_entries
    return tuple(audit_entries())


def paper_audit() -> list:
    """The paper audit's entries, which the report is handed (it does not compute them)."""
    return list(_paper_audit())


def fake_findings():
    return [Finding("rule_pass_big", 3.0, 1.0, 2.0, Severity.PASS, "test"),
            Finding("rule_fail_small", 0.9, 1.0, -0.1, Severity.FAIL, "test"),
            Finding("rule_warn", 2.5, 2.0, -0.25, Severity.WARN, "test", comparison="<="),
            Finding("rule_fail_big", 0.2, 1.0, -0.8, Severity.FAIL, "test"),
            Finding("rule_pass_small", 1.05, 1.0, 0.05, Severity.PASS, "test")]


IMG_SRC = re.compile(r"<img\b[^>]*\bsrc=\"([^\"]*)\"")


def assert_self_contained(text: str):
    """No http(s) or protocol-relative src/href, no <script src>, no <link> to a style sheet, no @import."""
    assert not re.search(r"""(?:src|href)\s*=\s*["']?\s*(?:https?:)?//""", text, re.I)
    assert not re.search(r"<script\b[^>]*\bsrc=", text, re.I)
    assert not re.search(r"<link\b", text, re.I)
    assert "@import" not in text and "url(http" not in text
    for href in re.findall(r"href=\"([^\"]*)\"", text):
        assert href.startswith("#"), href


def decode_images(text: str) -> list:
    from PIL import Image

    srcs = IMG_SRC.findall(text)
    out = []
    for s in srcs:
        assert s.startswith("data:image/png;base64,"), s[:60]
        im = Image.open(io.BytesIO(base64.b64decode(s.split(",", 1)[1], validate=True)))
        im.load()
        arr = np.asarray(im.convert("RGBA"), float)
        assert im.width >= 100 and im.height >= 100
        assert arr.std() > 5, "a blank image"
        out.append(im)
    return out


@pytest.fixture
def fit_dir(tmp_path):
    from PIL import Image

    d = tmp_path / "fit"
    d.mkdir()
    rep = {"family": "joint", "description": "joint angle vs command", "n_samples": 4000, "n_train": 2800,
           "n_holdout": 1200, "baseline": {"rmse_train": 0.02, "rmse_holdout": 0.021},
           "added_effects": [{"name": "backlash", "physical": {"play_deg": {"value": 0.81, "std": 0.03, "unit": "deg"}},
                              "rmse_holdout_before": 0.021, "rmse_holdout_after": 0.004, "confidence": "high",
                              "indistinguishable_from": []}],
           "final": {"rmse_train": 0.004, "rmse_holdout": 0.0041, "residual_white": True},
           "unexplained_structure": False, "units": {"target": "rad", "rmse": "rad"}}
    (d / "fit_report.json").write_text(json.dumps(rep))
    y, x = np.mgrid[0:120, 0:200]
    Image.fromarray((np.stack([x, y, x + y], -1) % 256).astype(np.uint8)).save(d / "before_after.png")
    return d


def test_page_is_self_contained_and_complete(tmp_path, default_params, fit_dir):
    path = write_report(default_params, tmp_path / "out", parts=synthetic_parts(),
                        mass_properties=fake_mass_properties(), fit_dir=fit_dir, findings=fake_findings(), audit=paper_audit())
    assert path == tmp_path / "out" / "report.html"
    text = path.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert_self_contained(text)
    for sid, _ in SECTIONS:
        assert f'<section id="{sid}">' in text
        assert f'href="#{sid}"' in text
    imgs = decode_images(text)
    # 2 assembly views + 2 printed parts + 3 plots + 1 fit plot; the bought part is in a table, not a picture
    assert len(imgs) == 2 + 2 + 3 + 1
    assert "hull_test_upper" in text and "spool_test" in text and "motor_test" in text
    assert "123.4 g" in text and "6.1 g" in text            # printed masses from mass_properties.json
    assert "412&nbsp;g" in text                               # total mass tile (0.4123 kg)
    assert "-0.12&nbsp;N" in text                             # net buoyancy 3.924 - 4.0447
    assert "backlash" in text and "0.81" in text              # the fit's effect and its parameter
    assert not list(tmp_path.joinpath("out").glob(".*tmp"))   # no temporary left behind


def test_failing_rules_come_first_coloured_by_verdict(tmp_path, default_params):
    text = write_report(default_params, tmp_path, findings=fake_findings(), audit=paper_audit()).read_text()
    rules = text[text.index('<section id="rules">'):text.index('<section id="mass">')]
    order = re.findall(r"<code>(rule_[a-z_]+)</code>", rules)
    assert order == ["rule_fail_big", "rule_fail_small", "rule_warn", "rule_pass_small", "rule_pass_big"]
    classes = re.findall(r'<tr class="row-(\w+)">', rules)
    assert classes == ["fail", "fail", "warn", "pass", "pass"]
    assert sorted_findings(fake_findings())[0].rule_id == "rule_fail_big"


def test_real_rules_are_sorted_worst_first(tmp_path, default_params):
    from swiftfin.design_rules import RuleContext, run_rules

    found = run_rules(RuleContext(default_params))
    text = write_report(default_params, tmp_path, findings=found, audit=paper_audit()).read_text()
    rules = text[text.index('<section id="rules">'):text.index('<section id="mass">')]
    sev = [Severity[{"pass": "PASS", "info": "INFO", "na": "NOT_EVALUATED", "warn": "WARN", "fail": "FAIL"}[c]]
           for c in re.findall(r'<tr class="row-(\w+)">', rules)]
    assert len(sev) == len(found)
    assert sev == sorted(sev, reverse=True)


def test_missing_inputs_are_said_not_faked(tmp_path, default_params):
    text = write_report(default_params, tmp_path, findings=fake_findings(), audit=paper_audit()).read_text()
    assert_self_contained(text)
    assert "mass properties not computed in this build" in text.lower()
    assert "no parts were built for this report" in text.lower()
    assert "No fit given" in text
    assert len(decode_images(text)) == 3       # the plots only
    # parts without mass properties: each card says its mass was not computed
    text = write_report(default_params, tmp_path / "b", parts=synthetic_parts(), findings=fake_findings(), audit=paper_audit()).read_text()
    assert text.count("mass not computed") == 2
    assert "Mass properties not computed in this build" in text


def test_audit_table_lists_every_entry(tmp_path, default_params):
    from swiftfin.design_rules.paper_audit import audit_entries

    entries = audit_entries()
    text = write_report(default_params, tmp_path, findings=fake_findings(), audit=entries).read_text()
    audit = text[text.index('<section id="audit">'):text.index('<section id="fit">')]
    assert len(re.findall(r"<tr class=\"row-", audit)) == len(entries)
    shown = audit.replace("<wbr>", "")   # ids carry optional line-break hints after underscores
    for e in entries:
        assert f"<code>{e.entry_id}</code>" in shown
    n_bad = sum(e.holds is False for e in entries)
    assert audit.count('class="badge fail">does not hold') == n_bad


def test_progress_is_quiet_without_a_terminal():
    class Stream(io.StringIO):
        def __init__(self, tty):
            super().__init__()
            self.tty = tty

        def isatty(self):
            return self.tty

    quiet, loud = Stream(False), Stream(True)
    Progress(stream=quiet)("step one")
    Progress(stream=loud)("step one")
    assert quiet.getvalue() == ""
    assert "step one" in loud.getvalue()


# ----------------------------------------------------------------------------------------------- command
def test_cli_bad_inputs_exit_2_and_write_nothing(tmp_path, capsys):
    from swiftfin.cli import main

    bad = tmp_path / "bad.toml"
    bad.write_text("[spool]\ndrum_diameter_mm = -3\n")
    assert main(["report", str(bad), "--out", str(tmp_path / "o1")]) == 2
    assert "drum_diameter_mm" in capsys.readouterr().err
    assert not (tmp_path / "o1").exists()
    assert main(["report", str(DEFAULT_DESIGN), "--out", str(tmp_path / "o2"), "--fit", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err
    assert "--fit" in err and "nope" in err and "Traceback" not in err
    assert not (tmp_path / "o2").exists()


def test_cli_reads_the_parts_from_a_build_folder(tmp_path, capsys):
    """A build folder (manifest.json of this parameter file + assembly.step) is read, not rebuilt; the
    mass table comes from its mass_properties.json."""
    import build123d as bd

    from swiftfin.cad.assembly import make_assembly
    from swiftfin.cad.part import PartSpec
    from swiftfin.exports.files import step_bytes
    from swiftfin.cli import main

    params = tmp_path / "design.toml"
    shutil.copy(DEFAULT_DESIGN, params)
    out = tmp_path / "build"
    out.mkdir()
    specs = [PartSpec("block_a", bd.Box(40, 20, 10), 0, "hull"),
             PartSpec("pin_b", bd.Cylinder(8, 30).moved(bd.Location((60, 0, 0))), 1, "link")]
    (out / "assembly.step").write_bytes(step_bytes(make_assembly(specs), "swiftfin_assembly"))
    manifest = {"params_sha256": hashlib.sha256(params.read_bytes()).hexdigest(),
                "parts": [{"label": "block_a", "family": "hull", "link": 0, "printed": True,
                           "volume_mm3": 8000.0, "print_size_mm": [40, 20, 10]},
                          {"label": "pin_b", "family": "link", "link": 1, "printed": True,
                           "volume_mm3": 6031.9, "print_size_mm": [16, 16, 30]}]}
    (out / "manifest.json").write_text(json.dumps(manifest))
    mp = fake_mass_properties()
    mp["parts"][0]["label"] = "block_a"
    (out / "mass_properties.json").write_text(json.dumps(mp))
    assert main(["report", str(params), "--out", str(out)]) == 0
    msg = capsys.readouterr()
    assert "report.html" in msg.out and msg.err == ""        # quiet: stderr is not a terminal under pytest
    text = (out / "report.html").read_text()
    assert_self_contained(text)
    assert 'id="part-block_a"' in text and 'id="part-pin_b"' in text
    assert "123.4 g" in text                                  # block_a's mass from mass_properties.json
    assert len(decode_images(text)) == 2 + 2 + 3
    assert sorted(p.name for p in out.iterdir()) == ["assembly.step", "manifest.json", "mass_properties.json",
                                                     "report.html"]
    # an unreadable assembly.step is refused with its name (exit 2), not a traceback
    (out / "assembly.step").write_text("not a step file")
    assert main(["report", str(params), "--out", str(out)]) == 2
    assert "assembly.step" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_default_design_builds_in_memory(tmp_path, tmp_path_factory):
    """The real design, no build folder: parts built in memory (or read from the session's rebuild cache, where
    another test stored them) with the trim ballast the build pours (its part in the mass table), mass properties
    computed, every section."""
    from swiftfin.cli import main
    from tests.conftest import session_cache_dir

    out = tmp_path / "build"
    assert main(["report", str(DEFAULT_DESIGN), "--out", str(out),
                 "--cache-dir", str(session_cache_dir(tmp_path_factory))]) == 0
    text = (out / "report.html").read_text()
    assert_self_contained(text)
    imgs = decode_images(text)
    n_printed = text.count('class="card" id="part-')
    assert n_printed >= 20 and len(imgs) == 2 + n_printed + 3
    assert "not computed" not in text.lower()
    assert "<td>trim_ballast</td><td>ballast</td>" in text and "<td>ballast_dam" in text
    assert sorted(p.name for p in out.iterdir()) == ["report.html"]


def test_fit_section_from_a_real_fit(tmp_path, default_params):
    """`swiftfin synth` with a known 15 ms sensor delay, `swiftfin fit`, then the page: the effect found, its
    fitted delay, and every plot of the fit folder, decoded."""
    from swiftfin.cli import main

    design = ["--design", str(DEFAULT_DESIGN)]
    assert main(["synth", "joint", "--out", str(tmp_path / "run.csv"), "--seed", "1", "--duration", "20",
                 "--effect", "sensor_delay=0.015", *design]) == 0
    assert main(["fit", "joint", str(tmp_path / "run.csv"), "--out", str(tmp_path / "fit"), *design]) == 0
    rep = json.loads((tmp_path / "fit" / "fit_report.json").read_text())
    text = write_report(default_params, tmp_path / "out", fit_dir=tmp_path / "fit",
                        findings=fake_findings(), audit=paper_audit()).read_text()
    fit = text[text.index('<section id="fit">'):]
    names = [e["name"] for e in rep["added_effects"]]
    assert "sensor_delay" in names
    for n in names:
        assert f"<b>{n}</b>" in fit
    delay = next(e for e in rep["added_effects"] if e["name"] == "sensor_delay")["params"]["delay_s"]["value"]
    assert delay == pytest.approx(0.015, rel=0.05)
    assert format(delay, ".4g") in fit
    pngs = sorted((tmp_path / "fit").glob("*.png"))
    assert len(pngs) >= 2
    assert len(decode_images(fit)) == len(pngs)


def test_report_for_build_takes_the_pipeline_result(tmp_path, default_params):
    """What `swiftfin build` hands over (BuildResult of BuiltParts), plus the build's mass_properties.json."""
    from swiftfin.cad.part import PartSpec
    from swiftfin.exports.files import Mesh, PartExport
    from swiftfin.pipeline import report_for_build
    from swiftfin.pipeline import BuildResult, BuiltPart

    built = []
    for rp in synthetic_parts():
        spec = PartSpec(rp.label, None, rp.link, rp.family, rp.printed, rp.print_rotation or (0.0, 0.0, 0.0),
                        rp.catalogue_mass_kg)
        exp = PartExport(Mesh(rp.vertices, rp.faces), rp.volume_mm3, 0.0, rp.print_size_mm or (1.0, 1.0, 1.0), {})
        built.append(BuiltPart(spec, exp, 0.0, False))
    (tmp_path / "mass_properties.json").write_text(json.dumps(fake_mass_properties()))
    path = report_for_build(BuildResult(default_params, built), tmp_path)
    text = path.read_text()
    assert_self_contained(text)
    assert 'id="part-spool_test"' in text and "rotation (180, 0, 0)" in text
    assert "123.4 g" in text and "412&nbsp;g" in text
    assert len(decode_images(text)) == 2 + 2 + 3


def test_no_legend_covers_plotted_data(default_params, monkeypatch):
    """Issue 15: every legend of the report's plots sits where no plotted line runs under it (checked on the
    figures, in display pixels, along every segment)."""
    from swiftfin.report import plots

    figures = []
    real_png = plots._png

    def capture(fig):
        out = real_png(fig)
        figures.append(fig)
        return out

    monkeypatch.setattr(plots, "_png", capture)
    plots.efficiency_plot(default_params)
    plots.joint_plot(default_params)
    plots.wave_plot(default_params)
    assert len(figures) == 3
    for fig in figures:
        assert sum(ax.get_legend() is not None for ax in fig.axes) >= 1
        assert plots.legend_overlaps(fig) == []


def test_robot_section_reads_the_simulator_files(tmp_path, default_params):
    """Issue 15: the page's robot section shows what the simulator files say, read back from them: a picture
    of the collision shapes with the joint axes, each link's mass, buoyancy volume, collision shapes and added
    mass, each joint's axis and range (the mini stand-in robot, exported here)."""
    from swiftfin.exports.robot import write_robot
    from swiftfin.report.robot import read_robot
    from tests.robot_helpers import mini_parts

    p = default_params
    res = write_robot(p, mini_parts(p), tmp_path)
    robot = read_robot(tmp_path / "robot")
    assert list(robot["links"]) == [lk.name for lk in res["robot"].links]
    for lk in res["robot"].links:
        got = robot["links"][lk.name]
        assert got["mass_kg"] == pytest.approx(lk.inertial.mass_kg, rel=1e-12)
        assert got["buoyancy_volume_m3"] == pytest.approx(lk.displaced_volume_m3, rel=1e-9)
        assert got["hydro"]["yDotV"] == pytest.approx(lk.hydro.as_fossen()["yDotV"], rel=1e-12)
        assert all(path.is_file() for path in got["collisions"])
    assert [j["name"] for j in robot["joints"]] == [f"joint_{j + 1}" for j in range(p.joints.count)]
    text = write_report(p, tmp_path, findings=fake_findings(), audit=paper_audit()).read_text()
    section = text[text.index('<section id="robot">'):text.index("</section>", text.index('<section id="robot">'))]
    assert len(decode_images(section)) == 1
    assert "joint_1" in section and "head" in section and "collision shapes" in section
    # without simulator files the section says so instead
    bare = write_report(p, tmp_path / "bare", findings=fake_findings(), audit=paper_audit()).read_text()
    assert "needs a build" in bare[bare.index('<section id="robot">'):]


def test_solve_section_from_a_real_solve(tmp_path, default_params):
    """`swiftfin solve --json` on a seeded design one rule short, then the page: the change, the front's plot
    decoded, its rows fastest first, the rules that stop it; a page without --solve says how to add one."""
    from swiftfin.cli import main
    from swiftfin.core.params import dump_toml
    from tests.test_synthesis import one_rule_short_design

    p = one_rule_short_design()
    (tmp_path / "d.toml").write_text(dump_toml(p), encoding="utf-8")
    vary = f"cable.pretension_n=1:{0.9 * p.cable.breaking_strength_n:.1f}"
    assert main(["solve", str(tmp_path / "d.toml"), "--vary", vary, "--vary", "swimming.tail_beat_frequency_hz=0.2:3",
                 "--front-samples", "128", "--out", str(tmp_path / "s.toml"), "--json", str(tmp_path / "s.json")]) == 0
    solve = json.loads((tmp_path / "s.json").read_text())
    text = write_report(default_params, tmp_path / "out", findings=fake_findings(), audit=paper_audit(),
                        solve=solve, solve_name="s.json").read_text()
    sec = text[text.index('<section id="solve">'):]
    sec = sec[:sec.index("</section>")]
    assert "cable.pretension_n" in sec and "The nearest passing design" in sec
    assert len(decode_images(sec)) == 1
    speeds = [float(v) for v in re.findall(r"<td class=num>([0-9.]+)</td><td class=num>[0-9.]+</td><td class=num>",
                                            sec)]
    assert speeds and speeds == sorted(speeds, reverse=True)
    assert speeds[0] == pytest.approx(max(q["speed_m_s"] for q in solve["front"]["points"]), abs=5e-4)
    assert "What stops the front" in sec
    bare = write_report(default_params, tmp_path / "bare", findings=fake_findings(), audit=paper_audit()).read_text()
    assert "swiftfin report --solve" in bare


def test_cli_refuses_a_bad_solve_file(tmp_path, capsys):
    from swiftfin.cli import main

    (tmp_path / "x.json").write_text('{"front": 3}')
    assert main(["report", str(DEFAULT_DESIGN), "--out", str(tmp_path / "o"), "--solve", str(tmp_path / "x.json")]) == 2
    err = capsys.readouterr().err
    assert "--solve" in err and "x.json" in err and "Traceback" not in err
    assert main(["report", str(DEFAULT_DESIGN), "--out", str(tmp_path / "o"), "--solve", str(tmp_path / "no.json")]) == 2
    assert "no such file" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_residual_spectrum_starts_below_the_slowest_motion():
    """The fit report's residual spectrum (calibration.report.residual_psd) over a 40 s record: its first frequency
    is 4 / the span (0.1 Hz, below the bench command's 0.37-0.5 Hz), a 0.5 Hz sine peaks at 0.5 Hz, and white noise
    sits at 2 s^2 dt."""
    from swiftfin.calibration.report import residual_psd
    rng = np.random.default_rng(4)
    dt = 0.001
    t = np.arange(0, 40, dt)
    f, p = residual_psd(t, 0.02 * np.sin(2 * np.pi * 0.5 * t))
    assert f[0] == pytest.approx(4 / 40.0, rel=0.01)
    assert abs(f[np.argmax(p)] - 0.5) < 0.11
    f, p = residual_psd(t, rng.normal(0, 0.01, t.size))
    assert np.median(p) == pytest.approx(2 * 0.01 ** 2 * dt, rel=0.1)
