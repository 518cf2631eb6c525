"""The trim ballast as parts: the mass model of every other part says how much lead levels the fish and where
(:func:`swiftfin.exports.water.trim_ballast`), the plan pours it where the hull can take it
(:mod:`swiftfin.layout.ballast_plan`), the CAD makes the fill and its dams (:mod:`swiftfin.cad.ballast`). The dams'
own plastic changes the trim, so trim, fill and dams are made again until the fill's ends settle
(:data:`SETTLED_MM`). Application layer: it joins the mass model (exports) and the CAD.
"""
from __future__ import annotations

import dataclasses

from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

PASSES = 6
"""Most rounds of trim -> fill -> dams -> trim; the default design settles in 3."""
SETTLED_MM = 0.01
"""The rounds stop when the fill's ends move less than this [mm]."""
LEAD_BOX_SAMPLES = 8
"""Samples of a lead's centre line per keep-out box."""
KEEP_OUT_SKIPPED = ("hull", "fin", "cable", "ptfe", "fastener", "seal", "ballast")
"""Families whose parts the fill need not keep clear of by their boxes (the shell it is poured against, and what
runs along the shell or lies in its seam)."""


def _line_boxes(p: Params) -> list:
    """The boxes of the cables' pieces, the PTFE tubes and the wiring harness's leads at rest, ``(label, link, lo,
    hi)`` in mm: they run along the shell, where a fill is poured (cad/cables.py, layout/harness_plan.py)."""
    import numpy as np

    from swiftfin.cad.cables import cable_pieces, tube_runs
    from swiftfin.layout.harness_plan import harness
    out = []
    for c in cable_pieces(p):
        pts = np.asarray(c.points_mm, float)
        out.append((c.label, c.link, tuple(pts.min(0) - c.radius_mm), tuple(pts.max(0) + c.radius_mm)))
    for t in tube_runs(p):
        pts = np.asarray(t.points_mm, float)
        out.append((t.label, t.link, tuple(pts.min(0) - t.od_mm / 2), tuple(pts.max(0) + t.od_mm / 2)))
    for h in harness(p):          # the leads, a box per few samples of their centre lines (one box would fill the head)
        pts = np.asarray(h.centre_line_mm, float)
        for k in range(0, len(pts) - 1, LEAD_BOX_SAMPLES):
            chunk = pts[k:k + LEAD_BOX_SAMPLES + 1]
            out.append((h.label, 0, tuple(chunk.min(0) - h.diameter_mm / 2), tuple(chunk.max(0) + h.diameter_mm / 2)))
    return out


def ballast_specs(p: Params, specs, meshes: dict | None = None, memo=None, jobs: int | None = 1,
                  progress=None) -> list:
    """The trim ballast's PartSpecs (its printed dams, then the fill) for the design's other parts ``specs``
    (``meshes``, ``memo``, ``jobs``: as :func:`swiftfin.exports.massprops.mass_properties` takes them). Empty when
    ``environment.trim_ballast`` is off or no lead can trim the fish (the mass model then says why); BuildError
    when the lead that levels the fish has no room in the hull."""
    import trimesh

    from swiftfin.cad.ballast import make_ballast_parts
    from swiftfin.exports.brep import tessellate_trimesh
    from swiftfin.exports.massprops import mass_properties
    from swiftfin.layout.ballast_plan import plan_ballast

    if not p.environment.trim_ballast:
        return []
    specs, meshes = list(specs), dict(meshes or {})
    boxes = {}
    for s in specs:
        m = meshes.get(s.label)
        if m is None:
            bb = s.solid.bounding_box()
            boxes[s.label] = ((bb.min.X, bb.min.Y, bb.min.Z), (bb.max.X, bb.max.Y, bb.max.Z))
        else:
            m = m if isinstance(m, trimesh.Trimesh) else trimesh.Trimesh(m.vertices, m.faces, process=False)
            boxes[s.label] = (tuple(map(float, m.bounds[0])), tuple(map(float, m.bounds[1])))
    dams, ends, plan, made = [], None, None, []

    def own(stage, labels, key, compute):       # the dams change from round to round under one label
        if memo is None or any(lb in {d.label for d in dams} for lb in labels):
            return compute()
        return memo(stage, labels, key, compute)
    for _ in range(PASSES):
        dam_meshes = {d.label: tessellate_trimesh(d.solid, p.export.mesh_tolerance_mm,
                                                  p.export.mesh_angular_tolerance_deg) for d in dams}
        trim = mass_properties(p, specs + dams, {**meshes, **dam_meshes}, memo=own, jobs=jobs).trim
        if not (trim.get("possible") or trim.get("sphere_only")):     # a fill may go where the sphere cannot
            if progress:
                progress(f"  trim ballast: none ({trim.get('reason', 'environment.trim_ballast is off')})")
            return []
        keep = [(s.label, *boxes[s.label]) for s in specs
                if s.link == trim["link"] and s.family not in KEEP_OUT_SKIPPED] + [
            (label, lo, hi) for label, link, lo, hi in _line_boxes(p) if link == trim["link"]]
        plan, why = plan_ballast(p, trim["mass_kg"], 1000 * trim["x_m"],
                                 1000 * trim.get("z_wanted_m", trim.get("z_m", 0.0)), int(trim["link"]), keep,
                                 prefer=None if plan is None else (plan.piece, plan.sigma, plan.z_level_mm))
        if plan is None:
            raise BuildError(f"trim ballast: {1000 * trim['mass_kg']:.1f} g of lead levels the fish at s = "
                             f"{-1000 * trim['x_m']:.1f} mm, but no fill of lead shot in epoxy fits in link "
                             f"{trim['link']}: {why}")
        made = make_ballast_parts(p, plan)
        dams = [s for s in made if s.printed]
        settled = ends is not None and max(abs(u - v) for u, v in zip(plan.s_mm, ends)) < SETTLED_MM
        ends = plan.s_mm
        if settled:
            break
    # the last round's trim was made with the dams before these (settled to SETTLED_MM): the fill takes the mass
    # the trim asks with these, so that the fish is neutral to the mass model's precision (its volume is the plan's,
    # a few parts in 1e5 from that mass over the fill's density)
    trim = mass_properties(p, specs + dams, {**meshes, **{d.label: tessellate_trimesh(
        d.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg) for d in dams}},
        memo=own, jobs=jobs).trim
    made = [s if s.printed else dataclasses.replace(s, mass_kg=float(trim["mass_kg"])) for s in made]
    if progress:
        progress(f"  trim ballast: {1000 * plan.mass_kg:.1f} g of fill ({1000 * plan.lead_kg:.1f} g of shot) in "
                 f"{plan.bonded_to}, s = {plan.s_mm[0]:.1f}..{plan.s_mm[1]:.1f} mm, its centre "
                 f"{plan.miss_x_mm:+.1f} mm from the level trim's station")
    return made
