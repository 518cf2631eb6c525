"""Parameter file → validated, frozen :class:`~swiftfin.core.schema.Params`.

Every problem in a file is collected and raised together as one :class:`ParamError` (house style rule 5):
unknown keys with a suggestion, wrong types, values out of range, and the cross-field impossibilities that
the schema alone can check. Geometric feasibility (parts that cannot fit in the hull) is checked by
``swiftfin.layout.geometry.layout_problems`` and joined to these by :func:`swiftfin.layout.design.load_design`.

The file is read once (:func:`read_file_bytes`: a regular file only, so a FIFO or a device never blocks) and
parsed from those bytes (:func:`parse_toml_bytes`: UTF-8, a leading BOM allowed, nesting bounded). A key that
fails the schema keeps its default so the later checks still run (:func:`schema_check`); what they find about,
or because of, a failed key is left out (:func:`independent_problems`, :func:`at_range_ends`).
"""
from __future__ import annotations

import dataclasses
import difflib
import math
import os
import re
import stat
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Iterable

from swiftfin.catalogues.cables import cable_params, cable_spec
from swiftfin.catalogues.motors import motor_params

from .schema import CUSTOM, SECTIONS, Body, Component, Params


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a parameter file."""
    key: str
    value: Any
    expected: str

    def __str__(self) -> str:
        try:
            v = ("(missing)" if self.value is _MISSING else str(self.value).lower() if isinstance(self.value, bool)
                 else repr(self.value))             # a bool as the parameter file spells it
        except ValueError:      # an integer past Python's digit limit for str()
            v = f"<an integer of about {self.value.bit_length() * 0.30103:.0f} digits>"
        if len(v) > 80:
            v = v[:60] + " ... " + v[-12:]      # a whole table or list says nothing more than its start
        return f"{self.key} = {v}: {self.expected}"


MAX_LISTED = 100   # problems printed in one message (all of them stay in ParamError.problems)


class ParamError(ValueError):
    """All the problems of one parameter file. ``str()`` is the message the CLI prints."""

    def __init__(self, source: str, problems: Iterable[Problem], what: str = "the parameter file"):
        self.source = source
        self.problems = list(problems)
        lines = [f"{source}: {len(self.problems)} problem(s) in {what}:"]
        lines += [f"  - {pr}" for pr in self.problems[:MAX_LISTED]]
        if len(self.problems) > MAX_LISTED:     # a generated or garbled file: the first ones show the pattern
            lines.append(f"  ... and {len(self.problems) - MAX_LISTED} more")
        super().__init__("\n".join(lines))


_MISSING = object()

GROOVE_WEB_MM = 0.2   # least material between neighbouring turns of the spool's groove (else the turns merge)


def suggest(name: str, options: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``options`` to a misspelt ``name``, or ``""``."""
    close = difflib.get_close_matches(name, list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def _meta(cls, name: str) -> dict:
    return dict(next(f.metadata for f in fields(cls) if f.name == name))


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
    if isinstance(value, float) and not math.isfinite(value):   # (an int is finite, however long)
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
                                           f"{suggest(value, choices)}"))
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


def _build_section(cls, raw: Any, prefix: str, out: list[Problem], failed: set[str] | None = None):
    """One section (or one component) from its table; a key that fails keeps its default and is added to
    ``failed`` (with the key an unknown key was probably meant to be), so later checks can ignore it."""
    failed = set() if failed is None else failed
    if not isinstance(raw, dict):
        out.append(Problem(prefix, raw, "expected a table of keys"))
        failed.add(prefix)
        return cls()
    names = {f.name: f for f in fields(cls)}
    values = {}
    for k, v in raw.items():
        if k not in names:
            out.append(Problem(f"{prefix}.{k}", v, f"unknown key{suggest(k, names)}"))
            close = difflib.get_close_matches(k, list(names), n=1, cutoff=0.6)
            if close and close[0] not in raw:
                failed.add(f"{prefix}.{close[0]}")     # its default stands in for what was probably meant
            continue
        f = names[k]
        default = f.default
        checked = _check_value(f"{prefix}.{k}", v, default, dict(f.metadata), out)
        if checked is not None:
            values[k] = checked
        else:
            failed.add(f"{prefix}.{k}")
    return cls(**values)


