"""What the printability rules read of a built part (issue 13, item 5): its support area in the orientation the
build chose, its walls under their limit and its bridges over theirs, as the wall probe and the bridge rule
(``exports/printability.py``) measured them on its mesh.

One form for both ways in: a build hands its parts' records to the report, and writes them into its
``manifest.json`` (each printed part's ``"print"`` entry), from which ``swiftfin check --build DIR`` reads them back
(:func:`records_from_manifest`, strict: a bad entry is named with its part and key).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from swiftfin.core.params import ParamError, Problem

Point = tuple[float, float, float]


@dataclass(frozen=True)
class Wall:
    """A region thinner than its limit (two perimeters; two layers where the thickness lies along the print's
    vertical; one line width for a load-free web): its thinnest point, body frame at rest [mm]."""
    thickness_mm: float
    limit_mm: float
    area_mm2: float
    at_mm: Point
    kind: str = "wall"          # "wall", or "web" (a load-free web between two bores)

    def __str__(self) -> str:
        return self.text()

    def text(self) -> str:
        x, y, z = self.at_mm
        what = "web between bores" if self.kind == "web" else "wall"
        return (f"{self.thickness_mm:.2f} mm {what} (limit {self.limit_mm:.2f}) over {self.area_mm2:.1f} mm^2 at "
                f"({x:.1f}, {y:.1f}, {z:.1f}) mm")


@dataclass(frozen=True)
class Span:
    """A ceiling in print orientation spanning more than its limit; ``span_mm`` None: no edge of it has material
    below (only support can start it)."""
    span_mm: float | None
    limit_mm: float
    area_mm2: float
    at_mm: Point

    @property
    def hanging(self) -> bool:
        return self.span_mm is None


@dataclass(frozen=True)
class Bore:
    """A fastener's hole whose ceiling needs support in the part's print orientation: its axis leans more than the
    support angle off the vertical and it is wider than the longest bridge."""
    fastener: str
    what: str                   # "clearance hole", "counterbore", "insert hole", "pilot", "nut trap", "pin bore"
    diameter_mm: float
    tilt_deg: float             # of its axis from the print's vertical


@dataclass(frozen=True)
class PrintRecord:
    label: str
    rotation_deg: tuple[float, float, float]
    support_area_mm2: float
    walls: tuple[Wall, ...] = ()
    bridges: tuple[Span, ...] = ()
    bores_checked: int = 0              # the fasteners' round holes in the part
    supported_bores: tuple[Bore, ...] = ()

    def to_dict(self) -> dict:
        return {"rotation_deg": [round(a, 6) for a in self.rotation_deg],
                "support_area_mm2": round(self.support_area_mm2, 3),
                "thin_walls": [{"thickness_mm": round(w.thickness_mm, 4), "limit_mm": round(w.limit_mm, 4),
                                "area_mm2": round(w.area_mm2, 3), "at_mm": [round(v, 3) for v in w.at_mm],
                                "kind": w.kind} for w in self.walls],
                "bridges": [{"span_mm": None if b.span_mm is None else round(b.span_mm, 3),
                             "limit_mm": round(b.limit_mm, 4), "area_mm2": round(b.area_mm2, 3),
                             "at_mm": [round(v, 3) for v in b.at_mm]} for b in self.bridges],
                "bores_checked": self.bores_checked,
                "supported_bores": [{"fastener": b.fastener, "what": b.what, "diameter_mm": round(b.diameter_mm, 4),
                                     "tilt_deg": round(b.tilt_deg, 3)} for b in self.supported_bores]}


WHAT = "the build's manifest"


def _num(v, positive: bool = False) -> bool:
    return (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            and (v > 0 if positive else v >= 0))


def _point(v) -> bool:
    return isinstance(v, list) and len(v) == 3 and all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                                       and math.isfinite(c) for c in v)


def _record(label: str, d, probs: list[Problem]) -> PrintRecord | None:
    key = f"parts[{label}].print"
    if not isinstance(d, dict):
        probs.append(Problem(key, d, "expected an object {rotation_deg, support_area_mm2, thin_walls, bridges}"))
        return None
    n = len(probs)
    rot, area = d.get("rotation_deg"), d.get("support_area_mm2")
    if not _point(rot):
        probs.append(Problem(f"{key}.rotation_deg", rot, "expected three angles [rx, ry, rz] in degrees"))
    if not _num(area):
        probs.append(Problem(f"{key}.support_area_mm2", area, "expected an area >= 0 in mm^2"))
    walls, spans = [], []
    for name, kind in (("thin_walls", "wall"), ("bridges", "bridge")):
        rows = d.get(name, [])
        if not isinstance(rows, list):
            probs.append(Problem(f"{key}.{name}", rows, "expected a list"))
            continue
        for i, r in enumerate(rows):
            k = f"{key}.{name}[{i}]"
            if not isinstance(r, dict):
                probs.append(Problem(k, r, "expected an object"))
                continue
            first = "thickness_mm" if kind == "wall" else "span_mm"
            v = r.get(first)
            ok = _num(v, positive=True) or (kind == "bridge" and v is None)
            if not ok:
                probs.append(Problem(f"{k}.{first}", v, "expected a length > 0 in mm" +
                                     (" (or null: no anchored edge)" if kind == "bridge" else "")))
            for f in ("limit_mm", "area_mm2"):
                if not _num(r.get(f), positive=True):
                    probs.append(Problem(f"{k}.{f}", r.get(f), "expected a number > 0"))
            if not _point(r.get("at_mm")):
                probs.append(Problem(f"{k}.at_mm", r.get("at_mm"), "expected a point [x, y, z] in mm"))
            if kind == "wall" and r.get("kind", "wall") not in ("wall", "web"):
                probs.append(Problem(f"{k}.kind", r.get("kind"), "expected \"wall\" or \"web\""))
            if len(probs) > n:
                continue
            at = tuple(float(c) for c in r["at_mm"])
            if kind == "wall":
                walls.append(Wall(float(v), float(r["limit_mm"]), float(r["area_mm2"]), at, r.get("kind", "wall")))
            else:
                spans.append(Span(None if v is None else float(v), float(r["limit_mm"]), float(r["area_mm2"]), at))
    checked, rows = d.get("bores_checked", 0), d.get("supported_bores", [])
    if not (isinstance(checked, int) and not isinstance(checked, bool) and checked >= 0):
        probs.append(Problem(f"{key}.bores_checked", checked, "expected a count >= 0"))
    bores = []
    if not isinstance(rows, list):
        probs.append(Problem(f"{key}.supported_bores", rows, "expected a list"))
        rows = []
    for i, r in enumerate(rows):
        k = f"{key}.supported_bores[{i}]"
        if not (isinstance(r, dict) and isinstance(r.get("fastener"), str) and isinstance(r.get("what"), str)
                and _num(r.get("diameter_mm"), positive=True) and _num(r.get("tilt_deg"))):
            probs.append(Problem(k, r, "expected {fastener, what, diameter_mm > 0, tilt_deg >= 0}"))
            continue
        bores.append(Bore(r["fastener"], r["what"], float(r["diameter_mm"]), float(r["tilt_deg"])))
    if len(probs) > n:
        return None
    return PrintRecord(label, tuple(float(a) for a in rot), float(area), tuple(walls), tuple(spans), checked,
                       tuple(bores))


def records_from_manifest(data, source: str) -> tuple[dict[str, tuple[float, float, float]], dict[str, PrintRecord]]:
    """The printed parts' print boxes [mm] and print records from a build's ``manifest.json`` content. A manifest
    written before the records were (no ``"print"`` entries) gives boxes and no records. Raises ParamError naming
    ``source`` and each bad entry."""
    probs: list[Problem] = []
    parts = data.get("parts") if isinstance(data, dict) else None
    if not isinstance(parts, list):
        raise ParamError(source, [Problem("parts", type(parts).__name__ if parts is not None else parts,
                                          "expected the list of parts a build's manifest.json has")], WHAT)
    boxes, records = {}, {}
    for i, e in enumerate(parts):
        if not isinstance(e, dict) or not isinstance(e.get("label"), str):
            probs.append(Problem(f"parts[{i}]", e, "expected an object with a \"label\""))
            continue
        if not e.get("printed"):
            continue
        label, size = e["label"], e.get("print_size_mm")
        if isinstance(size, list) and len(size) == 3 and all(_num(c, positive=True) for c in size):
            boxes[label] = tuple(float(c) for c in size)
        else:
            probs.append(Problem(f"parts[{label}].print_size_mm", size, "expected three sizes > 0 in mm"))
        if "print" in e:
            rec = _record(label, e["print"], probs)
            if rec is not None:
                records[label] = rec
    if probs:
        raise ParamError(source, probs, WHAT)
    return boxes, records
