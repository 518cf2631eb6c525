"""Caudal fin: a lunate fin of NACA 00xx sections with a root tang that slots into the peduncle.

Planform (in the vertical x-z plane; span along z, symmetric about z = 0; eta = 2 z / b in [-1, 1]):

* span ``b = caudal_fin.span_mm``, area ``S = b^2 / caudal_fin.aspect_ratio``;
* chord ``c(eta) = c_tip + (c_0 - c_tip) sqrt(1 - eta^2)`` (an elliptic distribution on a tip chord
  ``c_tip = 3 min_thickness_mm``, so the tips stay printable). Its area is
  ``S = b (c_tip + (c_0 - c_tip) pi / 4)``, hence ``c_0 = c_tip + (S / b - c_tip) 4 / pi``;
* leading edge swept back by ``Lambda = caudal_fin.sweep_deg``: station of the leading edge
  ``s_LE(eta) = s_root + |eta| (b / 2) tan(Lambda)``; trailing edge ``s_TE = s_LE + c``. Both edges are swept
  back, the trailing edge concave: the crescent (lunate) shape.
* The root trailing edge (the fork) sits at the fork length ``s = L``, i.e. ``s_root = L - c_0`` (interpretation
  of body.length_mm as fork length); if that would put the root leading edge closer than
  ``print.clearance_assembly_mm`` behind the hull end, the fin moves aft to ``hull_end + clearance``.

Sections: NACA 00xx of thickness ``T = max(thickness_fraction c, min_thickness_mm)`` plus a linear ramp that
brings the trailing edge to ``min_thickness_mm``: ``y(xi) = c yt(xi, T/c) + xi (t_min/2 - c yt(1, T/c))``.
The sections are lofted (B-spline) through 2 K + 1 spanwise stations graded toward the tips
(eta = sin(pi/2 k/K)), ruled over the last interval at each tip (:func:`blade_solid`), so planform area and span
match the closed forms up to the loft's interpolation error.

Mount: a rectangular root tang in the x-z plane (:func:`tang_dims_mm`, sized from the peduncle's end section so the
hull does not depend on the planform) runs from 30 % of the root chord forward through the gap to the hull end
and ``mount_length_mm`` into the peduncle's socket. The fin is rigid with the last link (index ``joints.count``).

Root joint (issue 12: the old 0.3 mm of slop per side and both screws at one station let the fin rattle):

* **Keyed socket, declared fit.** The socket is the tang's rectangle plus ``caudal_fin.root_fit_clearance_mm`` on
  each side (0.1 mm: an FDM close fit, still assembled by hand). A rectangle cannot turn in its socket, so it is
  its own key; a dovetail would need the tang slid in from the side across the seam, which the split hull
  (halves joined at z = 0 through the socket) cannot offer, and its 45 deg flanks would be printed as overhangs.
* **Drawn onto a datum face, not centred in the clearance.** Four M2 cap screws (hull screws; at two stations
  along the body, :data:`swiftfin.layout.fin_plan.ROOT_SCREW_FRACTIONS` = 1/4 and 3/4 of the socket's length, one
  in each hull half at each station) enter from the +y side through counterbores of the peduncle's wall and form
  their thread in the tang (``seat = "self_tap"``: the 4 mm tang has no room for an insert's boss). Tightened,
  they pull the tang flat onto the socket's +y face: the fit clearance is left on the -y side only, so there is no
  play whatever the printer's tolerance, and the preload (friction on the face) carries the side force. The two
  stations 7.5 mm apart take the fin's bending moment about z as a couple instead of a single pivot.
* **Holes from the records.** The tang's pilots and the peduncle's clearance holes and counterbores are cut by
  the registry from :func:`swiftfin.layout.fin_plan.fin_fasteners`; this module only shapes the fin.
"""
from __future__ import annotations

import math

from swiftfin.cad.kernel import bd
import numpy as np

from swiftfin.layout import geometry as L
from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

SPAN_STATIONS_HALF = 8        # K: sections from root to each tip
CHORD_POINTS = 25             # points per surface of a section