def _motor_entry(name: str) -> tuple[dict, tuple]:
    return motor_params(name), ()


def _cable_entry(name: str) -> tuple[dict, tuple]:
    return cable_params(name), cable_spec(name).missing()


CATALOGUE_SECTIONS = {"motor": _motor_entry, "cable": _cable_entry}
"""Sections whose ``model`` key names a catalogue entry: section -> name -> (the keys it fills, the keys the rules
read that it does not give)."""


def _agrees(given: Any, entry: Any) -> bool:
    if isinstance(entry, str) or isinstance(given, (str, bool)) or not isinstance(given, (int, float)):
        return given == entry
    return math.isclose(float(given), float(entry), rel_tol=1e-9, abs_tol=0.0)


def _with_catalogue_entry(section: str, raw: dict, out: list[Problem], failed: set[str]) -> dict:
    """The section's table with the keys its ``model`` fills (a name outside the catalogue is left for the schema's
    choice check to report). A key given beside the model that differs from the entry's number, and a key the
    rules read that the entry does not give and the file leaves out, are problems: never a silent choice
    between two numbers."""
    model = raw.get("model", CUSTOM)
    if not isinstance(model, str) or model == CUSTOM or model not in SECTIONS[section].__dataclass_fields__[
            "model"].metadata["choices"]:
        return raw
    entry, missing = CATALOGUE_SECTIONS[section](model)
    merged = dict(raw)
    for k, v in entry.items():
        if k not in raw:
            merged[k] = v
        elif not _agrees(raw[k], v):
            out.append(Problem(f"{section}.{k}", raw[k],
                               f"{section}.model = {model!r} gives {_fmt(v)}: leave the key out to take the "
                               f"entry's value, or set {section}.model = {CUSTOM!r} to give your own"))
            failed.add(f"{section}.{k}")
            del merged[k]
    for k in missing:
        if k not in raw:
            out.append(Problem(f"{section}.{k}", _MISSING,
                               f"{section}.model = {model!r} does not give it (the catalogue holds only the fibre "
                               f"maker's figures): give the cable's own number (data sheet or pull test)"))
            failed.add(f"{section}.{k}")
    return merged


COMPONENT_NAME_MAX = 40
_COMPONENT_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
COMPONENT_NAME_RULE = (f"a component name is letters, digits and underscores, starting with a letter, at most "
                       f"{COMPONENT_NAME_MAX} characters (it becomes a part label and a file name)")


