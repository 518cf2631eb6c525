"""Water: the volume the fish displaces, its centre, the water a link holds, and the trim ballast, in SI units.

Buoyancy: a sealed link displaces the closed outer envelope of the body (the NACA 00xx elliptical sections of
layout/geometry.py, integrated numerically, :func:`envelope_volume_mm3`) over its stations; the last one only up to
the back face of the dry compartment's rear wall (:func:`swiftfin.layout.hull_plan.dry_bulkhead`): behind it, in the
joint gap, only the solids of its parts displace water (:func:`behind_dry_wall`, exact B-rep), and the water round
them moves with the link. (The clevis room is a wet pocket in the wall's back face, about 2 cm^3 on the default
design, counted as displaced: an error of 0.1 %.) Plus the part of the caudal fin behind the hull end (exact B-rep,
:func:`_fin_outside_volume`). The sealed envelope ahead of the wall is dry: the seals that keep it so are checked on
the solids (cad/dry_check.py). A flooded link (``hull.flooded_from_joint``) carries the water inside its
envelope (:func:`envelope_inertial`). :func:`trim_ballast` sizes and places the lead that makes the fish neutral
and level. The sum per link is done by :func:`swiftfin.exports.massprops.mass_properties`.
"""
from __future__ import annotations

import math

import numpy as np

from swiftfin.core import units
from swiftfin.core.schema import Params
from swiftfin.exports.brep import VolumeProps, _wrapped, solid_volume_props
from swiftfin.exports.inertia import Inertial, combine, make_inertial
from swiftfin.exports.line_masses import link_of_station
from swiftfin.exports.parallel import memoized
from swiftfin.exports.print_model import PartMass, _common
from swiftfin.layout import geometry as layout
from swiftfin.layout.ballast_plan import fill_density_kg_m3


def envelope_section_mm(p: Params, s_mm):
    """Outer half-width and half-height of the skinned body at station s [mm] (0 outside the hull)."""
    s = np.asarray(s_mm, dtype=float)
    inside = (s >= 0) & (s <= layout.hull_end_mm(p))
    a = np.where(inside, layout.naca_half_width_mm(p, s), 0.0)
    return a, p.body.height_to_width * a


def envelope_volume_mm3(p: Params, s0_mm: float, s1_mm: float, n: int = 4001) -> tuple[float, float]:
    """Volume [mm^3] and station of the centroid [mm] of the skinned body between two stations (Simpson)."""
    from scipy.integrate import simpson
    s = np.linspace(s0_mm, s1_mm, n)
    a, b = envelope_section_mm(p, s)
    area = np.pi * a * b
    V = float(simpson(area, x=s))
    return V, (float(simpson(area * s, x=s)) / V if V > 0 else 0.5 * (s0_mm + s1_mm))


def envelope_inertial(p: Params, s0_mm: float, s1_mm: float, density_kg_m3: float, n: int = 400) -> Inertial:
    """The hull's closed outer envelope between stations s0 and s1 as a uniform body (elliptical slices of
    :func:`envelope_section_mm`, each a thin elliptic disc: I_xx = m (a^2 + b^2) / 4, I_yy = m (b^2 / 4 + ds^2 / 12),
    I_zz = m (a^2 / 4 + ds^2 / 12)), body frame, SI."""
    edges = np.linspace(s0_mm, s1_mm, n + 1)
    mids, ds = 0.5 * (edges[1:] + edges[:-1]), (s1_mm - s0_mm) / n
    a, b = envelope_section_mm(p, mids)
    a_m, b_m, ds_m = units.length_m(a), units.length_m(b), units.length_m(ds)
    m = density_kg_m3 * math.pi * a_m * b_m * ds_m
    items = [make_inertial(mi, (-units.length_m(si), 0.0, 0.0),
                           np.diag([mi * (ai**2 + bi**2) / 4, mi * (bi**2 / 4 + ds_m**2 / 12),
                                    mi * (ai**2 / 4 + ds_m**2 / 12)]))
             for mi, si, ai, bi in zip(m, mids, a_m, b_m) if mi > 0]
    return combine(items)


