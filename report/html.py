"""The design report: one self-contained HTML page (``DIR/report.html``) per build.

Everything is inlined: pictures and plots as base64 ``data:image/png`` URIs, the style sheet in a ``<style>``
element, system fonts only, no script, no link to anything outside the file; it opens offline anywhere.

Sections (ids in :data:`SECTIONS`): overview (the design's key numbers), assembly (rendered exterior and a
cut-away without the upper hull halves), parts (a picture of every printable part with its printed mass and
print settings; bought parts in a table), design rules (failing first, coloured by verdict, with margins),
mass (per part, per link, total mass and buoyancy), transmission efficiency (the paper's Figure 8 recomputed),
one tail-beat (joint angles, step rates), body wave, paper audit, and the fit (when a fit folder is given).
A section whose inputs are missing says so on the page instead of showing invented numbers.
"""
from __future__ import annotations

import base64
import hashlib
import functools
import html
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from swiftfin import __version__
from swiftfin.core.schema import Params

REPORT_NAME = "report.html"
MASS_PROPERTIES_NAME = "mass_properties.json"
FIT_REPORT_NAME = "fit_report.json"

SECTIONS = (("overview", "Overview"), ("assembly", "Assembly"), ("parts", "Parts"), ("rules", "Design rules"),
            ("mass", "Mass"), ("efficiency", "Efficiency"), ("tailbeat", "Tail-beat"), ("wave", "Body wave"),
            ("audit", "Paper audit"), ("fit", "Fit"))

FAMILY_COLORS = {"hull": (0.62, 0.72, 0.82), "link": (0.95, 0.65, 0.25), "fin": (0.24, 0.43, 0.57),
                 "spool": (0.89, 0.34, 0.18), "mount": (0.46, 0.69, 0.25), "guide": (0.63, 0.42, 0.84),
                 "bought": (0.33, 0.33, 0.36)}
OTHER_COLOR = (0.7, 0.7, 0.7)
VERDICT_CLASS = {"PASS": "pass", "INFO": "info", "NOT_EVALUATED": "na", "WARN": "warn", "FAIL": "fail"}


# ----------------------------------------------------------------------------------------------- inputs
@dataclass(frozen=True)
class ReportPart:
    """What the page needs of one part: its rest mesh in the body frame [mm] and its print facts."""
    label: str
    family: str
    link: int
    printed: bool
    vertices: np.ndarray
    faces: np.ndarray
    print_size_mm: tuple[float, float, float] | None = None
    volume_mm3: float | None = None
    print_rotation: tuple[float, float, float] | None = None   # None: not known (e.g. read from a build folder)
    catalogue_mass_kg: float | None = None


def as_report_part(part) -> ReportPart:
    """A ReportPart from a ReportPart or a ``swiftfin.pipeline.BuiltPart``."""
    if isinstance(part, ReportPart):
        return part
    spec, exp = part.spec, part.export
    return ReportPart(spec.label, spec.family, int(spec.link), bool(spec.printed), np.asarray(exp.mesh.vertices),
                      np.asarray(exp.mesh.faces), tuple(float(v) for v in exp.print_size_mm), float(exp.volume_mm3),
                      tuple(float(v) for v in spec.print_rotation), spec.mass_kg)


class Progress:
    """A line per step on a terminal (stderr), nothing when stderr is not a TTY (CI logs)."""

    def __init__(self, enabled: bool | None = None, stream=None):
        self.stream = stream or sys.stderr
        self.enabled = (hasattr(self.stream, "isatty") and self.stream.isatty()) if enabled is None else enabled
        self.t0 = time.perf_counter()

    def __call__(self, msg: str) -> None:
        if self.enabled:
            print(f"  [{time.perf_counter() - self.t0:6.1f} s] {msg}", file=self.stream, flush=True)


# ----------------------------------------------------------------------------------------------- helpers
def esc(x: Any) -> str:
    return html.escape(str(x), quote=True)


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def img(png: bytes, alt: str, cls: str = "") -> str:
    c = f' class="{cls}"' if cls else ""
    return f'<img{c} src="{data_uri(png)}" alt="{esc(alt)}">'


def num(v, fmt: str = ".4g", unit: str = "") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "&ndash;"
    s = format(v, fmt)
    return f"{s}&nbsp;{esc(unit)}" if unit and unit != "-" else s