def _build_components(raw: Any, out: list[Problem]) -> tuple:
    if not isinstance(raw, list):
        out.append(Problem("components", raw, "expected an array of tables [[components]]"))
        return Params().components
    comps = []
    seen: dict[str, int] = {}   # lower-cased name -> index of its first use (some file systems ignore case)
    for i, item in enumerate(raw):
        comp = _build_section(Component, item, f"components[{i}]", out)
        if isinstance(item, dict):
            for req in ("name", "mass_kg", "size_mm", "station_fraction", "source"):
                if req not in item:
                    out.append(Problem(f"components[{i}].{req}", _MISSING, "required for every component"))
            name = item.get("name")
            if isinstance(name, str):
                if len(name) > COMPONENT_NAME_MAX or not _COMPONENT_NAME.fullmatch(name):
                    out.append(Problem(f"components[{i}].name", name, f"not a valid name: {COMPONENT_NAME_RULE}"))
                elif name.lower() in seen:
                    first = seen[name.lower()]
                    out.append(Problem(f"components[{i}].name", name,
                                       f"duplicate name: components[{first}].name is {raw[first]['name']!r}; "
                                       f"component names must be unique (ignoring case)"))
                else:
                    seen[name.lower()] = i
        comps.append(comp)
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
                           f"{p.body.hull_end_fraction:g}, allowed {_range_text(_meta(Body, 'hull_end_fraction'))})"))
    if not p.hull.split_halves:
        out.append(Problem("hull.split_halves", False,
                           "expected true: a hull printed whole closes the head round its motors, spools, guides, "
                           "battery and boards, and no driver reaches their screws (the default design built whole, "
                           "2026-12-07: 26 of them enclosed, the build refused at its end); the head opens, and is "
                           "sealed, at the seam between its halves"))
    if p.hull.flooded_from_joint > j.count + 1:
        out.append(Problem("hull.flooded_from_joint", p.hull.flooded_from_joint,
                           f"must be a joint 1..{j.count}, or {j.count + 1} for a hull sealed throughout "
                           f"(joints.count = {j.count})"))
    elif p.hull.flooded_from_joint != 1 and j.count >= 1:
        out.append(Problem("hull.flooded_from_joint", p.hull.flooded_from_joint,
                           "only the head can be sealed (1): a sealed segment behind it would need its own glands "
                           "in both walls and a closed clevis room for the joint behind it, which the build does not "
                           "make (a seeded design sealed to joint 4 was refused by the build's dry-compartment check: "
                           "the clevis rooms of joints 1-3 open the walls between its sealed segments)"))
    n_flooded = max(0, j.count + 1 - p.hull.flooded_from_joint)
    if p.environment.flotation_foam_segments > n_flooded:
        out.append(Problem("environment.flotation_foam_segments", p.environment.flotation_foam_segments,
                           f"at most the {n_flooded} flooded segment(s) behind hull.flooded_from_joint = "
                           f"{p.hull.flooded_from_joint} (foam in a sealed segment lifts nothing: its envelope "
                           f"already displaces water)"))
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
                           "the hinge pin must be smaller than the tendon sector (2 x tendon_moment_arm_mm)"))
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


# A parameter file nests at most four levels (components -> [i] -> size_mm -> [k]); anything much deeper is
# refused before it is walked, so no check (nor repr) ever recurses into it.
MAX_NESTING = 16


def _too_deep(raw: Any) -> list[Problem]:
    """Keys whose value nests more than MAX_NESTING tables or lists (found without recursion)."""
    out: list[Problem] = []
    stack = [(raw, "", 0)]
    while stack:
        value, key, depth = stack.pop()
        if depth > MAX_NESTING:
            out.append(Problem(key or "(file)", "[...]" if isinstance(value, list) else "{...}",
                               f"nested more than {MAX_NESTING} tables or lists deep; a parameter file needs at most 4"))
            continue
        if isinstance(value, dict):
            stack += [(v, f"{key}.{k}" if key else str(k), depth + 1) for k, v in value.items()]
        elif isinstance(value, list):
            stack += [(v, f"{key}[{i}]", depth + 1) for i, v in enumerate(value)]
    # one line per top-level key is enough: the rest of the same value says nothing new
    firsts: dict[str, Problem] = {}
    for pr in out:
        firsts.setdefault(re.split(r"[.\[]", pr.key, maxsplit=1)[0], pr)
    return [Problem(pr.key if len(pr.key) <= 60 else pr.key[:40] + " ... " + pr.key[-12:], pr.value, pr.expected)
            for pr in firsts.values()]


def _top_level_problem(name: str, value: Any, allowed: list[str]) -> Problem:
    if isinstance(value, dict):
        return Problem(name, "{...}", f"unknown section{suggest(name, allowed)}")
    owners = [s for s, cls in SECTIONS.items() if any(f.name == name for f in fields(cls))]
    hint = (f" (did you mean '{name}' in [{owners[0]}]?)" if owners else
            suggest(name, allowed) or "")
    return Problem(name, value, f"unknown top-level key{hint}: every key belongs in a section: "
                                f"{', '.join(f'[{s}]' for s in SECTIONS)} or [[components]]")


@dataclass(frozen=True)
class SchemaResult:
    """What the schema made of a parsed file: ``params`` with the default in place of every key that failed
    (listed in ``failed``: dotted keys, or a section name when the whole section failed), and the problems."""
    params: Params
    problems: list[Problem]
    failed: frozenset[str]
    refused: bool = False   # the file as a whole (not a table, nested too deep): no later check can run


