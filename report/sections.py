"""The report's page sections: each takes what the caller computed (params, parts, mass properties, findings,
audit entries, plots, a fit folder) and returns that section's HTML. They format, they do not compute the design.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from swiftfin.core.schema import Params
from swiftfin.report.assets import FAMILY_COLORS, VERDICT_CLASS
from swiftfin.report.markup import badge, esc, img, notice, num, table, tile

#: the build folder's mass properties (exports) and a fit folder's report (calibration), named on the page
MASS_PROPERTIES_NAME = "mass_properties.json"
STEPS_NAME = "assembly_steps.json"
BOM_NAME = "bom.csv"
FIT_REPORT_NAME = "fit_report.json"


def sorted_findings(findings) -> list:
    """Failing rules first: by severity (worst first), then by margin (smallest first), then rule id."""
    def key(f):
        m = f.margin if f.margin is not None else math.inf
        return (-int(f.severity), m, f.rule_id)
    return sorted(findings, key=key)


def part_mass_index(mp: dict | None) -> dict[str, dict]:
    if not mp:
        return {}
    return {e["label"]: e for e in mp.get("parts", []) if isinstance(e, dict) and "label" in e}


def overview_section(p: Params, parts, mp, findings, audit, params_name: str) -> str:
    from swiftfin.design_rules import Severity

    tiles = []
    tiles.append(tile("body length", num(p.body.length_mm, ".0f", "mm"),
                      f"NACA 00{round(100 * p.body.naca_thickness_fraction):02d}, {p.joints.count} joints"))
    tiles.append(tile("tail-beat", num(p.swimming.tail_beat_frequency_hz, "g", "Hz"),
                      f"tail amplitude {1000 * p.swimming.tail_amplitude_m:g} mm, &lambda; = "
                      f"{p.swimming.wavelength_body_lengths:g} L"))
    tiles.append(tile("drive", f"{p.spool.drum_diameter_mm:g}&nbsp;mm spools",
                      f"{p.motor.holding_torque_nm:g} N&middot;m steppers, 1/{p.motor.microsteps} steps, "
                      f"{p.spool.wraps:g} wraps of {p.cable.diameter_mm:g} mm cable"))
    if mp and "total" in mp:
        t = mp["total"]
        tiles.append(tile("total mass", num(1000 * t["mass_kg"], ".0f", "g"),
                          f"paper: {1000 * t.get('paper_mass_kg', 1.2):.0f} g"))
        net = t.get("net_buoyancy_n")
        kind = "good" if net is not None and abs(net) <= p.environment.buoyancy_band_fraction * t["weight_n"] else "warn"
        tiles.append(tile("net buoyancy", num(net, "+.2f", "N"),
                          f"buoyancy {t['buoyancy_n']:.2f} N, weight {t['weight_n']:.2f} N", kind))
    else:
        tiles.append(tile("total mass", "&ndash;", "mass properties not computed in this build", "muted"))
    if parts is not None:
        n_pr = sum(1 for x in parts if x.printed)
        tiles.append(tile("parts", str(len(parts)), f"{n_pr} printed, {len(parts) - n_pr} bought"))
    else:
        tiles.append(tile("parts", "&ndash;", "no parts built for this report", "muted"))
    counts = {s: sum(1 for f in findings if f.severity is s) for s in Severity}
    worst = max((f.severity for f in findings), default=Severity.PASS)
    tiles.append(tile("design rules", badge(worst.name),
                      f"{counts[Severity.FAIL]} fail, {counts[Severity.WARN]} warn, {counts[Severity.PASS]} pass, "
                      f"{counts[Severity.NOT_EVALUATED]} not evaluated",
                      {"FAIL": "bad", "WARN": "warn"}.get(worst.name, "good")))
    holds = sum(e.holds is True for e in audit)
    bad = sum(e.holds is False for e in audit)
    tiles.append(tile("paper audit", f"{holds}/{len(audit)} hold", f"{bad} do not hold, "
                      f"{len(audit) - holds - bad} cannot be checked", "warn" if bad else "good"))
    return f'<div class="tiles">{"".join(tiles)}</div>'


def assembly_section(pics: dict | None, parts) -> str:
    if not pics:
        return notice("No parts were built for this report, so there is no picture of the assembly.")
    legend = "".join(
        f'<span class="swatch" style="background:rgb({int(255 * c[0])},{int(255 * c[1])},{int(255 * c[2])})"></span>'
        f'{esc(fam)}&ensp;' for fam, c in FAMILY_COLORS.items() if any(x.family == fam for x in parts))
    return (f'<figure class="wide">{img(pics["exterior"], "assembly, exterior")}'
            f'<figcaption>The assembled robot at rest, every part in place (nose left, body frame of layout/geometry.py). '
            f'Colours by part family: {legend}</figcaption></figure>'
            f'<figure class="wide">{img(pics["cutaway"], "assembly, cut-away")}'
            f'<figcaption>Cut-away: the upper hull halves hidden, showing the motor row, spools, guides and the '
            f'joint links.</figcaption></figure>')


def print_settings_text(p: Params) -> str:
    pr = p.print
    return (f"{pr.layer_height_mm:g} mm layers, {pr.perimeters} perimeters of {pr.line_width_mm:g} mm, "
            f"{pr.top_layers}/{pr.bottom_layers} top/bottom layers, {100 * pr.infill_fraction:g} % "
            f"{esc(pr.infill_pattern)} infill, {pr.nozzle_diameter_mm:g} mm nozzle, filament "
            f"{pr.filament_density_kg_m3:g} kg/m&sup3;")


def parts_section(p: Params, parts, part_pics: dict | None, mp: dict | None) -> str:
    if parts is None:
        return notice("No parts were built for this report.")
    masses = part_mass_index(mp)
    out = [f'<p class="lead">Print settings for every part (parameter file <code>[print]</code>): '
           f'{print_settings_text(p)}. Each part prints in the orientation shown by its rotation '
           f'(degrees about x, y, z, then dropped on the bed).</p>']
    if not masses:
        out.append(notice("Printed masses: mass properties not computed in this build (no "
                          f"<code>{MASS_PROPERTIES_NAME}</code>); the cards show the solid volume instead."))
    cards = []
    for x in parts:
        if not x.printed:
            continue
        e = masses.get(x.label)
        mass = (f'<span class="mass">{1000 * e["mass_kg"]:.1f} g</span> printed'
                if e and "mass_kg" in e else '<span class="mass muted">mass not computed</span>')
        vol = f"{x.volume_mm3 / 1000:.1f} cm&sup3; solid" if x.volume_mm3 is not None else ""
        size = ("bed footprint " + " &times; ".join(f"{v:.0f}" for v in x.print_size_mm) + " mm"
                if x.print_size_mm else "")
        rot = (f'rotation ({", ".join(f"{v:g}" for v in x.print_rotation)})&deg;, '
               if x.print_rotation is not None else "")
        if x.support_area_mm2 is not None:
            others = [a for r, a, fits in x.orientations if fits and tuple(r) != tuple(x.print_rotation or ())]
            alt = f" (other orientations tried: {', '.join(f'{a:.0f}' for a in others)})" if others else ""
            rot += f"support {x.support_area_mm2:.0f} mm&sup2; at {p.print.support_angle_deg:g}&deg;{alt}, "
        if x.thin_walls:     # exports/printability.thin_walls, thinnest first
            lw = p.print.line_width_mm
            w = x.thin_walls[0]
            under = sum(t.thickness_mm < lw for t in x.thin_walls)
            rot += (f"walls under {2 * lw:g} mm: {len(x.thin_walls)} ({under} under {lw:g}), thinnest "
                    f"{w.thickness_mm:.2f} at ({', '.join(f'{v:.0f}' for v in w.at_mm)}), ")
        if x.bridges:        # exports/printability.bridges over print.max_bridge_mm
            spans = [b for b in x.bridges if not b.hanging]
            hanging = len(x.bridges) - len(spans)
            if spans:
                b = max(spans, key=lambda b: b.span_mm)
                rot += (f"bridges over {p.print.max_bridge_mm:g} mm: {len(spans)}, longest {b.span_mm:.1f} mm over "
                        f"{b.area_mm2:.0f} mm&sup2; at ({', '.join(f'{v:.0f}' for v in b.at_mm)}), ")
            if hanging:
                rot += f"ceilings with no edge on material below: {hanging}, "
        pic = img(part_pics[x.label], x.label) if part_pics and x.label in part_pics else ""
        cards.append(f'<div class="card" id="part-{esc(x.label)}">{pic}<div class="cbody">'
                     f'<div class="cname">{esc(x.label)}</div>'
                     f'<div class="cmeta">{esc(x.family)} &middot; link {x.link}</div>'
                     f'<div>{mass}&ensp;<span class="muted">{vol}</span></div>'
                     f'<div class="cset">{size}<br>{rot}{p.print.layer_height_mm:g} mm layers, '
                     f'{p.print.perimeters} perimeters, {100 * p.print.infill_fraction:g} % '
                     f'{esc(p.print.infill_pattern)}</div></div></div>')
    out.append(f'<div class="cards">{"".join(cards)}</div>')
    bought = [x for x in parts if not x.printed]
    if bought:
        rows = []
        for x in bought:
            e = masses.get(x.label)
            m = e["mass_kg"] if e and "mass_kg" in e else x.catalogue_mass_kg
            rows.append([esc(x.label), esc(x.family), str(x.link), num(None if m is None else 1000 * m, ".1f", "g")])
        out.append("<h3>Bought parts</h3>" + table(["part", "family", "link", "catalogue mass"], rows, numeric={2, 3}))
    return "".join(out)


def rules_section(findings, note: str = "") -> str:
    rows, classes = [], []
    for f in sorted_findings(findings):
        unit = "" if f.unit == "-" else f.unit
        margin = "&ndash;" if f.margin is None else esc(f.margin_text()).replace(" ", "&nbsp;")
        bar = ""
        if f.margin is not None:
            w = min(100.0, abs(f.margin) * 100.0)
            bar = f'<span class="mbar {"neg" if f.margin < 0 else "pos"}" style="width:{w:.0f}%"></span>'
        detail = f'<div class="detail">{esc(f.detail)}</div>' if f.detail else ""
        value = "&ndash;" if f.value is None else esc(f.value_text()) + (f"&nbsp;{esc(unit)}" if unit else "")
        rows.append([f"<code>{esc(f.rule_id)}</code>{detail}", value,
                     esc(f.limit_text()) + (f"&nbsp;{esc(unit)}" if unit and f.limit is not None else ""),
                     f'<div class="margin">{margin}{bar}</div>', badge(f.severity.name), esc(f.source)])
        classes.append("row-" + VERDICT_CLASS.get(f.severity.name, "na"))
    return ('<p class="lead">Every rule of <code>design_rules/</code> applied to this design, failing rules first, '
            'then by margin (the relative distance to the limit; negative = violated).</p>'
            + (f'<p class="lead">{esc(note)}</p>' if note else "")
            + table(["rule", "value", "limit", "margin", "verdict", "source"], rows, "rules", classes, {1, 3}))


def mass_section(p: Params, mp: dict | None, mp_note: str) -> str:
    if not mp or "total" not in mp:
        return notice("Mass properties not computed in this build: no <code>mass_properties.json</code> was "
                      "found beside the build and none could be computed here. " + esc(mp_note))
    t = mp["total"]
    g = p.environment.gravity_m_s2
    tiles = [tile("total mass", num(1000 * t["mass_kg"], ".0f", "g"), f"paper Table 2: {1000 * t.get('paper_mass_kg', 1.2):.0f} g"),
             tile("displaced volume", num(1e6 * t["displaced_volume_m3"], ".0f", "cm\u00b3"), "sealed head + solids of the flooded tail"),
             tile("buoyancy", num(t["buoyancy_n"], ".2f", "N"), f"neutral mass {1000 * t['buoyancy_n'] / g:.0f} g"),
             tile("weight", num(t["weight_n"], ".2f", "N")),
             tile("net buoyancy", num(t["buoyancy_n"] - t["weight_n"], "+.2f", "N"),
                  "positive: floats", "good" if t["buoyancy_n"] >= t["weight_n"] else "warn"),
             tile("COB above COM", num(1000 * t.get("cob_above_com_m", float("nan")), "+.1f", "mm"),
                  "positive: self-righting"),
             tile("static pitch", num(t.get("static_pitch_deg", float("nan")), "+.1f", "deg"),
                  "positive: nose down", "good" if abs(t.get("static_pitch_deg", 90.0)) <= p.environment.max_static_pitch_deg
                  else "warn")]
    trim = mp.get("trim", {})
    if trim.get("possible"):
        tiles.append(tile("trim ballast", num(1000 * trim["mass_kg"], ".1f", "g"),
                          (f"lead shot in epoxy, centred at s = {-1000 * trim['fill_com_m'][0]:.1f} mm, z "
                           f"{1000 * trim['z_m']:.0f} mm ({1000 * trim['fill_miss_x_m']:+.1f} mm from the level "
                           f"trim's station)" if trim.get("placed") else
                           f"lead sphere at {trim['station_fraction']:.3f} L, z {1000 * trim['z_m']:.0f} mm")
                          + (f"; at most {1000 * trim['head_margin_kg']:.1f} g more at the head's centre keeps "
                             f"the lead inside the hull" if "head_margin_kg" in trim else "")))
    elif trim.get("enabled"):
        tiles.append(tile("trim ballast", "none", esc(trim.get("reason", "")), "warn"))
    out = [mp_note and f'<p class="lead">{esc(mp_note)}</p>' or "", f'<div class="tiles">{"".join(tiles)}</div>']
    links = mp.get("links", [])
    if links:
        rows = []
        for lk in links:
            com = lk.get("com_m_body", lk.get("com_m", [float("nan")] * 3))
            rows.append([esc(lk.get("name", lk.get("index"))), num(1000 * lk["mass_kg"], ".1f", "g"),
                         num(1000 * com[0], ".1f"), num(1000 * com[2], ".1f"),
                         num(1e6 * lk.get("displaced_volume_m3", float("nan")), ".0f"),
                         num(lk.get("inertia_kg_m2", {}).get("izz", float("nan")) * 1e6, ".1f"),
                         str(len(lk.get("parts", [])))])
        out.append("<h3>Per link</h3>" + table(
            ["link", "mass", "COM x [mm]", "COM z [mm]", "displaced [cm&sup3;]", "I<sub>zz</sub> [kg&middot;mm&sup2;]",
             "parts"], rows, numeric={1, 2, 3, 4, 5, 6}))
    parts = mp.get("parts", [])
    if parts:
        rows = []
        for e in sorted(parts, key=lambda e: (e.get("link", 0), -e.get("mass_kg", 0))):
            rows.append([esc(e["label"]), esc(e.get("family", "")), str(e.get("link", "")),
                         "printed" if e.get("printed") else "bought", num(1000 * e["mass_kg"], ".1f", "g"),
                         num(1e6 * e.get("volume_solid_m3", float("nan")), ".1f"),
                         num(1e6 * e.get("volume_material_m3", float("nan")), ".1f")])
        out.append("<h3>Per part</h3>" + table(
            ["part", "family", "link", "kind", "mass", "solid [cm&sup3;]", "plastic [cm&sup3;]"], rows,
            numeric={2, 4, 5, 6}))
    return "".join(out)


def plot_section(plot, alt: str) -> str:
    return f'<figure class="wide">{img(plot.png, alt)}<figcaption>{esc(plot.caption)}</figcaption></figure>'


def audit_section(audit) -> str:
    from swiftfin.design_rules.paper_audit import TOLERANCE

    rows, classes = [], []
    for e in audit:
        v = {True: ("holds", "pass"), False: ("does not hold", "fail"), None: ("cannot check", "na")}[e.holds]
        unit = "" if e.unit == "-" else e.unit
        rows.append(["<code>" + esc(e.entry_id).replace("_", "_<wbr>") + "</code>", esc(e.where), esc(e.quantity), num(e.paper, ".4g"),
                     num(e.recomputed, ".4g"), esc(unit), f'<span class="badge {v[1]}">{v[0]}</span>',
                     f'<span class="detail">{esc(e.reason)}</span>'])
        classes.append("row-" + v[1])
    holds = sum(e.holds is True for e in audit)
    bad = sum(e.holds is False for e in audit)
    return (f'<p class="lead">The numbers the paper derives from its own inputs, recomputed by '
            f'<code>physics/paper_audit.py</code> ({esc(TOLERANCE)}): {holds} hold, {bad} do not, '
            f'{len(audit) - holds - bad} cannot be checked.</p>'
            + table(["entry", "where", "quantity", "paper", "recomputed", "unit", "verdict", "why"], rows, "audit",
                    classes, {3, 4}))


def fit_section(fit_dir: Path | None) -> str:
    if fit_dir is None:
        return notice("No fit given. <code>swiftfin report --fit DIR</code> adds the before/after plots and the "
                      "effects found by a <code>swiftfin fit</code> run whose output is in DIR.", "info")
    fit_dir = Path(fit_dir)
    out = []
    rpath = fit_dir / FIT_REPORT_NAME
    rep = None
    if rpath.exists():
        try:
            rep = json.loads(rpath.read_text())
        except (OSError, json.JSONDecodeError) as exc:
            out.append(notice(f"{esc(rpath)} is not readable JSON: {esc(exc)}"))
    else:
        out.append(notice(f"No <code>{FIT_REPORT_NAME}</code> in {esc(fit_dir)}."))
    if isinstance(rep, dict):
        unit = rep.get("units", {}).get("rmse", "")
        b, fin = rep.get("baseline", {}), rep.get("final", {})
        tiles = [tile("family", esc(rep.get("family", "?")), esc(rep.get("description", ""))),
                 tile("samples", str(rep.get("n_samples", "?")),
                      f"{rep.get('n_train', '?')} train, {rep.get('n_holdout', '?')} held out"),
                 tile("held-out RMSE, base model", num(b.get("rmse_holdout"), ".4g", unit)),
                 tile("held-out RMSE, with effects", num(fin.get("rmse_holdout"), ".4g", unit),
                      "residual white" if fin.get("residual_white") else "structure left in the residual",
                      "good" if fin.get("residual_white") else "warn")]
        out.append(f'<div class="tiles">{"".join(tiles)}</div>')
        rows = []
        for e in rep.get("added_effects", []):
            shown = e.get("physical") or e.get("params") or {}
            phys = "<br>".join(f"{esc(k)} = {num(v.get('value'), '.4g')} &plusmn; {num(v.get('std'), '.2g')} "
                               f"{esc('' if v.get('unit') == '-' else v.get('unit', ''))}" for k, v in shown.items())
            ind = ", ".join(e.get("indistinguishable_from", []))
            rows.append([f"<b>{esc(e.get('name'))}</b>" + (f'<div class="detail">indistinguishable from: {esc(ind)}</div>' if ind else ""),
                         phys or "&ndash;", num(e.get("rmse_holdout_before"), ".4g"), num(e.get("rmse_holdout_after"), ".4g"),
                         esc(e.get("confidence", ""))])
        if rows:
            out.append("<h3>Effects found</h3>" + table(
                ["effect", "fitted parameters (&plusmn; standard uncertainty)", f"held-out RMSE before [{esc(unit)}]",
                 f"held-out RMSE after [{esc(unit)}]", "confidence"], rows, numeric={2, 3}))
        else:
            out.append(notice("The fit added no effect: the base model explains the data as well as any candidate.",
                              "info"))
        if rep.get("holdout"):
            out.append(f'<p class="detail">Held out: {esc(rep["holdout"])}</p>')
        if rep.get("unexplained_structure"):
            out.append(notice("The final residual still has structure that no candidate effect explains.", "warn"))
    named = {}
    if isinstance(rep, dict) and isinstance(rep.get("plots"), dict):
        named = {str(v): str(k) for k, v in rep["plots"].items()}
    pngs = sorted(fit_dir.glob("*.png"))
    for pth in pngs:
        title = named.get(pth.name, pth.stem).replace("_", " ")
        out.append(f'<figure class="fitplot">{img(pth.read_bytes(), pth.stem)}<figcaption>{esc(title)} '
                   f'(<code>{esc(pth.name)}</code>)</figcaption></figure>')
    if not pngs:
        out.append(notice(f"No plots (*.png) in {esc(fit_dir)}."))
    return "".join(out)



def read_bom(path: Path) -> list[dict] | None:
    """The rows of a build's ``bom.csv`` (None if it is not readable: the section says so)."""
    import csv
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            return list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError, csv.Error):
        return None


