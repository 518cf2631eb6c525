"""Load a design: schema validation plus the geometric feasibility of the layout, reported together.

Every level runs on whatever passed the one before it (house style rule 5: every problem at once): the schema
first, then the cross-field checks and the layout checks with the default standing in for each key that failed,
leaving out what a later level finds about (or because of) a key that failed earlier.
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from swiftfin.layout.geometry import layout_problems
from swiftfin.layout.joints import joint_link_problems
from swiftfin.core.params import (
    LAYOUT_PREREQUISITES, ParamError, Problem, at_range_ends, cross_field_problems, independent_problems,
    parse_toml_bytes, read_file_bytes, schema_check)
from swiftfin.core.schema import Params

DEFAULT_DESIGN = "swiftfin.toml"   # the name of a design in the working folder, and of the one shipped


def packaged_design_path() -> Path:
    """The default design shipped inside the package (the paper's SwiftFin; the repository's swiftfin.toml)."""
    from importlib.resources import files

    return Path(str(files("swiftfin") / DEFAULT_DESIGN))


def default_design_path() -> Path:
    """``swiftfin.toml`` in the working folder when there is one, otherwise the shipped default design."""
    here = Path(DEFAULT_DESIGN)
    return here if here.is_file() else packaged_design_path()


def _guarded(check: Callable[[Params], list[Problem]], params: Params, earlier: list[Problem]) -> list[Problem] | None:
    """``check(params)``; None when it raised on a design it cannot measure and earlier problems explain why,
    one problem naming the failed check when nothing else does (never a traceback)."""
    try:
        return check(params)
    except Exception as exc:  # noqa: BLE001 - a check that cannot measure a design must not end in a traceback
        if earlier:
            return None
        return [Problem(f"({check.__name__})", f"{type(exc).__name__}: {exc}",
                        "this design cannot be laid out (the check could not measure it); change the joint "
                        "stations or the part sizes")]


# The fastener and foam plans that need no CAD kernel, with the key a user changes when one cannot be made.
_PLANS: tuple[tuple[str, str, str], ...] = (
    ("swiftfin.layout.flotation_plan:foam_blocks", "environment.flotation_foam_segments", "the flotation blocks"),
    ("swiftfin.layout.hull_plan:hull_fasteners", "hull.screw_diameter_mm", "the hull's seam and splice fasteners"),
    ("swiftfin.layout.link_plan:link_fasteners", "joints.pin_diameter_mm", "the joints' pins, plugs and flange screws"),
    ("swiftfin.layout.fin_plan:fin_fasteners", "caudal_fin.mount_length_mm", "the fin root's screws"),
    ("swiftfin.layout.mount_plan:wall_fixings", "hull.screw_diameter_mm", "the motor mounts' wall fixings"),
    ("swiftfin.layout.guide_screws:guide_fasteners", "spool.drum_diameter_mm", "the PTFE guides and their screws"),
    ("swiftfin.layout.gland_plan:gland_plan", "hull.cable_gland_length_mm", "the cable glands through the dry wall"),
    ("swiftfin.layout.mount_plate_plan:mount_fasteners", "motor.frame_size_mm", "the motor mounts' plates"),
    ("swiftfin.layout.spool_plan:spool_plan", "spool.drum_diameter_mm", "the spools"),
    ("swiftfin.layout.cradle_plan:cradles", "components", "the components' cradles"),
    ("swiftfin.layout.cradle_plan:components_clear_of_motors", "components", "the components beside the motors"),
    ("swiftfin.layout.tube_plan:tubes_inside_hull", "spool.drum_diameter_mm", "the PTFE tubes"),
)


_PIECE_FREE_PLANS = ("swiftfin.layout.spool_plan:spool_plan",)
"""Plans that read none of the hull's pieces: made even where the hull cannot be cut to fit the bed (a seeded design
with spool grooves too thin for a line was accepted because its unsplit hull fitted no bed, 2026-11-30)."""


def plan_problems(params: Params) -> list[Problem]:
    """The fastener and flotation plans a build makes, made now: a design whose screws, pins or foam blocks cannot
    be placed (no catalogue length long enough, no room between bulkheads) is refused by the loader, naming the
    key to change, instead of failing half-way through a build."""
    import importlib

    from swiftfin.core.errors import BuildError, UserError
    from swiftfin.layout.hull_plan import hull_pieces
    out: list[Problem] = []
    seen: set[str] = set()
    plans = _PLANS
    try:
        hull_pieces(params)     # its cuts keep clear of the mounts' wall fixings, so it places them first
    except UserError:           # a hull that cannot be cut to fit the bed: the rule print.bed_fit reports it, and
        # the plans that place fasteners in its pieces have nothing to place them in; the spools' does not need them
        plans = tuple(plan for plan in _PLANS if plan[0] in _PIECE_FREE_PLANS)
    except BuildError as exc:
        _plan_problem(params, exc, "hull.screw_diameter_mm", "the hull's pieces", seen, out)
        return out
    for ref, key, what in plans:
        module, func = ref.split(":")
        try:
            getattr(importlib.import_module(module), func)(params)
        except (UserError, BuildError) as exc:
            _plan_problem(params, exc, key, what, seen, out)
    return out


def _plan_problem(params: Params, exc: Exception, key: str, what: str, seen: set[str], out: list[Problem]) -> None:
    """One plan's refusal as a problem: under the key its text begins with (``key = value: why``) when that is a
    real key, else under ``key``; a text already reported (one plan reads another) is not repeated."""
    from swiftfin.core.params import get_key
    text = str(exc)
    if text in seen:
        return
    seen.add(text)
    head, _, rest = text.partition(": ")
    own = head.split(" = ")[0] if " = " in head and rest else None
    try:
        own_value = get_key(params, own) if own else None
    except (AttributeError, KeyError, ValueError):
        own = None
    if own is not None:
        out.append(Problem(own, own_value, rest))
    else:
        out.append(Problem(key, get_key(params, key), f"{what} cannot be made for this design: {text}"))


def _component_problems(params: Params) -> list[Problem]:
    from swiftfin.core.errors import BuildError, UserError
    from swiftfin.layout.hull_plan import component_problems
    try:
        return component_problems(params)
    except (UserError, BuildError):     # a hull that cannot be cut into pieces: print.bed_fit and the plans say so
        return []


def _layout_level(params: Params, earlier: list[Problem]) -> list[Problem] | None:
    found = _guarded(layout_problems, params, earlier)
    if found == []:  # the links' own room (tendon wrap, stops, flange bolts) assumes a feasible layout
        found = _guarded(joint_link_problems, params, earlier)
    if found == []:  # the components sit in the head's hollow the layout leaves
        found = _guarded(_component_problems, params, earlier)
    if found == []:  # the fasteners and foam are placed in the room the layout leaves
        found = _guarded(plan_problems, params, earlier)
    return found


def _later_levels(params: Params, earlier: list[Problem]) -> tuple[list[Problem], list[Problem]] | None:
    """(cross-field, layout) problems of ``params``, None when a check raised (and ``earlier`` explains why)."""
    cross = _guarded(cross_field_problems, params, earlier)
    if cross is None:
        return None
    if any(pr.key in LAYOUT_PREREQUISITES for pr in cross):
        return cross, []                # the layout indexes the joints by these: it waits until they are fixed
    layout = _layout_level(params, earlier + cross)
    return None if layout is None else (cross, layout)


def design_problems(raw: Any) -> tuple[Params, list[Problem]]:
    """Every problem of a parsed parameter file: schema, cross-field and layout, in that order.

    Returns the params and the problems; with problems, the params hold the default in place of every key that
    failed the schema (the design the later levels checked). What a later level finds is reported when it
    stands on its own: not about, nor naming, a key that failed earlier
    (:func:`swiftfin.core.params.independent_problems`), and found again with every failed number at either end
    of its range (so it does not hang on the default that stood in for the value given).
    """
    res = schema_check(raw)
    out = list(res.problems)
    if res.refused:
        return res.params, out
    found = _later_levels(res.params, out)
    if found is None:
        return res.params, out
    cross, layout = found
    if res.failed and (cross or layout):
        for variant in at_range_ends(res.params, res.failed):
            other = _later_levels(variant, out)
            if other is None:           # a check cannot measure the design at this end of the range: no evidence
                continue
            keys = {pr.key for pr in other[0] + other[1]}
            cross = [pr for pr in cross if pr.key in keys]
            layout = [pr for pr in layout if pr.key in keys]
    out += independent_problems(cross, res.failed, out)
    out += independent_problems(layout, res.failed, out)
    return res.params, out


def check_design(params: Params, source: str) -> Params:
    """Raise ParamError listing every geometric impossibility of a schema-valid design."""
    problems = _layout_level(params, []) or []
    if problems:
        raise ParamError(source, problems)
    return params


def load_design_source(path: str | Path | None = None) -> tuple[Params, bytes]:
    """Read a parameter file once; validate and check the params parsed from exactly those bytes.

    Returns the params and the bytes (for the caller to hash what was parsed). Raises :class:`ParamError` with
    every problem of the file (schema, cross-field and layout together).
    """
    path = default_design_path() if path is None else path
    data = read_file_bytes(path)
    params, problems = design_problems(parse_toml_bytes(data, str(path)))
    if problems:
        raise ParamError(str(path), problems)
    return params, data


def load_design(path: str | Path | None = None) -> Params:
    """Parse, validate and check a parameter file. Raises :class:`ParamError` with every problem."""
    return load_design_source(path)[0]