def schema_check(raw: Any) -> SchemaResult:
    """Check a parsed TOML mapping against the schema, collecting every problem (no cross-field checks)."""
    out: list[Problem] = []
    failed: set[str] = set()
    if not isinstance(raw, dict):
        return SchemaResult(Params(), [Problem("(file)", type(raw).__name__, "expected a table of sections")],
                            frozenset(), refused=True)
    deep = _too_deep(raw)
    if deep:
        return SchemaResult(Params(), deep, frozenset(), refused=True)
    kwargs = {}
    allowed = list(SECTIONS) + ["components"]
    for name, value in raw.items():
        if name == "components":
            n_before = len(out)
            kwargs[name] = _build_components(value, out)
            if len(out) > n_before:
                failed.add("components")
        elif name in SECTIONS:
            if name in CATALOGUE_SECTIONS and isinstance(value, dict):
                value = _with_catalogue_entry(name, value, out, failed)
            kwargs[name] = _build_section(SECTIONS[name], value, name, out, failed)
        else:
            out.append(_top_level_problem(name, value, allowed))
            close = difflib.get_close_matches(name, allowed, n=1, cutoff=0.6)
            if close and isinstance(value, dict) and close[0] not in raw:
                failed.add(close[0])
    return SchemaResult(Params(**kwargs), out, frozenset(failed))


def _mentions(text: str, key: str) -> bool:
    """Whether ``text`` names ``key`` (or, for a whole section, any key of it)."""
    pat = re.escape(key) + (r"(?![\w])" if "." in key else r"\.\w")
    return re.search(r"(?<![\w.])" + pat, text) is not None


def independent_problems(later: Iterable[Problem], failed: Iterable[str], earlier: Iterable[Problem] = ()) -> list[Problem]:
    """The problems of a later check that stand on their own: not about a key that failed an earlier level (or
    whose default stood in for it), not naming such a key, not repeating a key an earlier problem already names,
    and not quoting a non-finite number (a sign the check ran on a design it cannot measure)."""
    failed = list(failed)
    seen = {pr.key for pr in earlier}
    kept = []
    for pr in later:
        text = f"{pr.key} {pr.expected}"
        if pr.key in seen or any(_mentions(text, f) or pr.key == f for f in failed):
            continue
        if seen and re.search(r"\b(nan|inf)\b", str(pr)):
            continue
        kept.append(pr)
    return kept


def at_range_ends(params: Params, failed: frozenset[str]) -> list[Params]:
    """``params`` with every failed numeric key at the low end of its range, and at the high end."""
    variants = []
    for end in (0, 1):
        p = params
        for key in sorted(failed):
            section, _, name = key.partition(".")
            cls = SECTIONS.get(section)
            f = next((f for f in fields(cls) if f.name == name), None) if cls and name else None
            if f is None or isinstance(f.default, (bool, str, tuple)):
                continue
            m = f.metadata
            ends = (min(m["choices"]), max(m["choices"])) if m.get("choices") else (m.get("lo"), m.get("hi"))
            if ends[end] is None:
                continue
            p = replace_key(p, key, type(f.default)(ends[end]))
        if p is not params:
            variants.append(p)
    return variants


# Cross-field problems about these keys make the layout meaningless (it indexes the joints by them): the layout
# checks wait until they are fixed.
LAYOUT_PREREQUISITES = frozenset({"joints.stations_fraction", "joints.count"})


def params_from_dict(raw: dict, source: str = "<dict>") -> Params:
    """Validate a parsed TOML mapping. Raises :class:`ParamError` with every problem.

    The cross-field checks also run when some keys failed the schema, with those keys' defaults in their place;
    what they find about (or because of) a failed key is left out (:func:`independent_problems`)."""
    res = schema_check(raw)
    out = list(res.problems)
    if not res.refused:
        cross = cross_field_problems(res.params)
        if res.failed and cross:        # keep what does not hang on the defaults standing in for failed keys
            for variant in at_range_ends(res.params, res.failed):
                keys = {pr.key for pr in cross_field_problems(variant)}
                cross = [pr for pr in cross if pr.key in keys]
        out += independent_problems(cross, res.failed, out)
    if out:
        raise ParamError(source, out)
    return res.params


