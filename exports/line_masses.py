"""Bought parts that are lines, not solids: the capstan cables and the PTFE tubes, as line masses in SI units.

The **cables** are line masses (``cable.linear_density_g_m``) along ``swiftfin.layout.geometry.cable_routes`` plus
their wraps on the drums (:func:`cable_masses`, one ``cables_link_<j>`` entry per link). The **fasteners** (screws,
inserts, nuts, pins of the fastener records) are short rods at their places (:func:`fastener_masses`). The **PTFE tubes**
(:func:`ptfe_tube_masses`) are thin-walled rods of ``guides.ptfe_tube_od_mm`` / ``ptfe_tube_id_mm`` and
``guides.ptfe_density_kg_m3`` along the tubes of ``cad.cables.tube_runs`` (the guide channels and the bulkhead
bores, mouth to seat: the same pieces as the bill of materials), one ``ptfe_tube_link_<j>`` entry per link that
holds tubes. The wiring harness's **leads** (:func:`harness_masses`) are rods along their routes, one ``harness``
entry on the head. Pieces are given to
links by their station (:func:`link_of_station`).
"""
from __future__ import annotations

import math

import numpy as np

from swiftfin.core import units
from swiftfin.core.schema import Params
from swiftfin.exports.inertia import Inertial, combine, make_inertial
from swiftfin.exports.print_model import PartMass
from swiftfin.layout import geometry as layout


def rod_inertial(mass_kg: float, a_m, b_m, radius_m: float) -> Inertial:
    """A uniform solid rod from a to b [m]: I = m (3 r^2 + l^2) / 12 across, m r^2 / 2 along."""
    a, b = np.asarray(a_m, dtype=float), np.asarray(b_m, dtype=float)
    d = b - a
    length = float(np.linalg.norm(d))
    u = d / length
    P = np.outer(u, u)
    I = mass_kg * (3 * radius_m**2 + length**2) / 12 * (np.eye(3) - P) + mass_kg * radius_m**2 / 2 * P
    return make_inertial(mass_kg, (a + b) / 2, I)


def link_of_station(p: Params, s_mm: float) -> int:
    """The kinematic link at station s: 0 ahead of joint 1, j between joint j and joint j+1."""
    return int(sum(1 for sj in layout.joint_stations_mm(p) if s_mm >= sj))


def cable_masses(p: Params) -> list[PartMass]:
    """The capstan cables as line masses along their rest routes (swiftfin.layout.geometry.cable_routes), one entry per
    link a route crosses: segments are cut at the joint stations and each piece is a thin rod of the cable's
    diameter and ``cable.linear_density_g_m``. The wraps on the spools (about ``spool.wraps`` turns of
    ``pi x drum diameter`` per cable) are added to the head as a ring at the spool axis."""
    rho_l = p.cable.linear_density_g_m / 1000.0            # kg/m
    r = units.length_m(p.cable.diameter_mm / 2)
    js = layout.joint_stations_mm(p)
    pieces: dict[int, list[Inertial]] = {}
    for route in layout.cable_routes(p):
        pts = np.asarray(route.points_mm, dtype=float)
        for a, b in zip(pts[:-1], pts[1:]):
            cuts = sorted({0.0, 1.0, *[(-sj - a[0]) / (b[0] - a[0]) for sj in js
                                       if b[0] != a[0] and 0.0 < (-sj - a[0]) / (b[0] - a[0]) < 1.0]})
            for t0, t1 in zip(cuts[:-1], cuts[1:]):
                pa, pb = a + t0 * (b - a), a + t1 * (b - a)
                length_m = units.length_m(float(np.linalg.norm(pb - pa)))
                if length_m <= 0:
                    continue
                link = link_of_station(p, -0.5 * (pa[0] + pb[0]))
                pieces.setdefault(link, []).append(
                    rod_inertial(rho_l * length_m, units.length_m(pa), units.length_m(pb), r))
    for mp in layout.motor_placements(p):
        R = units.length_m(p.spool.drum_diameter_mm / 2)
        m = rho_l * 2 * p.spool.wraps * 2 * math.pi * R       # two cable ends share the drum
        c = units.length_m(np.array([mp.x_mm, 0.0, mp.z_cable_mm]))
        pieces.setdefault(0, []).append(make_inertial(m, c, m * R**2 * np.diag([0.5, 0.5, 1.0])))
    out = []
    for link, items in sorted(pieces.items()):
        it = combine(items)
        pts = np.array([i.com for i in items])
        bbox = (tuple(pts.min(axis=0) - r), tuple(pts.max(axis=0) + r))
        out.append(PartMass(f"cables_link_{link}", link, "cable", False,
                            "line mass: cable.linear_density_g_m along swiftfin.layout.geometry.cable_routes (thin rods) plus the "
                            "drum wraps", (), 0.0, 0.0, 0.0, 0.0, it, it, None, None, bbox))
    return out