def trim_ballast(p: Params, mass_kg: float, com_m, volume_m3: float, cob_m, flooded_links) -> dict:
    """The lead ballast that makes the fish neutral (weight = buoyancy) and level (COM under the COB), placed on
    the hull's vertical plane of symmetry (its height: :func:`ballast_height`).

    Neutral: ``M + m = rho_w (V + v)`` with ``v = m / rho_b`` when the ballast sits in a flooded link (it
    displaces water) and ``v = 0`` in a sealed one. Level: ``(M x_com + m x) / (M + m) = (V x_cob + v x) / (V + v)``,
    so ``x = (rho_w V x_cob - M x_com) / (m - rho_w v)``. Returns the numbers and, when no ballast can do it (the
    fish sinks, or the place falls outside the hull), ``possible`` False and the reason."""
    rho_w, rho_b = p.environment.water_density_kg_m3, fill_density_kg_m3(p)   # lead shot set in epoxy
    M, V = float(mass_kg), float(volume_m3)
    x_com, x_cob = float(com_m[0]), float(cob_m[0])
    out = {"ballast_density_kg_m3": rho_b, "excess_buoyancy_kg": rho_w * V - M}
    if rho_w * V - M <= 0:
        return {**out, "possible": False,
                "reason": f"the fish sinks by {M - rho_w * V:.4g} kg: ballast cannot trim it (it needs more flotation: environment.flotation_foam_segments, foam_density_kg_m3)"}
    x_m = None
    for in_flooded in (True, False):
        m = (rho_w * V - M) / (1.0 - rho_w / rho_b) if in_flooded else rho_w * V - M
        v = m / rho_b if in_flooded else 0.0
        x_m = (rho_w * V * x_cob - M * x_com) / (m - rho_w * v)
        link = link_of_station(p, -1000.0 * x_m)
        if flooded_links[min(link, len(flooded_links) - 1)] == in_flooded:
            break
    s_mm = -1000.0 * x_m
    r_mm = 1000.0 * (3.0 * m / rho_b / (4.0 * math.pi)) ** (1.0 / 3.0)
    s_lo, s_hi = 0.0, layout.hull_end_mm(p)
    a, b = envelope_section_mm(p, s_mm)
    room = float(min(a, b)) - p.hull.wall_thickness_mm - r_mm
    out.update({"mass_kg": m, "x_m": x_m, "station_fraction": s_mm / p.body.length_mm, "link": link,
                "in_flooded_link": bool(flooded_links[min(link, len(flooded_links) - 1)]),
                "sphere_radius_mm": r_mm})
    if not (s_lo < s_mm < s_hi) or room <= 0:
        return {**out, "possible": False, "sphere_only": s_lo < s_mm < s_hi,
                "reason": f"the ballast would have to sit at station {s_mm:.0f} mm ({s_mm / p.body.length_mm:.3f} L), "
                          f"{'outside the hull' if not (s_lo < s_mm < s_hi) else 'where a sphere of it does not fit'}"}
    z_room_mm = _vertical_room_mm(float(a), float(b), p.hull.wall_thickness_mm + r_mm)
    return {**out, "possible": True, "z_m": float(-units.length_m(z_room_mm)),
            "z_room_m": float(units.length_m(z_room_mm))}


def trim_margin_kg(p: Params, mass_kg: float, com_m, volume_m3: float, cob_m, flooded_links, at_x_m: float) -> float:
    """How much more mass, added at station ``at_x_m`` (body x, m), the trim can still level: the least added mass
    for which :func:`trim_ballast` finds no place for its lead (it would leave the hull or the section's room), by
    bisection to 0.01 g. Every gram added takes a gram of lead away, and added aft of the lead it moves the rest
    forward (``x = (rho_w V x_cob - M x_com - dm x_add) / (m - dm)`` in a sealed link). 0 when no lead trims the
    fish as it is; the whole excess buoyancy when no added mass there moves the lead out. The parts inside are not
    counted (:func:`ballast_height` keeps the lead clear of them): a bound from above."""
    M, com = float(mass_kg), np.asarray(com_m, float)
    excess = p.environment.water_density_kg_m3 * float(volume_m3) - M

    def fits(dm: float) -> bool:
        c = (M * com + dm * np.array([at_x_m, 0.0, 0.0])) / (M + dm)
        return bool(trim_ballast(p, M + dm, c, volume_m3, cob_m, flooded_links).get("possible"))

    if excess <= 0 or not fits(0.0):
        return 0.0
    lo, hi = 0.0, excess * (1 - 1e-9)
    if fits(hi):
        return float(excess)
    while hi - lo > 1e-5:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if fits(mid) else (lo, mid)
    return float(lo)


def _vertical_room_mm(a_mm: float, b_mm: float, clear_mm: float) -> float:
    """How far up (or down) the vertical axis of an elliptic section (half-width a, half-height b) a point can
    sit and stay ``clear_mm`` from the outline (bisection on the distance to the sampled ellipse; on a tall
    section the sides, not the crown, stop a sphere first). 0 when the centre itself is not clear."""
    t = np.linspace(0.0, np.pi, 2001)
    ex, ez = a_mm * np.sin(t), b_mm * np.cos(t)

    def clear(z: float) -> bool:
        return float(np.min(np.hypot(ex, ez - z))) >= clear_mm

    if not clear(0.0):
        return 0.0
    lo, hi = 0.0, b_mm
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if clear(mid) else (lo, mid)
    return lo