def table(headers: list[str], rows: list[list[str]], cls: str = "", row_classes: list[str] | None = None,
          numeric: set[int] | None = None) -> str:
    """An HTML table; cells are HTML already (escape text before)."""
    numeric = numeric or set()
    th = "".join(f'<th{" class=num" if i in numeric else ""}>{h}</th>' for i, h in enumerate(headers))
    body = []
    for k, r in enumerate(rows):
        rc = f' class="{row_classes[k]}"' if row_classes and row_classes[k] else ""
        tds = "".join(f'<td{" class=num" if i in numeric else ""}>{c}</td>' for i, c in enumerate(r))
        body.append(f"<tr{rc}>{tds}</tr>")
    return f'<div class="tablewrap"><table class="{cls}"><thead><tr>{th}</tr></thead><tbody>{"".join(body)}</tbody></table></div>'


def notice(text: str, kind: str = "missing") -> str:
    return f'<p class="notice {kind}">{text}</p>'


def tile(label: str, value: str, sub: str = "", kind: str = "") -> str:
    return (f'<div class="tile {kind}"><div class="tlabel">{esc(label)}</div><div class="tvalue">{value}</div>'
            f'<div class="tsub">{sub}</div></div>')


def badge(name: str) -> str:
    cls = VERDICT_CLASS.get(name, "na")
    text = {"NOT_EVALUATED": "not evaluated"}.get(name, name.lower())
    return f'<span class="badge {cls}">{esc(text)}</span>'


# ----------------------------------------------------------------------------------------------- data
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


# ----------------------------------------------------------------------------------------------- sections
#: share of each part's triangles drawn in an assembly view (vertex clustering, per part, so that a part's view
#: mesh does not change when another part does): about 120 000 of the default design's ~330 000, still smaller
#: than the pixels of the hull's curvature at 2400 x 860 supersampled pixels for 520 mm of fish.
ASSEMBLY_VIEW_FACE_FRACTION = 0.35


def render_pictures(parts: list[ReportPart], progress: Callable[[str], None],
                    memo=None, jobs: int | None = 1) -> tuple[dict, dict[str, bytes], float]:
    """Assembly pictures ({'exterior', 'cutaway'}) and one picture per printed part; returns the seconds taken.
    ``memo(stage, labels, extra, compute)``: the application's store of pictures and view meshes, keyed by the
    parts' content (None: render every picture); ``jobs``: processes for the part pictures."""
    from swiftfin.report.render import MeshItem, png_bytes, render

    from swiftfin.exports.parallel import map_parts
    from swiftfin.report.render import cluster_decimate

    t0 = time.perf_counter()
    items = {p.label: MeshItem(p.vertices, p.faces, FAMILY_COLORS.get(p.family, OTHER_COLOR), p.label) for p in parts}

    def stored(stage: str, labels: tuple, extra, compute):
        return compute() if memo is None else memo(stage, labels, extra, compute)

    def picture(what: list, w: int, h: int, az: float, el: float) -> bytes:
        return stored("picture", tuple(it.name for it in what),
                      [w, h, az, el, [list(it.color) for it in what], [len(it.faces) for it in what]],
                      lambda: png_bytes(render(what, w, h, azimuth_deg=az, elevation_deg=el, max_faces=10**9)))

    def view_item(it: MeshItem) -> MeshItem:
        n = max(200, int(ASSEMBLY_VIEW_FACE_FRACTION * len(it.faces)))
        v, f = stored("view_mesh", (it.name,), [n], lambda: cluster_decimate(it.vertices, it.faces, n))
        return MeshItem(v, f, it.color, it.name)

    out = {}
    progress("rendering the assembly (exterior)")
    view = {label: view_item(it) for label, it in items.items()}
    out["exterior"] = picture(list(view.values()), 1200, 430, 62, 22)
    progress("rendering the assembly (cut-away, upper hull halves hidden)")
    cut = [view[p.label] for p in parts if not (p.family == "hull" and p.label.endswith("_upper"))]
    out["cutaway"] = picture(cut, 1200, 430, 58, 40)
    printed = [p for p in parts if p.printed]
    progress(f"rendering {len(printed)} parts")
    pngs = map_parts(lambda p: picture([items[p.label]], 360, 250, 62, 28), printed, jobs)
    pics = {p.label: png for p, png in zip(printed, pngs)}
    return out, pics, time.perf_counter() - t0


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


