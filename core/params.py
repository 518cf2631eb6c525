"""Parameter file → validated, frozen :class:`~swiftfin.core.schema.Params`.

Every problem in a file is collected and raised together as one :class:`ParamError` (house style rule 5):
unknown keys with a suggestion, wrong types, values out of range, and the cross-field impossibilities that
the schema alone can check. Geometric feasibility (parts that cannot fit in the hull) is checked by
``swiftfin.layout.geometry.layout_problems`` and joined to these by :func:`swiftfin.layout.design.load_design`.
"""
from __future__ import annotations

import dataclasses
import difflib
import hashlib
import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Iterable

from .schema import SECTIONS, Component, Params


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a parameter file."""
    key: str
    value: Any
    expected: str

    def __str__(self) -> str:
        v = "(missing)" if self.value is _MISSING else repr(self.value)
        if len(v) > 80:
            v = v[:60] + " ... " + v[-12:]      # a whole table or list says nothing more than its start
        return f"{self.key} = {v}: {self.expected}"


class ParamError(ValueError):
    """All the problems of one parameter file. ``str()`` is the message the CLI prints."""

    def __init__(self, source: str, problems: Iterable[Problem], what: str = "the parameter file"):
        self.source = source
        self.problems = list(problems)
        lines = [f"{source}: {len(self.problems)} problem(s) in {what}:"]
        lines += [f"  - {pr}" for pr in self.problems]
        super().__init__("\n".join(lines))


_MISSING = object()

GROOVE_WEB_MM = 0.2   # least material between neighbouring turns of the spool's groove (else the turns merge)


def _suggest(name: str, options: Iterable[str]) -> str:
    close = difflib.get_close_matches(name, list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def _range_text(meta: dict) -> str:
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is not None and hi is not None:
        return f"[{lo:g}, {hi:g}]"
    if lo is not None:
        return f">= {lo:g}"
    if hi is not None:
        return f"<= {hi:g}"
    return "any"


def _check_number(key: str, value: Any, default: Any, meta: dict, out: list[Problem]) -> Any:
    want_int = isinstance(default, int) and not isinstance(default, bool)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        out.append(Problem(key, value, f"expected {'an integer' if want_int else 'a number'} in {_range_text(meta)}"))
        return None
    if want_int and not isinstance(value, int):
        if float(value).is_integer():
            value = int(value)
        else:
            out.append(Problem(key, value, f"expected an integer in {_range_text(meta)}"))
            return None
    if not math.isfinite(value):
        out.append(Problem(key, value, f"expected a finite number in {_range_text(meta)}"))
        return None
    lo, hi = meta.get("lo"), meta.get("hi")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        out.append(Problem(key, value, f"out of range: allowed {_range_text(meta)}"))
        return None
    choices = meta.get("choices")
    if choices and value not in choices:
        out.append(Problem(key, value, f"expected one of {', '.join(str(c) for c in choices)}"))
        return None
    return float(value) if not want_int else int(value)


def _check_value(key: str, value: Any, default: Any, meta: dict, out: list[Problem]) -> Any:
    if isinstance(default, bool):
        if not isinstance(value, bool):
            out.append(Problem(key, value, "expected true or false"))
            return None
        return value
    if isinstance(default, str):
        if not isinstance(value, str):
            out.append(Problem(key, value, "expected a string"))
            return None
        choices = meta.get("choices")
        if choices and value not in choices:
            out.append(Problem(key, value, f"expected one of {', '.join(repr(c) for c in choices)}"
                                           f"{_suggest(value, choices)}"))
            return None
        return value
    if isinstance(default, tuple):
        if not isinstance(value, list) or not value:
            out.append(Problem(key, value, f"expected a list of numbers, each in {_range_text(meta)}"))
            return None
        n_lo, n_hi = meta.get("length") or (1, 10**6)
        if not n_lo <= len(value) <= n_hi:
            out.append(Problem(key, value, f"expected {n_lo}..{n_hi} values, got {len(value)}"))
            return None
        items = []
        elem_meta = dict(meta, choices=None)
        for i, v in enumerate(value):
            n_before = len(out)
            items.append(_check_number(f"{key}[{i}]", v, 0.0, elem_meta, out))
            if len(out) > n_before:
                return None
        return tuple(items)
    return _check_number(key, value, default, meta, out)


def _build_section(cls, raw: Any, prefix: str, out: list[Problem]):
    if not isinstance(raw, dict):
        out.append(Problem(prefix, raw, "expected a table of keys"))
        return cls()
    names = {f.name: f for f in fields(cls)}
    values = {}
    for k, v in raw.items():
        if k not in names:
            out.append(Problem(f"{prefix}.{k}", v, f"unknown key{_suggest(k, names)}"))
            continue
        f = names[k]
        default = f.default
        checked = _check_value(f"{prefix}.{k}", v, default, dict(f.metadata), out)
        if checked is not None:
            values[k] = checked
    return cls(**values)


def _build_components(raw: Any, out: list[Problem]) -> tuple:
    if not isinstance(raw, list):
        out.append(Problem("components", raw, "expected an array of tables [[components]]"))
        return Params().components
    comps = []
    for i, item in enumerate(raw):
        comp = _build_section(Component, item, f"components[{i}]", out)
        if isinstance(item, dict):
            for req in ("name", "mass_kg", "size_mm", "station_fraction", "source"):
                if req not in item:
                    out.append(Problem(f"components[{i}].{req}", _MISSING, "required for every component"))
        comps.append(comp)
    names = [c.name for c in comps]
    for n in sorted({n for n in names if names.count(n) > 1}):
        out.append(Problem("components", n, "component names must be unique"))
    return tuple(comps)


def cross_field_problems(p: Params) -> list[Problem]:
    """Impossibilities between fields that the schema can see without geometry."""
    out: list[Problem] = []
    j = p.joints
    if len(j.stations_fraction) != j.count:
        out.append(Problem("joints.stations_fraction", list(j.stations_fraction),
                           f"expected {j.count} stations (joints.count = {j.count})"))
    st = j.stations_fraction
    if any(b <= a for a, b in zip(st, st[1:])):
        out.append(Problem("joints.stations_fraction", list(st), "stations must be strictly increasing"))
    if st and st[-1] >= p.body.hull_end_fraction:
        out.append(Problem("joints.stations_fraction", list(st),
                           f"the last joint must lie ahead of the hull end (body.hull_end_fraction = "
                           f"{p.body.hull_end_fraction:g})"))
    if p.hull.flooded_from_joint > j.count + 1:
        out.append(Problem("hull.flooded_from_joint", p.hull.flooded_from_joint,
                           f"must be a joint 1..{j.count}, or {j.count + 1} for a hull sealed throughout "
                           f"(joints.count = {j.count})"))
    m = p.motor
    if len(m.pullout_curve_steps_per_s) != len(m.pullout_curve_torque_nm):
        out.append(Problem("motor.pullout_curve_torque_nm", list(m.pullout_curve_torque_nm),
                           f"expected as many values as motor.pullout_curve_steps_per_s "
                           f"({len(m.pullout_curve_steps_per_s)})"))
    rates = m.pullout_curve_steps_per_s
    if any(b <= a for a, b in zip(rates, rates[1:])):
        out.append(Problem("motor.pullout_curve_steps_per_s", list(rates), "rates must be strictly increasing"))
    if m.shaft_flat_depth_mm >= m.shaft_diameter_mm / 2:
        out.append(Problem("motor.shaft_flat_depth_mm", m.shaft_flat_depth_mm,
                           f"must be less than the shaft radius ({m.shaft_diameter_mm / 2:g} mm)"))
    if m.hole_spacing_mm >= m.frame_size_mm - m.mount_screw_diameter_mm:
        out.append(Problem("motor.hole_spacing_mm", m.hole_spacing_mm,
                           f"holes must lie inside the frame: < {m.frame_size_mm - m.mount_screw_diameter_mm:g} mm"))
    if m.pilot_diameter_mm >= m.hole_spacing_mm:
        out.append(Problem("motor.pilot_diameter_mm", m.pilot_diameter_mm,
                           f"must be smaller than motor.hole_spacing_mm ({m.hole_spacing_mm:g})"))

    s, c, g, pr = p.spool, p.cable, p.guides, p.print
    groove_width = c.diameter_mm + pr.clearance_sliding_mm       # the groove cad/spool.py cuts
    min_pitch = max(c.diameter_mm + pr.line_width_mm, groove_width + GROOVE_WEB_MM)
    if s.groove_pitch_mm < min_pitch:
        out.append(Problem("spool.groove_pitch_mm", s.groove_pitch_mm,
                           f"the cable ({c.diameter_mm:g} mm) is thicker than its groove: the groove is "
                           f"{groove_width:g} mm wide (cable + print.clearance_sliding_mm) and the pitch must leave a "
                           f"web between turns: pitch >= {min_pitch:g} mm"))
    if s.groove_depth_mm > c.diameter_mm:
        out.append(Problem("spool.groove_depth_mm", s.groove_depth_mm,
                           f"must not exceed the cable diameter ({c.diameter_mm:g} mm)"))
    core_r = s.drum_diameter_mm / 2 - s.groove_depth_mm
    bore_r = m.shaft_diameter_mm / 2 + pr.clearance_sliding_mm / 2
    min_wall = 2 * pr.line_width_mm
    if core_r - bore_r < min_wall:
        out.append(Problem("spool.drum_diameter_mm", s.drum_diameter_mm,
                           f"spool too small for the motor shaft: needs >= "
                           f"{2 * (bore_r + min_wall + s.groove_depth_mm):.2f} mm for a {m.shaft_diameter_mm:g} mm "
                           f"shaft with two line widths of wall under the groove"))
    if g.ptfe_tube_id_mm <= c.diameter_mm:
        out.append(Problem("guides.ptfe_tube_id_mm", g.ptfe_tube_id_mm,
                           f"cable hole smaller than the cable: must exceed cable.diameter_mm ({c.diameter_mm:g})"))
    if g.ptfe_tube_od_mm <= g.ptfe_tube_id_mm:
        out.append(Problem("guides.ptfe_tube_od_mm", g.ptfe_tube_od_mm,
                           f"must exceed guides.ptfe_tube_id_mm ({g.ptfe_tube_id_mm:g})"))
    if c.pretension_n >= c.breaking_strength_n:
        out.append(Problem("cable.pretension_n", c.pretension_n,
                           f"must be below cable.breaking_strength_n ({c.breaking_strength_n:g})"))
    if j.pin_diameter_mm >= 2 * j.tendon_moment_arm_mm - 2 * c.diameter_mm:
        out.append(Problem("joints.pin_diameter_mm", j.pin_diameter_mm,
                           f"the hinge pin must be smaller than the tendon sector (2 x tendon_moment_arm_mm)"))
    if pr.line_width_mm < pr.nozzle_diameter_mm * 0.8 or pr.line_width_mm > pr.nozzle_diameter_mm * 2.5:
        out.append(Problem("print.line_width_mm", pr.line_width_mm,
                           f"expected 0.8-2.5 x print.nozzle_diameter_mm ({pr.nozzle_diameter_mm:g})"))
    if pr.layer_height_mm > 0.8 * pr.nozzle_diameter_mm:
        out.append(Problem("print.layer_height_mm", pr.layer_height_mm,
                           f"must be <= 0.8 x print.nozzle_diameter_mm = {0.8 * pr.nozzle_diameter_mm:g}"))
    fin = p.caudal_fin
    if fin.min_thickness_mm < 2 * pr.line_width_mm * 0.99:
        out.append(Problem("caudal_fin.min_thickness_mm", fin.min_thickness_mm,
                           f"thinner than two extrusion lines ({2 * pr.line_width_mm:g} mm) cannot print"))
    r = p.rules
    for lo_key, hi_key in (("strouhal_min", "strouhal_max"), ("pretension_min_fraction", "pretension_max_fraction")):
        lo, hi = getattr(r, lo_key), getattr(r, hi_key)
        if lo >= hi:
            out.append(Problem(f"rules.{lo_key}", lo, f"must be below rules.{hi_key} ({hi:g})"))
    return out


def params_from_dict(raw: dict, source: str = "<dict>") -> Params:
    """Validate a parsed TOML mapping. Raises :class:`ParamError` with every problem."""
    out: list[Problem] = []
    kwargs = {}
    allowed = list(SECTIONS) + ["components"]
    for name, value in raw.items():
        if name == "components":
            kwargs[name] = _build_components(value, out)
        elif name in SECTIONS:
            kwargs[name] = _build_section(SECTIONS[name], value, name, out)
        else:
            out.append(Problem(name, value if not isinstance(value, dict) else "{...}",
                               f"unknown section{_suggest(name, allowed)}"))
    params = Params(**kwargs)
    if not out:
        out += cross_field_problems(params)
    if out:
        raise ParamError(source, out)
    return params


def read_toml(path: str | Path) -> dict:
    """Read a TOML file, turning a missing file or a syntax error into a ParamError."""
    path = Path(path)
    if not path.is_file():
        raise ParamError(str(path), [Problem("(file)", str(path), "parameter file not found")])
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ParamError(str(path), [Problem("(syntax)", str(exc), "the file is not valid TOML")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ParamError(str(path), [Problem("(file)", str(path), f"cannot be read: {exc}")]) from None


def load_params(path: str | Path) -> Params:
    """Schema-level validation of a parameter file (no geometry). See ``swiftfin.layout.design.load_design``."""
    return params_from_dict(read_toml(path), str(path))


def file_sha256(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def to_dict(p: Params) -> dict:
    """Plain nested dict (TOML-ready) of a Params."""
    def conv(v):
        if dataclasses.is_dataclass(v):
            return {f.name: conv(getattr(v, f.name)) for f in fields(v)}
        if isinstance(v, tuple):
            return [conv(x) for x in v]
        return v
    return conv(p)


def get_key(p: Params, dotted: str) -> Any:
    """Value of a dotted key such as ``spool.drum_diameter_mm``."""
    obj: Any = p
    for part in dotted.split("."):
        obj = getattr(obj, part)
    return obj


def replace_key(p: Params, dotted: str, value: Any) -> Params:
    """A copy of ``p`` with one dotted key changed (no validation; use params_from_dict(to_dict(...)))."""
    section, name = dotted.split(".", 1)
    sec = getattr(p, section)
    return dataclasses.replace(p, **{section: dataclasses.replace(sec, **{name: value})})


def _fmt(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        r = repr(v)
        return r if ("e" in r or "." in r or "inf" in r) else r + ".0"
    if isinstance(v, (tuple, list)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)


def dump_toml(p: Params | None = None) -> str:
    """The documented parameter file for ``p`` (default: the schema defaults = the paper's SwiftFin)."""
    p = p or Params()
    lines = ["# SwiftFin design parameters: the paper's SwiftFin (../shared/paper/swiftfin_paper.txt).",
             "# Generated by `swiftfin params --dump`; every key names its unit, range and source.",
             "# CAD lengths in mm; physics in SI. Stations are fractions of body.length_mm from the nose.", ""]
    for name, cls in SECTIONS.items():
        sec = getattr(p, name)
        lines.append(f"[{name}]")
        for f in fields(cls):
            m = f.metadata
            rng = _range_text(m) if not isinstance(f.default, (str, bool)) else ""
            if m.get("choices"):
                rng = "one of " + ", ".join(str(c) for c in m["choices"])
            doc = m.get("doc", "")
            src = m.get("source", "")
            lines.append(f"# {doc}. Range {rng}. Source: {src}" if rng else f"# {doc}. Source: {src}")
            lines.append(f"{f.name} = {_fmt(getattr(sec, f.name))}")
        lines.append("")
    lines.append("# Bought parts (motors come from [motor], one per joint; PTFE tube and cable from their sections).")
    for comp in p.components:
        lines.append("[[components]]")
        for f in fields(Component):
            lines.append(f"{f.name} = {_fmt(getattr(comp, f.name))}")
        lines.append("")
    return "\n".join(lines)
