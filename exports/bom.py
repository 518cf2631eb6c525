"""The bill of materials: every bought item of the build with its quantity, size and where it goes.

One :class:`BomLine` per kind of item (screws of one size and length together, each cable side on its own line
since each has its own cut length). Sources of the lines:

* fasteners: :func:`swiftfin.cad.fastening.all_fasteners` (screws, set screws, heat-set inserts, nuts, dowel pins,
  and what a record's ``meta`` adds: washers ``meta["washer"]``, clips ``meta["clip"]``);
* bought parts: the parts of the build that are not printed (motors, battery, electronics ...), with their
  catalogue masses; the lumped mass placeholders among ``params.components`` are listed as such;
* cables: per joint and side, the cut length = route at rest (:func:`swiftfin.layout.geometry.cable_routes`) +
  its share of the spool wrap (half of ``spool.wraps`` turns round the drum's cable circle, plus the groove
  margin) + the anchor runs at both ends + ``CABLE_TAIL_MM`` at each end for the crimp or knot and handling;
* crimp sleeves (``catalogues/cable_parts.toml``): one at each end of every cable side;
* PTFE tube pieces by cut length (:func:`swiftfin.cad.cables.tube_runs`, mouth to seat), the total to buy, and the
  epoxy that bonds them in (``catalogues/adhesives.toml``);
* what closes the dry wall (:func:`seal_lines`): the cable glands' sleeves and grease, the screws' sealant;
* the wiring harness's leads by cut length and their connectors (:func:`harness_lines`);
* extra lines a part family declares (``PartSpec.meta["bom"]``: a list of dicts with the BomLine fields), e.g. a
  tensioner's bought pieces;
* the trim ballast (lead), from the mass model when the build computed one.

Written as ``bom.csv`` (:func:`bom_csv`) and shown in the report.
"""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass

from swiftfin.core.schema import Params

CABLE_TAIL_MM = 40.0
"""Cable left over at each end for the crimp loop or knot and for handling while tensioning [mm]: a loop
through a crimp sleeve takes ~2 x 10 mm, plus a hand's hold. Engineering default."""

FIELDS = ("item", "spec", "quantity", "unit", "where", "source")


@dataclass(frozen=True)
class BomLine:
    item: str          # "Socket head cap screw"
    spec: str          # "ISO 4762 M2 x 8"
    quantity: float    # count, or a length / mass for items sold by length or weight
    unit: str          # "pcs", "mm", "g"
    where: str         # the joints or parts it serves
    source: str        # where the size comes from

    def row(self) -> dict:
        q = int(self.quantity) if self.unit == "pcs" else round(self.quantity, 1)
        return {"item": self.item, "spec": self.spec, "quantity": q, "unit": self.unit, "where": self.where,
                "source": self.source}


_SCREW_NAMES = {"cap_screw": ("Socket head cap screw", "ISO 4762"),
                "set_screw": ("Set screw, flat point", "ISO 4026")}


def _where(items) -> str:
    items = sorted(set(items))
    return "; ".join(items) if len(items) <= 6 else "; ".join(items[:6]) + f"; and {len(items) - 6} more"


def fastener_lines(fasteners) -> list[BomLine]:
    """Screws, inserts, nuts, pins, washers and clips, grouped by what a builder orders."""
    groups: dict[tuple, list] = {}
    for f in fasteners:
        if f.kind == "dowel":
            key = ("Dowel pin, hardened", f"ISO 8734 {float(f.size):g} x {f.length_mm:g} m6", "catalogues/pins.toml")
        else:
            name, std = _SCREW_NAMES[f.kind]
            key = (name, f"{std} {f.size} x {f.length_mm:g}", "catalogues/fasteners.toml")
        groups.setdefault(key, []).append(f)
        if f.seat == "insert":
            s = f.screw
            groups.setdefault(("Heat-set insert, brass", f"{f.size} x {s.insert_length_mm:g} "
                               f"(OD {s.insert_outer_diameter_mm:g}, hole {s.insert_hole_mm:g})",
                               "catalogues/fasteners.toml (CNC Kitchen / Ruthex standard)"), []).append(f)
        elif f.seat == "nut":
            groups.setdefault(("Hex nut", f"ISO 4032 {f.size}", "catalogues/fasteners.toml"), []).append(f)
        for extra in ("washer", "clip"):
            if f.meta.get(extra):
                groups.setdefault((extra.capitalize() if extra == "washer" else "Retaining clip",
                                   str(f.meta[extra]), "catalogues/"), []).append(f)
    out = []
    for (item, spec, source), fs in sorted(groups.items()):
        out.append(BomLine(item, spec, len(fs), "pcs", _where(f.joins for f in fs), source))
    return out