def ballast_height(trim: dict, link_inertial, keep_out=(), clearance_m: float = 0.0) -> dict:
    """Height of the trim ballast: where it adds no yaw-roll coupling to the link that carries it, clear of the
    other parts.

    The trim fixes the ballast's mass and station (:func:`trim_ballast`); its height is free inside the hull.
    On the floor it gives the largest righting lever, but a lead far forward (or aft) of its link's centre of
    mass and low gives the link a product of inertia ``I_xz``: its principal axes tilt, a yaw torque (every
    tail beat's recoil) then rolls it in phase, and the rectified ``(I_xx - I_zz) w_x w_z`` pitches the
    swimming fish (MuJoCo, default design, 30 s free at 3 Hz: head ``I_xz`` 3.5e-4 kg m^2 on the floor -> a steady
    8.0 deg nose down; 0 -> 1.3 deg, within a degree of the best height; README, *Trim*). So the ballast's
    height is where its link's ``I_xz`` about the link's new COM is zero,
    ``z = z_L + I_xz,L / (mu dx)`` (``mu`` the reduced mass of link and ballast, ``dx`` the ballast's station
    less the link's COM; off-diagonal parallel-axis term ``-mu dx dz``), or the nearest height to it that is
    inside the section's room (``trim['z_room_m']`` either side of the axis) and keeps the sphere
    ``clearance_m`` from the bounding box of every part in ``keep_out`` (``(label, ((x0, y0, z0), (x1, y1, z1)))``
    in metres, body frame) that it would meet. ``I_xz(z)`` is linear, so the nearest height is the best one.
    Returns the trim updated with ``z_m`` and the link's ``I_xz`` on the floor and at the chosen height, or
    ``possible`` False with the reason when no height is free."""
    m, x_b = float(trim["mass_kg"]), float(trim["x_m"])
    r = float(trim["sphere_radius_mm"]) * 1e-3
    M, c, I = link_inertial.mass_kg, link_inertial.com, link_inertial.inertia
    mu, dx = M * m / (M + m), x_b - float(c[0])
    room = float(trim["z_room_m"])

    def ixz(z: float) -> float:
        return float(I[0, 2] - mu * dx * (z - float(c[2])))

    floor = -room
    want = floor if abs(mu * dx) < 1e-12 else float(c[2]) + I[0, 2] / (mu * dx)
    gap = r + clearance_m
    blocked, names = [], []
    for label, (lo, hi) in keep_out:
        if lo[0] < x_b + gap and hi[0] > x_b - gap and lo[1] < gap and hi[1] > -gap:
            blocked.append((lo[2] - gap, hi[2] + gap))
            names.append(label)
    free = [(-room, room)]                     # the room less every blocked band
    for b0, b1 in blocked:
        free = [piece for f0, f1 in free for piece in ((f0, min(f1, b0)), (max(f0, b1), f1)) if piece[1] > piece[0]]
    if not free:
        return {**trim, "possible": False, "sphere_only": True, "z_wanted_m": want,
                "reason": f"no height at station {-1000 * x_b:.0f} mm holds the {1000 * r:.1f} mm lead sphere inside "
                          f"the hull clear of {', '.join(names)}"}
    z = min((float(np.clip(want, f0, f1)) for f0, f1 in free), key=lambda zz: abs(zz - want))
    return {**trim, "z_m": z, "z_floor_m": floor, "z_wanted_m": want, "clear_of": tuple(names),
            "link_ixz_on_floor_kg_m2": ixz(floor), "link_ixz_kg_m2": ixz(z)}


def _ballast_part(p: Params, trim: dict) -> PartMass:
    m, r = trim["mass_kg"], units.length_m(trim["sphere_radius_mm"])
    c = np.array([trim["x_m"], 0.0, trim["z_m"]])
    it = make_inertial(m, c, 0.4 * m * r * r * np.eye(3))
    bbox = (tuple(c - r), tuple(c + r))
    return PartMass("trim_ballast", int(trim["link"]), "ballast", False,
                    "computed: sphere of lead shot in epoxy (layout/ballast_plan.py) that makes the fish neutral and "
                    "level (exports.massprops.trim_ballast)", (), m / fill_density_kg_m3(p), 0.0,
                    m / fill_density_kg_m3(p), 0.0, it, it, None, None, bbox)