# A parameter file is a few kB; anything past this is not one (and is not read into memory to find out).
MAX_FILE_BYTES = 16 * 2**20

_FILE_KINDS = ((stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISCHR, "a character device"),
               (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def read_file_bytes(path: str | Path, what: str = "parameter file", kind: str | None = None) -> bytes:
    """The bytes of a regular file, read once; anything else (missing, a directory, a FIFO or device, too large,
    unreadable) is a ParamError naming the file and what it is. Never blocks on a FIFO or reads a device.

    ``what`` names the file in the messages, ``kind`` in their heading (default ``the {what}``)."""
    path = Path(path)
    name = str(path)
    where = kind or f"the {what}"

    def fail(expected: str) -> ParamError:
        return ParamError(name, [Problem("(file)", name, expected)], where)

    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise fail(f"{what} not found") from None
    except NotADirectoryError:
        raise fail(f"{what} not found (a folder in its path is a file)") from None
    except (OSError, ValueError) as exc:
        raise fail(f"cannot be read: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        raise fail(f"is a directory, not a {what}")
    if not stat.S_ISREG(st.st_mode):
        ftype = next((k for test, k in _FILE_KINDS if test(st.st_mode)), "a special file")
        raise fail(f"is not a regular file (it is {ftype}); give the path of a {what}")
    if st.st_size > MAX_FILE_BYTES:
        raise fail(f"is {st.st_size} bytes: too large for a {what} (at most {MAX_FILE_BYTES} bytes)")
    try:
        # O_NONBLOCK: should the path have become a FIFO since the stat, opening it must not wait for a writer
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise fail(f"is not a regular file; give the path of a {what}")
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise fail(f"cannot be read: {exc.strerror or exc}") from None
    if len(data) > MAX_FILE_BYTES:
        raise fail(f"too large for a {what} (more than {MAX_FILE_BYTES} bytes)")
    return data


def decode_text(data: bytes, source: str, what: str = "parameter file", kind: str | None = None) -> str:
    """UTF-8 text of a file's bytes, without the byte-order mark that Excel and Notepad write at the start."""
    kind = kind or f"the {what}"
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise ParamError(source, [Problem("(file)", source, "is UTF-16 text: save it as UTF-8")], kind)
    if b"\x00" in data:
        raise ParamError(source, [Problem("(file)", source, f"is a binary file, not a {what} (it holds NUL bytes)")],
                         kind)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise ParamError(source, [Problem("(file)", source,
                                          f"is not UTF-8 text: byte 0x{data[exc.start]:02x} at line {line} "
                                          f"(save the file as UTF-8)")], kind) from None
    return text.removeprefix("\ufeff")


def parse_toml_bytes(data: bytes, source: str, what: str = "parameter file", kind: str | None = None) -> dict:
    """Parse a TOML file's bytes (UTF-8, a leading BOM allowed); any failure is a ParamError naming it. ``what``
    names the file in the messages, ``kind`` in their heading (as :func:`read_file_bytes`)."""
    kind = kind or f"the {what}"
    text = decode_text(data, source, what, kind)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParamError(source, [Problem("(syntax)", str(exc), "the file is not valid TOML")], kind) from None
    except ValueError as exc:           # tomllib's int(): a number past Python's digit limit
        raise ParamError(source, [Problem("(syntax)", str(exc)[:60] + " ...",
                                          "the file is not valid TOML: a number too long to read")], kind) from None
    except RecursionError:
        raise ParamError(source, [Problem("(syntax)", "[[[...]]]",
                                          f"the file is nested too deeply to parse (a {what} nests at "
                                          f"most 4 tables or lists)")], kind) from None


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
    """Value of a dotted key such as ``spool.drum_diameter_mm`` (or ``components[0].z_mm``: an entry of a list)."""
    obj: Any = p
    for part in dotted.split("."):
        name, _, index = part.partition("[")
        obj = getattr(obj, name)
        if index:
            obj = obj[int(index.rstrip("]"))]
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
