"""The seam gasket's numbers, measured on the built gasket (the part of :mod:`swiftfin.cad.seal`), and its outline
drawing: the compression at the gap's extremes against the sheet's band, the contact stress at the least compression
against the water's pressure at the design depth, the sealing ring's narrowest strip and the least web of sponge a
hole leaves (the findings ``seal.seam_gasket_*``: :func:`swiftfin.design_rules.rules.built_seam_gasket_findings`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.cad.part import PartSpec
from swiftfin.catalogues.seals import seam_gap_tolerance_mm, seam_gasket
from swiftfin.core.schema import Params

@dataclass(frozen=True)
class GasketNumbers:
    gap_mm: float
    compression_range: tuple[float, float]      # least, most [-]
    band: tuple[float, float]
    contact_stress_min_kpa: float               # at the least compression
    water_pressure_kpa: float                   # at the design depth
    safety_factor: float
    area_mm2: float
    min_width_mm: float                         # the sheet's least strip
    ring_closed_at_min_width: bool              # the sealing ring survives an opening by min_width_mm
    narrow_at_mm: tuple[float, float] | None    # where the ring breaks, if it does
    strip_mm: float                             # the widest opening the ring survives (its narrowest strip)
    web_mm: float                               # the least sponge between a hole and an edge
    web_at: str                                 # that hole
    min_web_mm: float
    screws: int
    load_per_screw_n: float                     # the sponge's push at the most compression / screws

    @property
    def problems(self) -> list[str]:
        out = []
        lo, hi = self.compression_range
        if lo < self.band[0] - 1e-9 or hi > self.band[1] + 1e-9:
            out.append(f"compression {lo * 100:.1f}-{hi * 100:.1f} % outside the sheet's band "
                       f"{self.band[0] * 100:.0f}-{self.band[1] * 100:.0f} %")
        if self.contact_stress_min_kpa < self.safety_factor * self.water_pressure_kpa:
            out.append(f"contact stress {self.contact_stress_min_kpa:.1f} kPa at the least compression under "
                       f"{self.safety_factor:g} x the water's {self.water_pressure_kpa:.1f} kPa")
        if not self.ring_closed_at_min_width:
            at = "" if self.narrow_at_mm is None else f" at ({self.narrow_at_mm[0]:.1f}, {self.narrow_at_mm[1]:.1f}) mm"
            out.append(f"the sealing ring is narrower than the sheet's least strip {self.min_width_mm:g} mm{at}")
        if self.web_mm < self.min_web_mm - 1e-9:
            out.append(f"{self.web_at}: {self.web_mm:.2f} mm of sponge to the edge, under {self.min_web_mm:g} mm")
        return out

    @property
    def ok(self) -> bool:
        return not self.problems


def compression_range(p: Params, gap_mm: float) -> tuple[float, float]:
    """The sheet's least and most compression: the gap +/- :func:`swiftfin.catalogues.seals.seam_gap_tolerance_mm`
    (the limiter's cutting tolerance, each printed face off flat)."""
    return seam_gasket().compression_range(gap_mm, seam_gap_tolerance_mm())


def sponge_stress_kpa(compression: float) -> float:
    """Contact stress of the sponge at ``compression`` [kPa] (``SeamGasket.stress_kpa``)."""
    return seam_gasket().stress_kpa(compression)


def section_polygons(solid, z_mm: float) -> list[np.ndarray]:
    """The solid's section at height ``z_mm`` as closed polygons (x, y) (manifold3d's slice of its mesh)."""
    from swiftfin.exports.brep import tessellate_trimesh
    return _mesh_section(tessellate_trimesh(solid, 0.02, 5.0), z_mm)


def ring_survives_opening(polys: list[np.ndarray], width_mm: float) -> tuple[bool, tuple[float, float] | None]:
    """Whether a disc of diameter ``width_mm`` can travel all round the gasket's sealing ring (its region between
    the outline and the largest hole, the cavity): the ring eroded by half the width still encloses the cavity. If
    not, roughly where it breaks: the largest piece an opening by that width (erode, dilate back) removes."""
    import manifold3d as m3d
    cs = m3d.CrossSection([np.asarray(pl, float) for pl in polys], m3d.FillRule.EvenOdd)
    cavity = _largest_hole(cs)
    if cavity is None:
        return True, None
    eroded = cs.offset(-width_mm / 2, m3d.JoinType.Round, 2.0, 64)
    hole_after = _largest_hole(eroded)
    if hole_after is not None and hole_after >= cavity * (1 - 1e-6):
        return True, None
    opened = eroded.offset(width_mm / 2, m3d.JoinType.Round, 2.0, 64)
    lost = (cs - opened).decompose()
    big = max(lost, key=lambda c: c.area()) if lost else None
    if big is None:
        return False, None
    b = big.bounds()
    return False, ((b[0] + b[2]) / 2, (b[1] + b[3]) / 2)


def narrowest_strip_mm(polys: list[np.ndarray], upper_mm: float, resolution_mm: float = 0.01) -> float:
    """The widest disc that travels all round the sealing ring (:func:`ring_survives_opening`), found by bisection
    to ``resolution_mm`` up to ``upper_mm``: the ring's narrowest strip [mm]."""
    lo, hi = 0.0, upper_mm
    if ring_survives_opening(polys, hi)[0]:
        return hi
    while hi - lo > resolution_mm:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ring_survives_opening(polys, mid)[0] else (lo, mid)
    return lo


def _largest_hole(cs) -> float | None:
    """Area of the largest hole of a cross-section (mm^2), None if it has none."""
    import manifold3d as m3d
    holes = []
    for piece in cs.decompose():
        polys = piece.to_polygons()
        if not polys:
            continue
        outer = max(polys, key=lambda pl: abs(_area(pl)))
        filled = m3d.CrossSection([outer])
        holes += [h.area() for h in (filled - piece).decompose()]
    return max(holes) if holes else None


def _area(pl) -> float:
    pl = np.asarray(pl, float)
    x, y = pl[:, 0], pl[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def gasket_numbers(p: Params, spec: PartSpec) -> GasketNumbers:
    """The gasket's judgement on its solid (see the module docstring): its section at mid-gap, the sealing ring
    (every contour but the holes round the limiters and dowels) opened by the sheet's least strip, and the web of
    sponge each hole leaves to the nearest other contour."""
    sheet = seam_gasket()
    gap = float(spec.meta["gap_mm"])
    lo, hi = compression_range(p, gap)
    polys = section_polygons(spec.solid, -gap / 2)
    holes = [(lb, np.array([x, y]), r) for lb, x, y, r in spec.meta["holes"]]

    def hole_of(pl) -> int | None:
        c = np.asarray(pl, float).mean(axis=0)
        for i, (_, xy, r) in enumerate(holes):
            if np.linalg.norm(c - xy) < 0.5 * r:
                return i
        return None

    ring = [pl for pl in polys if hole_of(pl) is None]
    closed, where = ring_survives_opening(ring, sheet.min_width_mm())
    strip = narrowest_strip_mm(ring, 4 * sheet.min_width_mm())
    web, web_at = math.inf, ""
    edges = np.vstack([_densify(pl) for pl in ring]) if ring else np.zeros((0, 2))
    for lb, xy, r in holes:
        if len(edges):
            d = float(np.min(np.linalg.norm(edges - xy, axis=1))) - r
            if d < web:
                web, web_at = d, lb
    area = float(spec.meta["area_mm2"])
    screws = int(spec.meta["screws"])
    depth = p.environment.design_depth_m
    return GasketNumbers(gap, (lo, hi), (sheet.compression_min_fraction, sheet.compression_max_fraction),
                         sponge_stress_kpa(lo),
                         p.environment.water_density_kg_m3 * p.environment.gravity_m_s2 * depth / 1000.0,
                         sheet.pressure_safety_factor, area, sheet.min_width_mm(), closed, where, strip, web, web_at,
                         sheet.min_web_mm, screws, sponge_stress_kpa(hi) * area / 1000.0 / max(screws, 1))


def _densify(pl, step_mm: float = 0.05) -> np.ndarray:
    """The polygon's edges sampled every ``step_mm`` (its vertices and the points between)."""
    pl = np.asarray(pl, float)
    out = []
    for a, b in zip(pl, np.roll(pl, -1, axis=0)):
        n = max(1, int(np.linalg.norm(b - a) / step_mm))
        out.append(a + (b - a) * np.arange(n)[:, None] / n)
    return np.vstack(out)


def gasket_outline_svg_of(spec: PartSpec, mesh=None) -> str:
    """The built gasket's outline drawing (:func:`gasket_outline_svg`): its mesh (or its solid's) cut at mid-gap."""
    gap = float(spec.meta["gap_mm"])
    polys = _mesh_section(mesh, -gap / 2) if mesh is not None else section_polygons(spec.solid, -gap / 2)
    sheet = seam_gasket()
    return gasket_outline_svg(polys, f"; {sheet.sheet}; {len(spec.meta['holes'])} holes; "
                                     f"{float(spec.meta['area_mm2']) / 100:.1f} cm^2")


def _mesh_section(mesh, z_mm: float) -> list[np.ndarray]:
    import manifold3d as m3d
    man = m3d.Manifold(m3d.Mesh(vert_properties=np.asarray(mesh.vertices, np.float32),
                                tri_verts=np.asarray(mesh.faces, np.uint32)))
    return [np.asarray(c) for c in man.slice(z_mm).to_polygons()]


def gasket_outline_svg(polys: list[np.ndarray], holes_note: str = "") -> str:
    """The gasket's outline as an SVG drawing at 1:1 in mm, seen from above (the body's +y up the page, its nose,
    +x, to the right): every closed contour of its section, filled even-odd, for the die maker or a knife."""
    pts = np.vstack(polys)
    x0, y0 = pts.min(axis=0) - 5
    x1, y1 = pts.max(axis=0) + 5
    w, h = x1 - x0, y1 - y0
    paths = " ".join("M " + " L ".join(f"{x - x0:.3f},{y1 - y:.3f}" for x, y in pl) + " Z" for pl in polys)
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.3f}mm" height="{h:.3f}mm" '
            f'viewBox="0 0 {w:.3f} {h:.3f}">\n'
            f'<title>seam gasket, 1:1, mm{holes_note}</title>\n'
            f'<path d="{paths}" fill="#ccc" fill-rule="evenodd" stroke="black" stroke-width="0.1"/>\n</svg>\n')