from swiftfin.layout.fin_plan import (  # noqa: F401  the numbers, re-exported for the part family
    Planform, TangDims, planform, tang_back_station_mm, tang_dims_mm)


def section_wire(p: Params, pf: Planform, eta: float) -> bd.Wire:
    """Closed section at spanwise eta: spline over both surfaces (through the leading edge), line at the TE."""
    f = p.caudal_fin
    c = float(pf.chord_mm(eta))
    T = max(f.thickness_fraction * c, f.min_thickness_mm)
    xi = (1 - np.cos(np.linspace(0.0, math.pi, CHORD_POINTS))) / 2
    te_ramp = f.min_thickness_mm / 2 - c * float(L.naca_half_thickness(1.0, T / c))
    y = c * L.naca_half_thickness(xi, T / c) + xi * te_ramp
    x = -(float(pf.s_le_mm(eta)) + xi * c)
    z = eta * pf.span_mm / 2
    upper = [(float(a), float(b), z) for a, b in zip(x[::-1], y[::-1])]
    lower = [(float(a), float(-b), z) for a, b in zip(x[1:], y[1:])]
    spline = bd.Edge.make_spline(upper + lower)
    te = bd.Edge.make_line(spline.end_point(), spline.start_point())
    return bd.Wire([spline, te])


def blade_solid(p: Params) -> bd.Solid:
    """The lofted lunate blade alone (no tang): the solid whose planform the closed forms describe.

    Smooth (B-spline) between the stations next to the tips, ruled from there to each tip. The elliptic trailing
    edge runs into the tip plane tangentially, and a smooth loft through the tip section overshot it: its surface
    rose 0.4 um above the tip plane and folded back (the normal turning over within 0.01 mm of the tip), which the
    mesher turned into sliver triangles stacked four to an edge (39 such edges on the fin of
    tests/data/seeded_large_drum.toml at the export's 0.05 mm, 232 at 0.02; the default fin failed likewise when
    lofted through 25 sections instead of 17). A ruled piece is linear between its two sections, so it cannot
    overshoot; it differs from the smooth loft by 0.07 % of the default blade's volume."""
    pf = planform(p)
    K = SPAN_STATIONS_HALF
    etas = [math.sin(math.pi / 2 * k / K) for k in range(K, 0, -1)]
    etas = [-e for e in etas] + [0.0] + etas[::-1]
    wires = [section_wire(p, pf, e) for e in etas]
    middle = bd.Solid.make_loft(wires[1:-1])
    tips = [bd.Solid.make_loft(wires[:2], ruled=True), bd.Solid.make_loft(wires[-2:], ruled=True)]
    solids = middle.fuse(*tips).clean().solids()
    if len(solids) != 1:
        raise BuildError(f"caudal_fin: the blade's loft came out as {len(solids)} solids, expected one")
    return solids[0]


def fin_solid(p: Params) -> bd.Solid:
    """Blade + root tang (the root screws' pilots are cut by the registry from their records)."""
    blade = blade_solid(p)
    td = tang_dims_mm(p)
    s_back = tang_back_station_mm(p)
    tang = bd.Solid.make_box(s_back - td.s_front_mm, td.thickness_mm, td.height_mm,
                             bd.Plane(origin=(-s_back, -td.thickness_mm / 2, -td.height_mm / 2)))
    body = blade.fuse(tang).clean()
    solids = body.solids()
    if len(solids) != 1:
        raise BuildError(f"caudal_fin: expected one solid, got {len(solids)}")
    return solids[0]


def make_caudal_fin(p: Params) -> list[PartSpec]:
    """The caudal fin, label ``caudal_fin``, rigid with link ``joints.count``.

    Printed lying on its side (rx = 90 deg: the thickness direction becomes vertical); the symmetric
    sections need a little support or a brim under the lower surface.
    """
    pf = planform(p)
    return [PartSpec("caudal_fin", fin_solid(p), p.joints.count, "fin", print_rotation=(90.0, 0.0, 0.0),
                     meta={"span_mm": pf.span_mm, "area_mm2": pf.area_mm2, "root_chord_mm": pf.root_chord_mm})]