def bom_section(rows: list[dict] | None) -> str:
    if rows is None:
        return notice("No bill of materials: this report was not made by a build (or its bom.csv is unreadable).")
    body = [[esc(r.get("item", "")), esc(r.get("spec", "")), esc(r.get("quantity", "")), esc(r.get("unit", "")),
             esc(r.get("where", "")), esc(r.get("source", ""))] for r in rows]
    n = sum(1 for r in rows if r.get("unit") == "pcs" and str(r.get("quantity", "")).isdigit())
    return (f"<p>Every bought item of this build ({len(rows)} lines; <code>bom.csv</code> in the build folder): the "
            f"fasteners as the parts place them, the bought parts, each cable side's cut length, and what the part "
            f"families declare. {n} of the lines are counted in pieces.</p>"
            + table(["Item", "Size", "Qty", "Unit", "Where", "Source"], body, cls="bom"))


def read_steps(path: Path) -> dict | None:
    """The build's ``assembly_steps.json``; None when it is not readable JSON with a list of steps."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    return data if isinstance(data, dict) and isinstance(data.get("steps"), list) else None


def _fastener_summary(labels: list[str]) -> str:
    """'4 x joint_3_pin_*' style: fastener labels grouped by their stem (the text before the last _<n>)."""
    groups: dict[str, int] = {}
    for lb in labels:
        head, _, tail = lb.rpartition("_")
        stem = f"{head}_*" if tail.isdigit() and head else lb
        groups[stem] = groups.get(stem, 0) + 1
    return ", ".join(f"{n} &times; <code>{esc(k)}</code>" if n > 1 else f"<code>{esc(k)}</code>"
                     for k, n in groups.items())


def steps_section(steps: dict | None, pics: dict | None) -> str:
    if not steps:
        return notice("No assembly steps: this report was not made by a build (or its assembly_steps.json is "
                      "unreadable).")
    out = [f"<p>The order to put the fish together ({len(steps['steps'])} steps; <code>{STEPS_NAME}</code> in the "
           f"build folder). Found by taking the finished assembly apart one part at a time: each part's way in, "
           f"along the arrow's axis from outside everything already in place, was proved clear on the meshes "
           f"({steps.get('paths_proved', 0)} paths, {steps.get('pair_paths', 0)} part pairs along them). Every "
           f"fastener is listed at the step that puts the last of its parts in ({steps.get('fasteners', 0)} in all; "
           f"sizes and lengths in the bill of materials); a screw that must be driven before a part goes on "
           f"(its key passes there) comes in an earlier step. In each picture the parts already in place are grey, "
           f"the step's parts are set back against their way in.</p>"]
    for note in steps.get("notes", []):
        out.append(notice(esc(note)))
    for s in steps["steps"]:
        head = f"<h3>Step {int(s['number'])}</h3><p>{esc(s.get('text', ''))}.</p>"
        facts = []
        if s.get("parts"):
            facts.append(f"<b>Parts</b> (in along {esc(s.get('direction', ''))}): "
                         + ", ".join(f"<code>{esc(q)}</code>" for q in s["parts"]))
        if s.get("fasteners"):
            facts.append(f"<b>Fasteners</b>: {_fastener_summary(s['fasteners'])}")
        if s.get("threads"):
            facts.append("<b>Cables, tubes and leads</b>: " + ", ".join(f"<code>{esc(q)}</code>" for q in s["threads"]))
        pic = (pics or {}).get(s["number"])
        alt = f"assembly step {int(s['number'])}, exploded"
        fig = f'<figure class="wide">{img(pic, alt)}</figure>' if pic else ""
        out.append(head + "".join(f"<p>{f}</p>" for f in facts) + fig)
    return "".join(out)


def solve_section(solve: dict | None, plot=None, name: str = "") -> str:
    """The trade-offs of a ``swiftfin solve --json`` result: the nearest passing design's changes, the Pareto front
    over speed, mass and power (table and plot) and the rules that bind along it."""
    if solve is None:
        return notice("No solve given. <code>swiftfin solve --json FILE</code>, then <code>swiftfin report --solve "
                      "FILE</code>, adds the nearest passing design and the Pareto front over speed, mass and power.",
                      "info")
    out = []
    passes = bool(solve.get("passes"))
    tiles = [tile("nearest design", "passes" if passes else "none passes",
                  f"{len(solve.get('changes', []))} key(s) changed", "good" if passes else "warn"),
             tile("designs evaluated", str(solve.get("designs_evaluated", "?")), esc(name))]
    front = solve.get("front")
    if front:
        tiles.append(tile("on the front", str(front.get("size", len(front.get("points", [])))),
                          f"of {front.get('passing', '?')} passing, {front.get('sampled', '?')} sampled"))
    out.append(f'<div class="tiles">{"".join(tiles)}</div>')
    rows = [[f"<code>{esc(c.get('key'))}</code>", num(c.get("from"), ".4g") if not isinstance(c.get("from"), str)
             else esc(c.get("from")), num(c.get("to"), ".4g") if not isinstance(c.get("to"), str) else esc(c.get("to")),
             esc(", ".join(c.get("buys", [])) or "-")] for c in solve.get("changes", [])]
    if rows:
        out.append("<h3>The nearest passing design</h3>" + table(["key", "from", "to", "what it buys (fails when "
                                                                  "undone alone)"], rows))
    if not solve.get("passes") and solve.get("failing"):
        out.append(notice("The closest design found still fails: " + esc(", ".join(solve["failing"]))))
    if front:
        pts = list(front.get("points") or [])
        if plot is not None:
            out.append(f'<figure class="wide">{img(plot.png, "Pareto front: speed against power")}'
                       f'<figcaption>{esc(plot.caption)}</figcaption></figure>')
        if pts:
            k = min(len(pts), 12)
            shown = [pts[int(round(i))] for i in np.linspace(0, len(pts) - 1, k)]
            rows = []
            for q in shown:
                ch = ", ".join(f"{esc(key.split('.', 1)[-1])}={esc(v) if isinstance(v, str) else num(v, '.4g')}"
                               for key, v in q.get("changes", {}).items())
                rows.append([num(q.get("speed_m_s"), ".3f"), num(q.get("mass_kg"), ".3f"), num(q.get("power_w"), ".2f"),
                             f"<code>{esc(q.get('binding'))}</code>",
                             esc(", ".join(q.get("limits_speed", [])) or "- (power or mass)"),
                             f'<span class="detail">{ch or "(the design itself)"}</span>'])
            out.append("<h3>Along the front, fastest first</h3>" + table(
                ["speed [m/s]", "mass [kg]", "power [W]", "least margin", "fails 5 % faster", "changes"], rows,
                numeric={0, 1, 2}))
            counts: dict = {}
            for q in pts:
                for r in q.get("limits_speed") or ["(none: power or mass, not a rule)"]:
                    counts[r] = counts.get(r, 0) + 1
            out.append('<p class="detail">What stops the front\'s designs from beating 5 % faster: '
                       + esc(", ".join(f"{r} ({n})" for r, n in sorted(counts.items(), key=lambda kv: -kv[1])))
                       + ".</p>")
        for n in front.get("notes", []):
            out.append(f'<p class="detail">{esc(n)}</p>')
    return "".join(out)