def _outside_piece(part, x_end_mm: float, big_mm: float, whole=None) -> VolumeProps | None:
    """Volume properties of the part of a solid behind the plane x = x_end (None if none of it is).

    ``whole``: a function giving the whole solid's properties (the export integrated them already). Where the part
    lies mostly behind the plane (the caudal fin behind the hull's end: its root tongue alone is ahead), the piece
    ahead is integrated and taken from the whole, which is exact for volumes and moments: the fin's lofted blade
    cost 1.9 s to cut and integrate, its tongue 0.03 s, and the two ways agree to 3e-12 of the volume."""
    from build123d import Box, Pos
    box = part.solid.bounding_box()
    lo, hi = box.min.X, box.max.X
    if whole is not None and hi > x_end_mm and x_end_mm - lo > hi - x_end_mm:
        ahead = Pos(x_end_mm + big_mm / 2, 0, 0) * Box(big_mm, big_mm, big_mm)
        inside = solid_volume_props(_common(_wrapped(part.solid), ahead.wrapped))
        return _difference(whole(), inside) if inside.volume_mm3 > 0 else whole()
    cut = Pos(x_end_mm - big_mm / 2, 0, 0) * Box(big_mm, big_mm, big_mm)
    pr = solid_volume_props(_common(_wrapped(part.solid), cut.wrapped))
    return pr if pr.volume_mm3 > 0 else None


def _difference(whole: VolumeProps, piece: VolumeProps) -> VolumeProps | None:
    """The properties of ``whole`` less its ``piece`` (a part of it): volumes and first moments subtract; the
    second moments about the whole's centroid (parallel axes) subtract, then move to the rest's centroid."""
    v = whole.volume_mm3 - piece.volume_mm3
    if v <= 0:
        return None
    cw, cp = np.asarray(whole.centroid_mm), np.asarray(piece.centroid_mm)
    c = (whole.volume_mm3 * cw - piece.volume_mm3 * cp) / v

    def shift(d, vol):     # the parallel-axis term of a body of volume vol whose centroid is d from the point
        return vol * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    piece_about_w = np.asarray(piece.second_moment_mm5) + shift(cp - cw, piece.volume_mm3)
    second = np.asarray(whole.second_moment_mm5) - piece_about_w - shift(c - cw, v)
    return VolumeProps(float(v), tuple(float(x) for x in c), tuple(tuple(float(x) for x in row) for row in second))


def behind_dry_wall(p: Params, parts, memo=None, meshes: dict | None = None):
    """The last sealed link (``None`` when it is the whole fish: see :func:`swiftfin.layout.hull_plan.dry_bulkhead`),
    the back face of its dry compartment's rear wall [mm], and the volume properties of each of that link's parts'
    pieces behind the wall (the clevis lugs and stops in the joint gap: solids in water)."""
    from swiftfin.layout.hull_plan import dry_bulkhead
    dry = dry_bulkhead(p)
    if dry is None or dry.rear_joint is None:
        return None, 0.0, []
    link = p.hull.flooded_from_joint - 1
    x_wall = -dry.s_back_mm
    pieces = []
    for part in parts:
        if part.link != link or getattr(part, "solid", None) is None:
            continue
        mesh = (meshes or {}).get(part.label)
        x_min = float(mesh.bounds[0][0]) if mesh is not None else part.solid.bounding_box().min.X
        if x_min - p.export.mesh_tolerance_mm >= x_wall:
            continue
        big = 4.0 * p.body.length_mm
        pr = memoized(memo, "outside_piece", (part.label,), [x_wall, big],
                      lambda part=part: _outside_piece(part, x_wall, big))
        if pr is not None:
            pieces.append(pr)
    return link, dry.s_back_mm, pieces


def _fin_outside_volume(p: Params, parts, memo=None, meshes: dict | None = None) -> tuple[float, np.ndarray, int, list]:
    """Volume [mm^3], centroid [mm] and link of the parts behind the hull end (the caudal fin), and the volume
    properties of each piece (for the water a flooded link does not carry there)."""
    x_end = -layout.hull_end_mm(p)
    V, first, link, pieces = 0.0, np.zeros(3), -1, []
    for part in parts:
        mesh = (meshes or {}).get(part.label)
        x_min = float(mesh.bounds[0][0]) if mesh is not None else part.solid.bounding_box().min.X
        if x_min - p.export.mesh_tolerance_mm >= x_end:     # the B-rep lies within the mesh tolerance of its mesh
            continue
        big = 4.0 * p.body.length_mm
        whole = (lambda part=part: memoized(memo, "solid_props", (part.label,), None,
                                            lambda: solid_volume_props(part.solid)))
        pr = memoized(memo, "outside_piece", (part.label,), [x_end, big],
                      lambda part=part, whole=whole: _outside_piece(part, x_end, big, whole))
        if pr is not None:
            V += pr.volume_mm3
            first = first + pr.volume_mm3 * np.asarray(pr.centroid_mm)
            link = max(link, part.link)
            pieces.append(pr)
    return V, (first / V if V > 0 else first), link, pieces