def rules_section(findings) -> str:
    rows, classes = [], []
    for f in sorted_findings(findings):
        unit = "" if f.unit == "-" else f.unit
        margin = "&ndash;" if f.margin is None else f"{100 * f.margin:+.1f}&nbsp;%"
        bar = ""
        if f.margin is not None:
            w = min(100.0, abs(f.margin) * 100.0)
            bar = f'<span class="mbar {"neg" if f.margin < 0 else "pos"}" style="width:{w:.0f}%"></span>'
        detail = f'<div class="detail">{esc(f.detail)}</div>' if f.detail else ""
        rows.append([f"<code>{esc(f.rule_id)}</code>{detail}", num(f.value, ".4g", unit),
                     esc(f.limit_text()) + (f"&nbsp;{esc(unit)}" if unit and f.limit is not None else ""),
                     f'<div class="margin">{margin}{bar}</div>', badge(f.severity.name), esc(f.source)])
        classes.append("row-" + VERDICT_CLASS.get(f.severity.name, "na"))
    return ('<p class="lead">Every rule of <code>design_rules/</code> applied to this design, failing rules first, '
            'then by margin (the relative distance to the limit; negative = violated).</p>'
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
                          f"lead sphere at {trim['station_fraction']:.3f} L, z {1000 * trim['z_m']:.0f} mm"))
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


