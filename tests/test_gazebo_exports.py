"""Water for Gazebo: the SDF's buoyancy volumes and hydrodynamic derivatives, checked with the real parsers
(libsdformat through a small compiled loader, tests/tools/sdf_check.cc; urdfdom's check_urdf) and against
closed forms (Lamb's k1, the strip integrals' ratio, neutral buoyancy of the trimmed fish)."""
from __future__ import annotations

import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from swiftfin.exports.hydro import FOSSEN_ADDED_MASS, FOSSEN_QUADRATIC, lamb_k1
from swiftfin.layout import geometry as layout
from tests.conftest import require_tool

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def robot(default_params, default_robot):
    out, res = default_robot
    return default_params, out / "robot", res


@pytest.fixture(scope="module")
def sdf_check(tmp_path_factory) -> Path:
    """The libsdformat loader, compiled against the installed libsdformat (Debian: libsdformat-dev)."""
    why = "libsdformat (Debian libsdformat-dev) validates the SDF files"
    gxx = require_tool("g++", why)
    pkg = require_tool("pkg-config", why)
    flags = subprocess.run([pkg, "--cflags", "--libs", "sdformat12"], capture_output=True, text=True)
    if flags.returncode != 0:
        import os
        msg = f"libsdformat 12 not installed: {why} (apt-get install libsdformat-dev)"
        if os.environ.get("SWIFTFIN_REQUIRE_TOOLS"):
            pytest.fail(msg)
        pytest.skip(msg)
    exe = tmp_path_factory.mktemp("sdf_check") / "sdf_check"
    r = subprocess.run([gxx, "-std=c++17", str(HERE / "tools" / "sdf_check.cc"), *flags.stdout.split(), "-o",
                        str(exe)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    return exe


@pytest.mark.parametrize("name", ["swiftfin.sdf", "swiftfin_world.sdf"])
def test_libsdformat_loads_the_sdf_files_without_errors(robot, sdf_check, name):
    p, folder, res = robot
    r = subprocess.run([str(sdf_check), str(folder / name)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "error" not in r.stdout.lower(), r.stdout + r.stderr
    lines = r.stdout.splitlines()
    if name == "swiftfin.sdf":
        assert f"model swiftfin links {p.joints.count + 1} joints {p.joints.count}" in lines
        assert "plugins 0" in lines
        for lk in res["robot"].links:       # libsdformat reads the dry link masses we wrote
            row = next(x for x in lines if x.startswith(f"link {lk.name} "))
            assert float(row.split()[3]) == pytest.approx(lk.inertial.mass_kg, rel=1e-5)
            assert row.endswith("collisions 1")
    else:
        assert "world swiftfin_water models 1" in lines


def test_check_urdf_accepts_the_urdf_with_its_gazebo_tags(robot):
    exe = require_tool("check_urdf", "urdfdom's parser validates the URDF (apt-get install liburdfdom-tools)")
    p, folder, res = robot
    r = subprocess.run([exe, str(folder / "swiftfin.urdf")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "Successfully Parsed XML" in r.stdout, r.stdout + r.stderr
    root = ET.parse(folder / "swiftfin.urdf").getroot()
    plugins = root.findall("gazebo/plugin")
    assert [pl.find("link_name").text for pl in plugins] == [lk.name for lk in res["robot"].links]


def test_the_buoyancy_volumes_are_the_displaced_volumes_at_the_centres_of_buoyancy(robot):
    """Gazebo's Buoyancy system takes each link's volume from its collisions: one ellipsoid per link, of the
    link's displaced volume, at its centre of buoyancy. The trimmed fish is neutral: rho sum(V) = its mass."""
    p, folder, res = robot
    rho = p.environment.water_density_kg_m3
    root = ET.parse(folder / "swiftfin.sdf").getroot()
    total_V = total_m = 0.0
    for lk in res["robot"].links:
        el = root.find(f".//link[@name='{lk.name}']")
        (col,) = el.findall("collision")
        radii = [float(v) for v in col.find("geometry/ellipsoid/radii").text.split()]
        V = 4 / 3 * math.pi * np.prod(radii)
        assert V == pytest.approx(lk.displaced_volume_m3, rel=1e-9)
        assert np.allclose([float(v) for v in col.find("pose").text.split()[:3]], lk.cob_m, atol=1e-12)
        total_V += V
        total_m += float(el.find("inertial/mass").text)
    assert rho * total_V == pytest.approx(total_m, rel=1e-9)
    assert total_m == pytest.approx(res["total_mass_kg"], rel=1e-9)
    world = ET.parse(folder / "swiftfin_world.sdf").getroot()
    b = world.find(".//plugin[@name='gz::sim::systems::Buoyancy']")
    assert float(b.find("uniform_fluid_density").text) == rho
    assert world.find("world/gravity").text.split()[2] == repr(-p.environment.gravity_m_s2)


def test_hydrodynamic_derivatives(robot):
    """Every link has its 12 Fossen derivatives, all <= 0; the head's sway and heave added masses are in the
    ratio of its section's half-axes squared (strip theory: rho pi b^2 across, rho pi a^2 up), and equal the
    strip integral done here independently; the fin's lateral added mass rides on the last link; a flooded
    link's water is in its added mass."""
    p, folder, res = robot
    world = ET.parse(folder / "swiftfin_world.sdf").getroot()
    links = res["robot"].links
    plugins = {pl.find("link_name").text: pl for pl in world.iter("plugin") if pl.find("link_name") is not None}
    assert list(plugins) == [lk.name for lk in links]
    for lk in links:
        vals = {k: float(plugins[lk.name].find(k).text) for k in FOSSEN_ADDED_MASS + FOSSEN_QUADRATIC}
        assert all(v <= 0 for v in vals.values()), vals
        assert vals["yDotV"] < 0 and vals["nDotR"] < 0 and vals["yVabsV"] < 0
    head = {k: v for k, v in links[0].hydro.as_fossen().items()}
    # the water the head carries in its joint gap (behind the dry wall) rides with it in every direction
    m_w = links[0].entrained_water.mass_kg if links[0].entrained_water is not None else 0.0
    head["yDotV"] += m_w
    head["zDotW"] += m_w
    k = p.body.height_to_width
    assert head["yDotV"] / head["zDotW"] == pytest.approx(k**2, rel=1e-6)
    s = np.linspace(0.0, layout.joint_stations_mm(p)[0], 20001)
    b = np.asarray(layout.half_height_mm(p, s)) / 1000
    strip = p.hydro.body_added_mass_coefficient * p.environment.water_density_kg_m3 * math.pi * \
        float(np.sum((b[1:] ** 2 + b[:-1] ** 2) / 2 * np.diff(s / 1000)))
    assert -head["yDotV"] == pytest.approx(strip, rel=1e-4)
    # the fin: ~0.54 kg of lateral added mass by strip theory (rho pi (b/2)^2 over its mean chord)
    last, before = links[-1].hydro.as_fossen(), links[-2].hydro.as_fossen()
    assert -last["yDotV"] > 0.4
    for lk in links:
        if lk.entrained_water is not None:
            assert -lk.hydro.as_fossen()["xDotU"] > lk.entrained_water.mass_kg
    assert before["yDotV"] > last["yDotV"]


def test_lamb_k1_closed_forms():
    """Lamb's longitudinal added-mass coefficient: 1/2 for a sphere, 0.210 at L/D = 2, 0.0207 at L/D = 10
    (Lamb 1932, §373, table)."""
    assert lamb_k1(1.0, 1.0) == 0.5
    assert lamb_k1(2.0, 1.0) == pytest.approx(0.210, abs=0.001)
    assert lamb_k1(10.0, 1.0) == pytest.approx(0.0207, abs=0.0005)
