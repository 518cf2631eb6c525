"""The trim ballast as solids: the fill of lead shot in epoxy and the printed dams that hold it while it cures
(numbers: :mod:`swiftfin.layout.ballast_plan`; body frame at rest, mm).

The fill is the shell's hollow (its inner surface shrunk by the bond gap: a loft of the inner ellipses, as the
cradles') between its stations, beyond its level ``|z| = z_level`` on its half's side; a dam is the same loft over
its own stations beyond ``|z| = z_dam`` (it stands :data:`~swiftfin.layout.ballast_plan.DAM_RISE_MM` proud of the
fill). The dams are printed flat on their aft face (a plate: no support); the fill is bought (weighed shot and epoxy),
its mass the plan's.

Not a family of the registry: what they are depends on the mass model of every other part (the trim), so the
application builds them after the rest (``swiftfin.pipeline.place_ballast``).
"""
from __future__ import annotations

from swiftfin.cad.cradle import inner_loft
from swiftfin.cad.kernel import bd
from swiftfin.cad.link import box, isect, one_solid
from swiftfin.cad.part import PartSpec
from swiftfin.catalogues.adhesives import adhesive
from swiftfin.catalogues.ballast import ballast_fill
from swiftfin.core.schema import Params
from swiftfin.layout.ballast_plan import DAM_LABEL, FILL, FILL_LABEL, BallastPlan
from swiftfin.layout.cradle_plan import CRADLE_ADHESIVE

LOFT_STEP_MM = 1.0
"""Station step of the inner-surface loft (the nose's sections change fast: 1 mm keeps the fill's volume within
0.1 % of the plan's integral)."""


def _loft(p: Params, s0: float, s1: float, gap_mm: float) -> bd.Solid:
    """The shell's hollow between stations s0 and s1, its inner surface shrunk by ``gap_mm``, at 1 mm steps."""
    return inner_loft(p, s0, s1, gap_mm, max(2, int(round((s1 - s0) / LOFT_STEP_MM)) + 1))


def _beyond(p: Params, plan: BallastPlan, s0: float, s1: float, level: float, label: str) -> bd.Solid:
    big = 200.0
    z0, z1 = (level, big) if plan.sigma > 0 else (-big, -level)
    return one_solid(isect(_loft(p, s0, s1, plan.gap_mm), box(-s1 - 1, -s0 + 1, -big, big, z0, z1)), label)


def fill_solid(p: Params, plan: BallastPlan) -> bd.Solid:
    return _beyond(p, plan, plan.s_mm[0], plan.s_mm[1], plan.z_level_mm, FILL_LABEL)


def dam_solid(p: Params, plan: BallastPlan, k: int) -> bd.Solid:
    d0, d1 = plan.dams[k]
    return _beyond(p, plan, d0, d1, plan.z_dam_mm, dam_label(plan, k))


def dam_label(plan: BallastPlan, k: int) -> str:
    return DAM_LABEL if len(plan.dams) == 1 else f"{DAM_LABEL}_{'fore' if k == 0 else 'aft'}"


def make_ballast_parts(p: Params, plan: BallastPlan) -> list[PartSpec]:
    """The dams (printed, on their aft face) and the fill (bought: weighed shot and epoxy)."""
    fill, bond = ballast_fill(FILL), adhesive(CRADLE_ADHESIVE)
    half = "upper" if plan.sigma > 0 else "lower"
    out = []
    for k in range(len(plan.dams)):
        out.append(PartSpec(label=dam_label(plan, k), solid=dam_solid(p, plan, k), link=plan.link, family="ballast",
                            print_rotation=(0.0, -90.0, 0.0), meta={"bonded_to": plan.bonded_to, "bom": []}))
    lead_g, epoxy_ml = 1000 * plan.lead_kg, plan.binder_kg / fill.binder_density_kg_m3 * 1e6
    where = (f"{plan.bonded_to}, s = {plan.s_mm[0]:.1f}..{plan.s_mm[1]:.1f} mm, to |z| = {plan.z_level_mm:.2f} mm "
             f"from the seam")
    out.append(PartSpec(label=FILL_LABEL, solid=fill_solid(p, plan), link=plan.link, family="ballast",
                        printed=False, mass_kg=plan.mass_kg, meta={
                            "bonded_to": plan.bonded_to, "plan": plan,
                            "source": f"computed: {fill.description}, {plan.density_kg_m3:.0f} kg/m^3 "
                                      f"({fill.source}); mass and place from the trim (layout/ballast_plan.py)",
                            "bom_item": f"Trim ballast: lead shot, #9 ({fill.shot_diameter_mm:g} mm)",
                            "bom_spec": f"{lead_g:.1f} g weighed out, set in epoxy ({1000 * plan.mass_kg:.1f} g of "
                                        f"fill, {plan.volume_mm3 / 1000:.2f} cm^3), in {where}",
                            "bom": [
                                {"item": "Epoxy", "spec": f"{bond.description}: sets the shot in the {half} half "
                                 f"({1000 * plan.binder_kg:.1f} g) and bonds the dam", "unit": "mL",
                                 "quantity": round(epoxy_ml * 1.2 + 0.05, 1), "where": where, "source": fill.source},
                            ]}))
    return out