def cable_lines(p: Params) -> list[BomLine]:
    """One line per cable side: its cut length [mm]."""
    from swiftfin.layout.geometry import cable_routes, spool_dims

    d = spool_dims(p)
    wrap_mm = (p.spool.wraps / 2 + p.spool.groove_margin_turns / 2) * math.pi * p.spool.drum_diameter_mm
    out = []
    for r in cable_routes(p):
        # the anchor runs: up the spool to the top of its upper flange, round the tendon sector to its anchor
        spool_anchor = d.groove_length_mm + d.flange_mm + p.spool.flange_height_mm
        sector = p.joints.tendon_moment_arm_mm * math.pi / 2 + p.joints.link_thickness_mm
        length = r.length_mm + wrap_mm + spool_anchor + sector + 2 * CABLE_TAIL_MM
        side = "left" if r.side > 0 else "right"
        out.append(BomLine("Cable", f"{p.cable.material}, {p.cable.diameter_mm:g} mm, cut {length:.0f} mm", 1, "pcs",
                           f"joint {r.joint + 1}, {side} side (route {r.length_mm:.0f} mm + wrap {wrap_mm:.0f} + "
                           f"anchors {spool_anchor + sector:.0f} + tails 2 x {CABLE_TAIL_MM:g})",
                           "cable_routes(p) and [spool], [cable]"))
    total = sum(float(x.spec.rsplit("cut ", 1)[1].split()[0]) for x in out)
    out.append(BomLine("Cable, total to buy", f"{p.cable.material}, {p.cable.diameter_mm:g} mm", round(total), "mm",
                       "all joints", "sum of the cut lengths above"))
    return out


def crimp_lines(p: Params) -> list[BomLine]:
    """Two crimp sleeves per cable side: one on the spool's end, one in the tendon sector's anchor."""
    from swiftfin.catalogues.cable_parts import crimp_sleeve
    from swiftfin.layout.geometry import cable_routes

    c = crimp_sleeve(p.cable.diameter_mm)
    routes = cable_routes(p)
    return [BomLine("Crimp sleeve, single barrel", f"for {c.cable_diameter_mm:g} mm cable: bore {c.bore_mm:g}, "
                    f"OD {c.outer_diameter_mm:g}, {c.length_mm:g} mm long", 2 * len(routes), "pcs",
                    "both ends of every cable side (spool anchor, tendon sector anchor)",
                    "catalogues/cable_parts.toml")]


TUBE_CUT_STEP_MM = 0.5
"""PTFE tube pieces are listed by cut length rounded down to this step [mm] (a knife and a rule cut no finer; a
piece a little short leaves its mouth a little inside the bore, one a little long would stand proud of it)."""


def tube_lines(p: Params) -> list[BomLine]:
    """The PTFE tube pieces by cut length (each from ``cad.cables.tube_runs``: its centre line from the mouth to
    its seat on the printed shoulder), the total to buy, and the epoxy that bonds them in (the clearance
    round each tube filled over its length)."""
    from swiftfin.cad.cables import TUBE_ADHESIVE, tube_runs
    from swiftfin.catalogues.adhesives import adhesive

    from swiftfin.layout.geometry import tube_bore_diameter_mm

    g = p.guides
    tubes = tube_runs(p)
    if not tubes:
        return []
    groups: dict[float, list[str]] = {}
    glue_mm3 = 0.0
    for t in tubes:
        cut = math.floor(t.length_mm / TUBE_CUT_STEP_MM + 1e-9) * TUBE_CUT_STEP_MM
        groups.setdefault(cut, []).append(t.label.removeprefix("tube_"))
        glue_mm3 += math.pi * ((tube_bore_diameter_mm(p, t.kind) / 2) ** 2 - (t.od_mm / 2) ** 2) * t.length_mm
    spec = f"PTFE, {g.ptfe_tube_od_mm:g} x {g.ptfe_tube_id_mm:g} mm, etched (bondable) outside"
    out = [BomLine("PTFE tube piece", f"{spec}, cut {cut:g} mm", len(labels), "pcs", _where(labels),
                   "cad.cables.tube_runs (mouth to seat)") for cut, labels in sorted(groups.items())]
    total = sum(cut * len(labels) for cut, labels in groups.items())
    out.append(BomLine("PTFE tube, total to buy", spec, total, "mm", "all guides and bulkheads",
                       "sum of the cut lengths above"))
    a = adhesive(TUBE_ADHESIVE)
    out.append(BomLine("Adhesive", a.description, math.ceil(glue_mm3 / 100) / 10, "mL",
                       "every PTFE tube in its bore, pushed onto its seat (fills the clearance round the tube)",
                       a.source))
    return out