# ----------------------------------------------------------------------------------------------- page
CSS = """
:root{--ink:#1f2a37;--muted:#6b7685;--line:#e3e7ed;--bg:#f5f7fa;--card:#fff;--accent:#1f5f99;
--pass:#2a9d5c;--warn:#d68910;--fail:#c0392b;--info:#2874a6;--na:#8a94a3}
*{box-sizing:border-box}
html{scroll-behavior:smooth}
body{margin:0;font:15px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,"Helvetica Neue",Arial,sans-serif;
color:var(--ink);background:var(--bg)}
header.top{background:linear-gradient(120deg,#0e2a47,#1f5f99 60%,#2f86c4);color:#fff;padding:28px 40px 22px}
header.top h1{margin:0 0 4px;font-size:28px;font-weight:650;letter-spacing:.2px}
header.top .sub{opacity:.85;font-size:14px}
nav{position:sticky;top:0;z-index:5;background:#fff;border-bottom:1px solid var(--line);padding:0 32px;
display:flex;flex-wrap:wrap;gap:2px;box-shadow:0 1px 4px rgba(0,0,0,.04)}
nav a{color:var(--ink);text-decoration:none;padding:11px 12px;font-size:14px;border-bottom:2px solid transparent}
nav a:hover{color:var(--accent);border-bottom-color:var(--accent)}
main{max-width:1280px;margin:0 auto;padding:8px 32px 48px}
section{background:var(--card);border:1px solid var(--line);border-radius:10px;padding:20px 26px;margin:22px 0;
scroll-margin-top:56px}
section h2{margin:0 0 12px;font-size:21px;font-weight:650}
section h3{margin:20px 0 8px;font-size:16px}
.lead{color:#3b4754;margin:4px 0 14px}
.muted{color:var(--muted)}
code{font:12.5px/1.3 ui-monospace,"SFMono-Regular",Menlo,Consolas,monospace;background:#f0f3f7;padding:1px 4px;border-radius:3px}
.tiles{display:grid;grid-template-columns:repeat(auto-fill,minmax(190px,1fr));gap:12px;margin:8px 0 6px}
.tile{border:1px solid var(--line);border-left:4px solid var(--accent);border-radius:8px;padding:10px 14px;background:#fbfcfe}
.tile.good{border-left-color:var(--pass)}.tile.warn{border-left-color:var(--warn)}.tile.bad{border-left-color:var(--fail)}
.tile.muted{border-left-color:var(--na)}
.tlabel{font-size:12px;text-transform:uppercase;letter-spacing:.6px;color:var(--muted)}
.tvalue{font-size:22px;font-weight:650;margin:2px 0}
.tsub{font-size:12.5px;color:var(--muted)}
figure{margin:10px 0 18px}
figure img{display:block;max-width:100%;height:auto;margin:0 auto}
figure.wide img{width:100%;max-width:1200px}
figure.fitplot img{width:auto;max-width:100%;max-height:640px}
figcaption{font-size:13.5px;color:#3b4754;margin-top:6px;max-width:1100px}
.swatch{display:inline-block;width:11px;height:11px;border-radius:2px;margin:0 4px -1px 0;border:1px solid rgba(0,0,0,.2)}
.cards{display:grid;grid-template-columns:repeat(auto-fill,minmax(228px,1fr));gap:14px}
.card{border:1px solid var(--line);border-radius:8px;overflow:hidden;background:linear-gradient(#f7f9fc,#fff 60%)}
.card img{display:block;width:100%;height:auto;background:radial-gradient(circle at 50% 45%,#fff,#eef2f7)}
.cbody{padding:8px 12px 12px;font-size:13.5px;border-top:1px solid var(--line)}
.cname{font-weight:650;font-size:14.5px;word-break:break-word}
.cmeta{color:var(--muted);font-size:12.5px}
.mass{font-weight:650}
.cset{color:var(--muted);font-size:12px;margin-top:3px}
.tablewrap{overflow-x:auto}
table{border-collapse:collapse;width:100%;font-size:13.5px}
th,td{padding:6px 9px;border-bottom:1px solid var(--line);text-align:left;vertical-align:top}
th{background:#f3f6f9;font-weight:600;position:sticky;top:0}
td.num,th.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
tbody tr:hover{background:#f7fafd}
tr.row-fail{background:#fdecea}tr.row-warn{background:#fef5e7}tr.row-na{background:#f6f7f9}
tr.row-fail td:first-child{border-left:4px solid var(--fail)}tr.row-warn td:first-child{border-left:4px solid var(--warn)}
tr.row-pass td:first-child{border-left:4px solid var(--pass)}tr.row-info td:first-child{border-left:4px solid var(--info)}
tr.row-na td:first-child{border-left:4px solid var(--na)}
.badge{display:inline-block;padding:1px 8px;border-radius:10px;font-size:12px;font-weight:600;color:#fff;white-space:nowrap}
.badge.pass{background:var(--pass)}.badge.warn{background:var(--warn)}.badge.fail{background:var(--fail)}
.badge.info{background:var(--info)}.badge.na{background:var(--na)}
.tile .badge{font-size:16px;padding:2px 12px}
.detail{color:var(--muted);font-size:12px;margin-top:2px}
.margin{min-width:90px}
.mbar{display:block;height:4px;border-radius:2px;margin-top:3px;margin-left:auto}
.mbar.pos{background:var(--pass)}.mbar.neg{background:var(--fail)}
.notice{border-radius:8px;padding:10px 14px;margin:8px 0;font-size:14px}
.notice.missing{background:#f4f6f8;border:1px dashed #b7c0cc;color:#44505e}
.notice.info{background:#eaf2fb;border:1px solid #c6dbf1}
.notice.warn{background:#fef5e7;border:1px solid #f5d7a1}
table.audit td:nth-child(3){min-width:150px}table.audit td:nth-child(8){min-width:210px}
table.rules td:first-child{min-width:260px}table.rules td:last-child{min-width:260px}table.rules td:nth-child(3){white-space:nowrap}
footer{color:var(--muted);font-size:12.5px;text-align:center;padding:10px 0 30px}
"""


@functools.lru_cache(maxsize=4)
def standard_plots(params: Params) -> tuple:
    """The efficiency, tail-beat and body-wave plots of a design (pure functions of the frozen Params, so
    they are computed once per design in a process)."""
    from swiftfin.report import plots

    return plots.efficiency_plot(params), plots.joint_plot(params), plots.wave_plot(params)


@dataclass
class ReportTiming:
    render_s: float = 0.0
    plots_s: float = 0.0
    total_s: float = 0.0
    steps: dict = field(default_factory=dict)