def ptfe_tube_masses(p: Params) -> list[PartMass]:
    """The PTFE tube pieces (:func:`swiftfin.cad.cables.tube_runs`: every guide channel and bulkhead bore, mouth to
    seat) as thin rods along their centre lines, one entry per link. A tube is a hollow cylinder: mass
    rho pi (OD^2 - ID^2) / 4 per metre; its inertia across is taken as a solid rod's of the outer radius scaled to
    that mass (the radial term is < 1e-3 of the total for a piece longer than 5 OD)."""
    from swiftfin.cad.cables import tube_runs
    g = p.guides
    r_o, r_i = g.ptfe_tube_od_mm / 2, g.ptfe_tube_id_mm / 2
    rho_l = g.ptfe_density_kg_m3 * math.pi * units.length_m(1.0) ** 2 * (r_o**2 - r_i**2)   # kg/m
    pieces: dict[int, list[Inertial]] = {}
    ends: dict[int, list[np.ndarray]] = {}
    for t in tube_runs(p):
        pts = np.asarray(t.points_mm, float)
        for a, b in zip(pts[:-1], pts[1:]):
            length_m = units.length_m(float(np.linalg.norm(b - a)))
            if length_m <= 0:
                continue
            ends.setdefault(t.link, []).extend([units.length_m(a), units.length_m(b)])
            pieces.setdefault(t.link, []).append(
                rod_inertial(rho_l * length_m, units.length_m(a), units.length_m(b), units.length_m(r_o)))
    out = []
    for link, items in sorted(pieces.items()):
        it = combine(items)
        pts = np.array(ends[link])
        pad = units.length_m(r_o)
        out.append(PartMass(f"ptfe_tube_link_{link}", link, "ptfe", False,
                            f"line mass: guides.ptfe_density_kg_m3 x pi (OD^2 - ID^2) / 4 = {1000 * rho_l:.3g} g/m "
                            "along the tubes of cad.cables.tube_runs (guide channels and bulkheads)",
                            (), 0.0, 0.0, 0.0, 0.0, it, it, None, None,
                            (tuple(pts.min(axis=0) - pad), tuple(pts.max(axis=0) + pad))))
    return out


def harness_masses(p: Params, leads=None) -> list[PartMass]:
    """The wiring harness's leads (:func:`swiftfin.layout.harness_plan.harness`) as one ``harness`` entry on the
    head: each lead's cut length (route, service allowance, terminations) at its catalogue linear density, spread
    along its route as thin rods of its diameter. Empty when the design has no harness."""
    from swiftfin.layout.harness_plan import harness
    leads = harness(p) if leads is None else leads
    items, ends = [], []
    for h in leads:
        pts = np.asarray(h.centre_line_mm, float)
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        per_mm = h.mass_kg / float(seg.sum())
        r = units.length_m(h.diameter_mm / 2)
        for a, b, length in zip(pts[:-1], pts[1:], seg):
            if length > 0:
                items.append(rod_inertial(per_mm * float(length), units.length_m(a), units.length_m(b), r))
        ends += [units.length_m(pts.min(axis=0) - h.diameter_mm / 2),
                 units.length_m(pts.max(axis=0) + h.diameter_mm / 2)]
    if not items:
        return []
    it = combine(items)
    box = np.array(ends)
    return [PartMass("harness", 0, "harness", False,
                     f"line mass: {len(leads)} leads (catalogues/wiring.toml: copper and PVC of their wires) of their "
                     "cut lengths along the routes of layout/harness_plan.py", (), 0.0, 0.0, 0.0, 0.0, it, it, None,
                     None, (tuple(box.min(axis=0)), tuple(box.max(axis=0))))]


def fastener_masses(p: Params, fasteners=None) -> list[PartMass]:
    """Every screw, insert, nut and pin of the design (:func:`swiftfin.cad.fastening.all_fasteners`) as a thin steel
    rod along its axis (its screw, insert and nut lumped together), one ``fasteners_link_<j>`` entry per link; the
    masses come from the catalogue (``Fastener.mass_kg``)."""
    if fasteners is None:
        from swiftfin.cad.fastening import all_fasteners
        fasteners = all_fasteners(p)
    pieces: dict[int, list[Inertial]] = {}
    for f in fasteners:
        a = units.length_m(np.asarray(f.head_mm, dtype=float))
        b = units.length_m(np.asarray(f.tip_mm, dtype=float))
        r = units.length_m(float(f.size) / 2 if f.kind == "dowel" else f.screw.nominal_diameter_mm / 2)
        pieces.setdefault(f.link, []).append(rod_inertial(f.mass_kg, a, b, r))
    out = []
    for link, items in sorted(pieces.items()):
        it = combine(items)
        pts = np.array([i.com for i in items])
        out.append(PartMass(f"fasteners_link_{link}", link, "fastener", False,
                            f"catalogue masses of {len(items)} screws, inserts, nuts and pins (catalogues/), as rods "
                            f"along their axes", (), 0.0, 0.0, 0.0, 0.0, it, it, None, None,
                            (tuple(pts.min(axis=0)), tuple(pts.max(axis=0)))))
    return out