def seal_lines(p: Params) -> list[BomLine]:
    """What closes the dry compartment's wall (catalogues/seals.toml): per cable gland a close PTFE sleeve cut to the
    gland's packed length, the grease packed round the cables, and the sealant the screws through the wall are
    bedded in. The glands' tubes themselves are PTFE tube pieces above (``tube_hull_...``)."""
    from swiftfin.cad.dry_check import bedded_screws, cable_glands
    from swiftfin.catalogues.seals import cable_gland, seal_item

    glands = cable_glands(p)
    out = []
    if glands:
        g = cable_gland()
        d = p.cable.diameter_mm
        sleeve = (f"PTFE capillary tube, {d + g.sleeve_diametral_clearance_mm:.1f} mm ID x "
                  f"{p.guides.ptfe_tube_id_mm:g} mm OD (pressed into the gland's tube)")
        groups: dict[float, list[str]] = {}
        for c in glands:
            cut = math.floor(c.packed_mm / TUBE_CUT_STEP_MM + 1e-9) * TUBE_CUT_STEP_MM
            groups.setdefault(cut, []).append(c.label)
        out += [BomLine("Cable gland sleeve", f"{sleeve}, cut {cut:g} mm", len(labels), "pcs", _where(labels),
                        "catalogues/seals.toml [cable_gland] (packed length: cad.dry_check.cable_glands)")
                for cut, labels in sorted(groups.items())]
        out.append(BomLine("Grease", g.grease, 1, "pcs", "packed round each cable in its gland's sleeve",
                           "catalogues/seals.toml [cable_gland]"))
    screws = [c.label for c in bedded_screws(p)]
    if screws:
        row = seal_item("bedded_screw")
        out.append(BomLine("Sealant", row["sealant"], 1, "pcs",
                           f"under the head and along the thread of the {len(screws)} screws through the dry wall",
                           row["source"]))
    return out


def bought_part_lines(p: Params, specs) -> list[BomLine]:
    groups: dict[tuple, list] = {}
    placeholders = {c.name for c in p.components if c.name == "fasteners"}
    for s in specs:
        if s.printed:
            continue
        base = s.label.rstrip("0123456789").rstrip("_") or s.label
        if base == "motor":
            spec = (f"NEMA {round(p.motor.frame_size_mm / 2.54):d} stepper, {p.motor.body_length_mm:g} mm body, "
                    f"{p.motor.holding_torque_nm:g} N m, {p.motor.mass_kg * 1000:g} g")
            item = "Stepper motor"
        elif s.label in placeholders:
            continue   # a mass placeholder for the screws, which are listed one by one
        elif s.meta.get("bom_item"):
            item, spec = s.meta["bom_item"], s.meta.get("bom_spec", "")
        else:
            spec = f"{s.mass_kg * 1000:g} g" if s.mass_kg else ""
            item = s.label.replace("_", " ").capitalize()
        groups.setdefault((item, spec, str(s.meta.get("source", ""))), []).append(s.label)
    return [BomLine(item, spec, len(labels), "pcs", _where(labels), source)
            for (item, spec, source), labels in groups.items()]


def declared_lines(specs) -> list[BomLine]:
    out = []
    for s in specs:
        for d in s.meta.get("bom", ()) or ():
            out.append(BomLine(d["item"], d["spec"], float(d["quantity"]), d.get("unit", "pcs"),
                               d.get("where", s.label), d.get("source", s.family)))
    return out


def harness_lines(p: Params) -> list[BomLine]:
    """The wiring harness (layout/harness_plan.py): each lead by its cut length, and the connectors crimped on."""
    from swiftfin.layout.harness_plan import harness
    out, housings = [], {}
    for h in harness(p):
        s = h.spec
        side = "+y" if h.side > 0 else "-y"
        what = f"motor_{h.joint} to the electronics" if h.joint else "the battery to the electronics"
        item = "Motor leads (the motor's own, trimmed)" if h.joint else "Battery snap with leads (PP3)"
        out.append(BomLine(item, f"{s.wires} x {s.wire_od_mm:g} mm wires, cut {h.cut_length_mm:.0f} mm", 1, "pcs",
                           f"{what}, {side} side (route {h.length_mm:.0f} mm + {100 * s.service_fraction:.0f} % + "
                           f"2 x {s.termination_mm:g} mm)", "layout/harness_plan.py, catalogues/wiring.toml"))
        housings.setdefault(s.connector, []).append(h.label)
    for connector, labels in housings.items():
        out.append(BomLine("Connector", connector, len(labels), "pcs", _where(labels), "catalogues/wiring.toml"))
    return out


def ballast_lines(mass_properties: dict | None) -> list[BomLine]:
    trim = (mass_properties or {}).get("trim") or {}
    if not trim.get("enabled") or not trim.get("possible", True) or not trim.get("mass_kg") or trim.get("placed"):
        return []
    return [BomLine("Trim ballast, lead", f"{trim['mass_kg'] * 1000:.1f} g (sphere of {2 * trim['sphere_radius_mm']:.1f} mm "
                    f"or shot in the pocket)", round(trim["mass_kg"] * 1000, 1), "g",
                    f"link {trim.get('link', 0)} at {trim.get('station_fraction', 0) * 100:.1f} % of the length",
                    "mass model (exports/water.py trim_ballast)")]


def bom_lines(p: Params, specs, fasteners, mass_properties: dict | None = None) -> list[BomLine]:
    """Every bought item of the build (see the module docstring)."""
    return (bought_part_lines(p, specs) + fastener_lines(fasteners) + cable_lines(p) + crimp_lines(p)
            + tube_lines(p) + seal_lines(p) + harness_lines(p) + declared_lines(specs) + ballast_lines(mass_properties))


def bom_csv(lines) -> str:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=FIELDS, lineterminator="\n")
    w.writeheader()
    for line in lines:
        w.writerow(line.row())
    return buf.getvalue()


def read_bom_csv(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))