def build_page(params: Params, parts=None, mass_properties: dict | None = None, fit_dir=None, *, findings,
               audit, progress: Callable[[str], None] | None = None, params_name: str = "swiftfin.toml",
               mass_note: str = "", timing: ReportTiming | None = None, memo=None, plots=None,
               jobs: int | None = 1) -> str:
    """The report page as a string (see :func:`write_report`)."""
    progress = progress or (lambda msg: None)
    timing = timing if timing is not None else ReportTiming()
    t_start = time.perf_counter()
    rparts = [as_report_part(x) for x in parts] if parts is not None else None
    pics = part_pics = None
    if rparts:
        pics, part_pics, timing.render_s = render_pictures(rparts, progress, memo, jobs)
    t0 = time.perf_counter()
    progress("plotting the efficiency curves (paper Fig. 8), one tail-beat and the body wave")
    if plots is None:
        try:
            hash(params)
            plot_fn = standard_plots
        except TypeError:   # a Params holding an unhashable value: compute without the cache
            plot_fn = standard_plots.__wrapped__
        plots = plot_fn(params)
    eff, beat, wave = plots
    timing.plots_s = time.perf_counter() - t0
    progress("writing the page")
    body = {
        "overview": overview_section(params, rparts, mass_properties, findings, audit, params_name),
        "assembly": assembly_section(pics, rparts or []),
        "parts": parts_section(params, rparts, part_pics, mass_properties),
        "rules": rules_section(findings),
        "mass": mass_section(params, mass_properties, mass_note),
        "efficiency": plot_section(eff, "transmission efficiency against frequency"),
        "tailbeat": plot_section(beat, "joint angles and step rates over one tail-beat"),
        "wave": plot_section(wave, "body wave envelope"),
        "audit": audit_section(audit),
        "fit": fit_section(Path(fit_dir) if fit_dir is not None else None),
    }
    titles = dict(SECTIONS)
    titles["efficiency"] = "Transmission efficiency (paper Fig. 8, recomputed)"
    titles["tailbeat"] = "One tail-beat at the design point"
    titles["wave"] = "Body wave along the body"
    nav = "".join(f'<a href="#{sid}">{esc(name)}</a>' for sid, name in SECTIONS)
    sections = "".join(f'<section id="{sid}"><h2>{esc(titles[sid])}</h2>{body[sid]}</section>' for sid, _ in SECTIONS)
    timing.total_s = time.perf_counter() - t_start
    # no wall-clock time on the page: the same design gives the same bytes (the build's manifest hashes it)
    stamp = "parameters " + hashlib.sha256(repr(params).encode()).hexdigest()[:12]
    sub = (f"Design <code style=\"background:rgba(255,255,255,.15);color:#fff\">{esc(params_name)}</code> &middot; "
           f"{params.body.length_mm:g} mm capstan-driven robotic tuna, {params.joints.count} tail joints &middot; "
           f"swiftfin {esc(__version__)} &middot; {stamp}")
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>SwiftFin design report &ndash; {esc(params_name)}</title><style>{CSS}</style></head><body>"
            f'<header class="top"><h1>SwiftFin design report</h1><div class="sub">{sub}</div></header>'
            f"<nav>{nav}</nav><main>{sections}</main>"
            f"<footer>Generated by <code>swiftfin</code>: pictures rendered off-screen, plots recomputed from "
            f"the models. Self-contained: no network, no script."
            f"</footer></body></html>\n")


def write_report(params: Params, out_dir, parts=None, mass_properties: dict | None = None, fit_dir=None, *,
                 findings, audit, progress: Callable[[str], None] | None = None,
                 params_name: str = "swiftfin.toml", mass_note: str = "",
                 timing: ReportTiming | None = None, memo=None, plots=None, jobs: int | None = 1) -> Path:
    """Write ``out_dir/report.html`` and return its path.

    ``parts``: ReportParts or ``swiftfin.pipeline.BuiltPart``s (None: no pictures, the page says so);
    ``mass_properties``: the content of ``mass_properties.json`` (None: the page says it was not computed);
    ``fit_dir``: a ``swiftfin fit`` output folder; ``findings`` / ``audit``: the design rules' findings and the
    paper audit's entries, computed by the caller (the report shows, it does not compute); ``plots``: the
    (efficiency, tail-beat, wave) plots of :func:`standard_plots` when the caller has them (its cache).
    The file is written to a temporary name and renamed, so a failed report never leaves half a page.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    page = build_page(params, parts, mass_properties, fit_dir, findings=findings, audit=audit, progress=progress,
                      params_name=params_name, mass_note=mass_note, timing=timing, memo=memo, plots=plots,
                      jobs=jobs)
    path = out / REPORT_NAME
    tmp = out / f".{REPORT_NAME}.tmp"
    tmp.write_text(page, encoding="utf-8")
    tmp.replace(path)
    return path
