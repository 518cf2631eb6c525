"""The build: parameters -> every part family -> exports -> assembly checks -> files, written atomically.

``build(params_file, out_dir)`` is what ``swiftfin build`` runs:

1. load and check the design (a bad file raises ParamError before anything is written);
2. run each family of cad/registry.py (through the rebuild cache, swiftfin/cache.py), check its parts (one
   valid solid each, unique snake_case labels, printed parts fit the bed), tessellate each part and write
   its STL, 3MF and STEP in print orientation (exports/files.py);
3. check the assembly (cad/assembly.py: clearances over the range of motion, contacts, inside the hull);
4. write ``parts/<label>.{step,stl,3mf}``, ``assembly.step`` (every part at rest, product names = labels)
   and ``manifest.json`` into a temporary folder beside ``out_dir`` and move it into place at the end, so an
   interrupted or failed build never leaves a half-written ``out_dir``; ``out_dir`` is replaced only when it
   holds a previous build and nothing else (swiftfin/outdir.py).
"""
from __future__ import annotations

import dataclasses
import functools
import json
import os
import re
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from swiftfin.cad.part import PartSpec
from swiftfin.cad.registry import FAMILIES, family_function
from swiftfin.exports.manifest import MANIFEST_NAME, make_manifest, manifest_text, sha256_bytes
from swiftfin import outdir
from swiftfin.cache import FamilyCache, brep_roundtrip, record_reads, shape_from_brep
from swiftfin.core.calibration import FILE_NAME as CALIBRATION_NAME
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.schema import Params
from swiftfin.progress import bar, say

LABEL_RE = re.compile(r"^[a-z][a-z0-9_]*$")
FILE_KINDS = (".step", ".stl", ".3mf")


@dataclass
class BuiltPart:
    spec: PartSpec
    export: object              # exports.files.PartExport
    time_s: float
    cached: bool
    content_sha256: str = ""    # of the part's BREP and spec: what the later stages' cache keys read


@dataclass
class BuildResult:
    params: Params
    parts: list[BuiltPart]
    family_times_s: dict[str, float] = field(default_factory=dict)
    #: the bare CAD work in it: each family's modelling, fastener cuts, tessellation and file writes (its time
    #: without the print checks of its export), and the assembly STEP's composition and write ("assembly.step")
    cad_times_s: dict[str, float] = field(default_factory=dict)
    check_time_s: float = 0.0
    assembly_stats: dict = field(default_factory=dict)
    fastener_report: object = None     # cad.fastener_check.FastenerReport
    dry_report: object = None          # cad.dry_check.DryReport
    assembly_plan: object = None       # cad.assembly_steps.Plan
    cable_stats: dict = field(default_factory=dict)   # the cables' and tubes' proof (empty: not a whole build)
    calibration: object = None         # core.calibration.Calibration the build applied (None: none given)
    calibration_changes: list = field(default_factory=list)   # what it changed, a line each (Calibration.changes)


def _one_solid(spec: PartSpec):
    """The part's solid as one build123d Solid (a one-solid compound is unwrapped); BuildError otherwise."""
    import build123d as bd

    shape = spec.solid
    solids = shape.solids() if hasattr(shape, "solids") else []
    if len(solids) != 1:
        raise BuildError(f"{spec.label} ({spec.family}): expected one solid, got {len(solids)}")
    solid = solids[0] if not isinstance(shape, bd.Solid) else shape
    if not solid.is_valid:
        raise BuildError(f"{spec.label} ({spec.family}): the solid is not valid (OpenCascade BRepCheck)")
    if solid.volume <= 0:
        raise BuildError(f"{spec.label} ({spec.family}): the solid has no volume")
    solid.label = spec.label
    return solid


def _check_spec(spec, family: str) -> PartSpec:
    if not isinstance(spec, PartSpec):
        raise BuildError(f"part family '{family}' returned {type(spec).__name__}, not a PartSpec")
    if not LABEL_RE.match(spec.label):
        raise BuildError(f"part family '{family}': label {spec.label!r} is not snake_case")
    return dataclasses.replace(spec, solid=_one_solid(spec))


def _check_bed(spec: PartSpec, size, p: Params) -> None:
    if not spec.printed:
        return
    x, y, z = size
    pr = p.print
    fits_xy = (x <= pr.bed_x_mm and y <= pr.bed_y_mm) or (y <= pr.bed_x_mm and x <= pr.bed_y_mm)
    if not fits_xy or z > pr.bed_z_mm:
        raise BuildError(f"{spec.label}: {x:.1f} x {y:.1f} x {z:.1f} mm in its print orientation does not fit "
                         f"the printer ({pr.bed_x_mm:g} x {pr.bed_y_mm:g} x {pr.bed_z_mm:g} mm, print.bed_*_mm)")


def family_modules(name: str) -> tuple[str, ...]:
    """Source modules a family's cached output depends on (their imports are followed by the cache): the family,
    the registry that cuts every fastener's holes in its parts, and every plan that places fasteners."""
    from swiftfin.cad.fastening import FASTENER_PLANS
    plans = tuple(sorted({ref.split(":")[0] for ref in FASTENER_PLANS.values()}))
    return (FAMILIES[name].split(":")[0], "swiftfin.cad.registry", "swiftfin.cad.fastening", *plans,
            "swiftfin.exports.files", "swiftfin.cad.part", "swiftfin.cache")


def _content_key(spec: PartSpec, brep: bytes) -> str:
    """SHA-256 of a part's BREP text and its spec (label, link, family, printed, print rotation, catalogue
    mass): the identity of a part for the later stages' cache (StageCache)."""
    fields = {f.name: getattr(spec, f.name) for f in dataclasses.fields(PartSpec) if f.name not in ("solid", "meta")}
    return sha256_bytes(brep + b"\0" + json.dumps(fields, sort_keys=True, default=list).encode())


#: the code each later stage's cached results depend on (StageCache): their modules and what they import
STAGE_MODULES: dict[str, tuple[str, ...]] = {
    "solid_props": ("swiftfin.exports.brep",),
    "mesh_props": ("swiftfin.exports.brep",),
    "part_mass": ("swiftfin.exports.print_model",),
    "part_core": ("swiftfin.exports.print_model",),
    "outside_piece": ("swiftfin.exports.water",),
    "link_mesh": ("swiftfin.exports.robot",),
    "picture": ("swiftfin.report.render",),
    "view_mesh": ("swiftfin.report.render",),
    "assembly_steps": ("swiftfin.cad.assembly_steps", "swiftfin.cad.fastening"),
    "assembly_step_file": ("swiftfin.cad.assembly", "swiftfin.exports.files"),
    "robot_picture": ("swiftfin.report.render", "swiftfin.report.robot"),
}


def build_jobs() -> int:
    """Processes for the per-part work of a build: ``$SWIFTFIN_JOBS``, or one per core."""
    raw = os.environ.get("SWIFTFIN_JOBS", "")
    if raw.strip():
        try:
            n = int(raw)
        except ValueError:
            raise UserError(f"SWIFTFIN_JOBS = {raw!r}: expected a whole number of processes >= 1") from None
        if n < 1:
            raise UserError(f"SWIFTFIN_JOBS = {raw!r}: expected a whole number of processes >= 1")
        return n
    return os.cpu_count() or 1


def stage_memo(result: "BuildResult", cache: FamilyCache | None):
    """The memo the export and report layers use for per-part work: the B-rep volume properties the export
    already integrated, and (with a cache) every stage's stored results (StageCache)."""
    from swiftfin.cache import StageCache

    stored = None
    if cache is not None:
        stored = StageCache(cache.root, STAGE_MODULES).memo({b.spec.label: b.content_sha256 for b in result.parts})
    known = {b.spec.label: b.export.volume_props for b in result.parts
             if getattr(b.export, "volume_props", None) is not None}

    def memo(stage: str, labels: tuple[str, ...], extra, compute):
        if stage == "solid_props" and len(labels) == 1 and labels[0] in known:
            return known[labels[0]]        # same solid, same integration: the export's
        return compute() if stored is None else stored(stage, labels, extra, compute)
    return memo


def run_family(name: str, p: Params, cache: FamilyCache | None) -> tuple[list[BuiltPart], float]:
    """Build (or fetch from the cache) one family's parts with their exports. Returns (parts, seconds)."""
    from swiftfin.exports.files import export_part

    skey = None
    if cache is not None:
        skey = cache.source_key(name, family_modules(name))    # the cache's bookkeeping: not the family's time
    t0 = time.perf_counter()
    if cache is not None:
        hit = cache.lookup(name, skey, p)
        if hit is not None:
            _, (folder, payload) = hit
            out = []
            for item in payload:
                brep = folder / f"{item['label']}.brep"
                spec = PartSpec(solid=shape_from_brep(brep, item["label"]), **item["spec"])
                out.append(BuiltPart(spec, item["export"], 0.0, True, _content_key(spec, brep.read_bytes())))
            dt = time.perf_counter() - t0
            for b in out:
                b.time_s = dt / max(len(out), 1)
            return out, dt
    func = family_function(name)
    view, reads = record_reads(p)
    try:
        specs = func(view)
    except (BuildError, UserError):
        raise
    except Exception as exc:  # a part family that cannot make its solid for this design
        raise BuildError(f"part family '{name}' failed: {type(exc).__name__}: {exc}") from exc
    t_family = time.perf_counter() - t0
    specs = [_check_spec(s, name) for s in specs]
    breps: dict[str, bytes] = {}
    for i, spec in enumerate(specs):  # every output is made from the solid as the cache would return it
        solid, breps[spec.label] = brep_roundtrip(spec.solid, spec.label)
        specs[i] = dataclasses.replace(spec, solid=solid)
    out = []
    for spec in specs:
        t1 = time.perf_counter()
        exp = export_part(spec, view)
        if exp.print_rotation is not None and tuple(exp.print_rotation) != tuple(spec.print_rotation):
            spec = dataclasses.replace(spec, print_rotation=tuple(exp.print_rotation))   # the orientation chosen
        _check_bed(spec, exp.print_size_mm, p)
        out.append(BuiltPart(spec, exp, t_family / max(len(specs), 1) + time.perf_counter() - t1, False,
                             _content_key(spec, breps[spec.label])))
    if cache is not None:
        payload = [{"label": b.spec.label,
                    "spec": {f.name: getattr(b.spec, f.name) for f in dataclasses.fields(PartSpec)
                             if f.name != "solid"},
                    "export": b.export} for b in out]
        cache.store(name, skey, reads, payload, breps)
    return out, time.perf_counter() - t0


def build_parts(p: Params, cache: FamilyCache | None = None,
                progress: Callable[[str], None] | None = None, families: tuple[str, ...] | None = None,
                prefetch=None) -> BuildResult:
    """Every family's parts, checked and exported (not yet written). ``prefetch`` (swiftfin.prefetch.Prefetch):
    handed each family's new parts as it finishes, for the per-part work that needs no other part."""
    result = BuildResult(p, [])
    seen: dict[str, str] = {}
    names = families or tuple(FAMILIES)
    with bar(len(names), "parts", "family", show=progress is not None) as fam_bar:
        for name in names:
            n0 = len(result.parts)
            _build_family(name, p, cache, result, seen, progress)
            if prefetch is not None:
                prefetch.parts(result.parts[n0:], p)
            fam_bar.update()
    return result


def _build_family(name: str, p: Params, cache, result: BuildResult, seen: dict, progress) -> None:
    """One family's parts into ``result`` (``seen``: the labels so far, each with its family)."""
    parts, dt = run_family(name, p, cache)
    result.family_times_s[name] = dt
    result.cad_times_s[name] = dt - sum(b.export.checks_s for b in parts if not b.cached)
    for b in parts:
        if b.spec.label in seen:
            raise BuildError(f"two parts are labelled {b.spec.label!r} (families '{seen[b.spec.label]}' "
                             f"and '{name}')")
        seen[b.spec.label] = name
        result.parts.append(b)
        if progress:
            progress(f"  {len(result.parts):>3}  {b.spec.label:<28} {name:<7} link {b.spec.link}  "
                     f"{b.time_s:6.2f} s{'  (cached)' if b.cached else ''}")


def _built_part(spec: PartSpec, p: Params) -> BuiltPart:
    """One part made outside the families (the trim ballast), checked and exported as a family's parts are."""
    from swiftfin.exports.files import export_part

    t0 = time.perf_counter()
    spec = _check_spec(spec, spec.family)
    solid, brep = brep_roundtrip(spec.solid, spec.label)
    spec = dataclasses.replace(spec, solid=solid)
    exp = export_part(spec, p)
    if exp.print_rotation is not None and tuple(exp.print_rotation) != tuple(spec.print_rotation):
        spec = dataclasses.replace(spec, print_rotation=tuple(exp.print_rotation))
    _check_bed(spec, exp.print_size_mm, p)
    return BuiltPart(spec, exp, time.perf_counter() - t0, False, _content_key(spec, brep))


def place_ballast(result: BuildResult, cache: FamilyCache | None = None, progress=None) -> None:
    """The trim ballast's parts (:func:`swiftfin.ballast.ballast_specs`) appended to ``result.parts``, so that the
    assembly, the clearance and dry-wall checks, the assembly steps, the bill of materials and the mass model all
    see them. Only on a whole build with ``environment.trim_ballast``."""
    from swiftfin.ballast import ballast_specs
    from swiftfin.exports.robot import as_trimesh

    p = result.params
    if not p.environment.trim_ballast or not set(FAMILIES) <= set(result.family_times_s) \
            or "hull" not in result.family_times_s:       # no hull to pour it into (a test's partial build)
        return
    specs = ballast_specs(p, [b.spec for b in result.parts],
                          {b.spec.label: as_trimesh(b.export.mesh) for b in result.parts}, stage_memo(result, cache),
                          build_jobs(), progress)
    result.parts += [_built_part(s, p) for s in specs]


CHECK_FIELDS = ("assembly_stats", "cable_stats", "fastener_report", "dry_report", "assembly_plan", "check_time_s")
"""What :func:`check_built` fills in on the BuildResult."""


def start_checks(result: BuildResult, cache: FamilyCache | None = None, progress=None):
    """:func:`check_built` on a forked process (exports.parallel.Forked) while the build writes the parts, the
    assembly STEP and the robot: the checks read meshes only, never the CAD kernel, and take as long as those
    (a cold build of the default design: about 30 s each). Returns ``join()``, which waits for them, fills in
    ``result`` (:data:`CHECK_FIELDS`) and raises their BuildError. With one job (``$SWIFTFIN_JOBS`` = 1) they
    run at ``join()``, in this process."""
    from swiftfin.cad.cables import tube_runs
    from swiftfin.cad.fastening import all_fasteners
    from swiftfin.exports.parallel import Forked

    # the plans both sides read (memoised on the params: the tubes' seats alone take 0.85 s), made once, here,
    # before the fork, so that the checks and the mass model (the fasteners' and tubes' masses) share them
    all_fasteners(result.params)
    if set(FAMILIES) <= set(result.family_times_s):    # only a whole build proves its tubes (check_cables_built)
        tube_runs(result.params)

    def checks():
        check_built(result, cache, progress)
        return {k: getattr(result, k) for k in CHECK_FIELDS}

    job = Forked(checks, run_here=build_jobs() <= 1)
    joined = []

    def join() -> None:
        if joined:             # once: a second call (after a failure in the writing) has nothing more to say
            return
        joined.append(True)
        for k, v in job.result().items():
            setattr(result, k, v)
    join.cancel = job.cancel
    return join


def check_built(result: BuildResult, cache: FamilyCache | None = None, progress=None) -> None:
    from swiftfin.cad.assembly import PassedPairs, check_assembly

    t0 = time.perf_counter()
    placed = placed_parts(result)
    passed = PassedPairs(cache.root / "assembly-pairs") if cache is not None else None
    result.assembly_stats = check_assembly(result.params, placed, progress=progress, passed=passed)
    result.cable_stats = check_cables_built(result, placed, passed, progress, cache)
    result.fastener_report = check_fasteners_built(result, placed, cache)
    result.dry_report = check_dry_wall_built(result, placed, cache)
    result.assembly_plan = plan_assembly(result, placed, cache, progress)
    result.check_time_s = time.perf_counter() - t0


def _on_solids(cache: FamilyCache | None, name: str, modules: tuple[str, ...], params, parts, fn, records=()):
    """``fn(params)``, a check on the solids of ``parts`` (cad.assembly.Placed), stored (with a cache) under the
    parameter keys it reads, the parts' meshes (their digests) and ``records`` (the fastener or tube records it
    is handed, made from the parameters outside it: by their repr): a rebuild that changed none of them proves
    nothing again. A failure raises and is never stored."""
    if cache is None:
        return fn(params)
    inputs = sha256_bytes(json.dumps([sorted((q.label, q.digest) for q in parts), repr(records)]).encode())
    return cache.memoize(name, modules, params, fn, inputs=inputs)


def check_cables_built(result: BuildResult, placed=None, passed=None, progress=None,
                       cache: FamilyCache | None = None) -> dict:
    """The cables and PTFE tubes in the assembly (cad/cables.py): each swept along its route, moving with its links,
    against every built part over the joints' range (the parts among themselves are the rigid check's), with the
    wiring harness's leads (layout/harness_plan.py, on the head) among them, and every
    tube seated on its printed shoulder with its mouth open and held both ways (``check_tube_seats``). Only a
    whole build: the cables run through the parts of every family. BuildError names the cable or tube, the part,
    the gap and the joint angles, or the tube and its end."""
    from swiftfin.cad.assembly import check_assembly
    from swiftfin.cad.cables import cable_parts, check_tube_seats, harness_parts, tube_runs

    if not set(FAMILIES) <= set(result.family_times_s):
        return {}
    if progress:
        progress("  checking the cables, PTFE tubes and leads against every part over the joints' range ...")
    p = result.params
    placed = placed_parts(result) if placed is None else placed
    tubes = tube_runs(p)
    leads = harness_parts(p)
    meshes = cable_parts(p, None, tubes) + leads
    stats = check_assembly(p, placed + meshes, progress=progress, passed=passed, focus={q.label for q in meshes})
    built = [q.label for q in placed]
    held = [t for t in tubes if any(lb == t.holder or lb.startswith(t.holder + "_") for lb in built)]
    # a tube's stop and mouth are measured in the parts of its own link (cad.cables._ring_fill): those alone are
    # handed over and key the stored result, so a change on another link (the fin's) proves nothing again
    links = {t.link for t in held}
    holders = [q for q in placed if q.link in links]
    seats = _on_solids(cache, "check-tube-seats", ("swiftfin.cad.cables",), p, holders,
                       lambda view: check_tube_seats(view, holders, held), records=held) if held else {}
    return {"cable_pieces": len(meshes) - len(tubes) - len(leads), "tubes": len(tubes), "leads": len(leads), **stats,
            **{k: v for k, v in seats.items() if k.startswith("worst")}}


def placed_parts(result: BuildResult) -> list:
    """The built parts as the assembly checks take them (cad.assembly.Placed: label, link, family, mesh)."""
    from swiftfin.cad.assembly import Placed

    return [Placed(b.spec.label, b.spec.link, b.spec.family, b.export.mesh.vertices, b.export.mesh.faces)
            for b in result.parts]


def built_fasteners(result: BuildResult, placed) -> tuple[list, dict[str, str]]:
    """The fasteners whose parts were all built (all of them in a whole build: tests/test_fasteners.py proves every
    record names parts of the design; a build of some families has only theirs), and glued part -> its host."""
    from swiftfin.cad.fastening import all_fasteners

    built = {q.label for q in placed}
    fasteners = [f for f in all_fasteners(result.params) if f.parts <= built]
    glued = {b.spec.label: b.spec.meta["glued_to"] for b in result.parts if b.spec.meta.get("glued_to")}
    return fasteners, glued


def plan_assembly(result: BuildResult, placed=None, cache: FamilyCache | None = None, progress=None):
    """The assembly steps of the built parts (cad/assembly_steps.py): each part's way in proved clear of what is
    already placed, the fasteners and the cabling in order. BuildError when no order puts the parts together."""
    from swiftfin.cad.assembly_steps import PathMemo, plan_steps
    from swiftfin.core.params import to_dict

    placed = placed_parts(result) if placed is None else placed
    if progress:
        progress("  planning the assembly steps (each part's way in, proved clear of what is already placed) ...")
    fasteners, glued = built_fasteners(result, placed)
    memo = stage_memo(result, cache)
    paths = PathMemo(cache.root / "assembly-paths") if cache is not None else None
    return memo("assembly_steps", tuple(sorted(q.label for q in placed)),
                [to_dict(result.params), sorted(f.label for f in fasteners)],
                lambda: plan_steps(result.params, placed, fasteners, glued, memo=paths))


def check_dry_wall_built(result: BuildResult, placed=None, cache: FamilyCache | None = None):
    """The dry compartment closed on the built solids (cad/dry_check.py): every opening through its wall a declared
    sealed crossing, every cable gland longer than its cable's stroke. BuildError names the part, the opening's
    place and size, or the gland. None when the sealed hull parts were not all built (or none is sealed)."""
    from swiftfin.cad.dry_check import check_dry_wall, dry_wall_problems, sealed_part_labels

    placed = placed_parts(result) if placed is None else placed
    mans = {q.label: q.manifold for q in placed}
    labels = sealed_part_labels(result.params)
    if not labels or not set(labels) <= set(mans):
        return None
    sealed = [q for q in placed if q.label in labels]
    report = _on_solids(cache, "check-dry-wall", ("swiftfin.cad.dry_check",), result.params, sealed,
                        lambda view: check_dry_wall(view, {lb: mans[lb] for lb in sealed_part_labels(view)}))
    problems = dry_wall_problems(result.params, report)
    if problems:
        raise BuildError("the dry compartment is not closed:\n" + "\n".join(f"  - {pr}" for pr in problems))
    return report


def check_fasteners_built(result: BuildResult, placed=None, cache: FamilyCache | None = None):
    """The fastener rules on the built solids (cad/fastener_check.py); BuildError lists every failure."""
    from swiftfin.cad.fastener_check import check_fasteners

    placed = placed_parts(result) if placed is None else placed
    fasteners, glued = built_fasteners(result, placed)
    # the trim ballast is poured into its half on the bench, before that half goes on: a driver reaching a screw that
    # is driven before the half does not meet it (a seeded design's 2.2 kg fill in the head's upper half stood over
    # the motors' screws, 2026-11-29)
    glued = {**glued, **{b.spec.label: b.spec.meta["bonded_to"] for b in result.parts
                         if b.spec.family == "ballast" and b.spec.meta.get("bonded_to")}}
    return _on_solids(cache, "check-fasteners", ("swiftfin.cad.fastener_check",), result.params, placed,
                      lambda view: check_fasteners(view, fasteners, {q.label: q.manifold for q in placed},
                                                   goes_in_with=glued, placed=placed),
                      records=(fasteners, sorted(glued.items())))


# --------------------------------------------------------------------------------------------- writing
def assembly_step(result: BuildResult) -> bytes:
    from swiftfin.cad.assembly import make_assembly
    from swiftfin.exports.files import step_bytes

    return step_bytes(make_assembly([b.spec for b in result.parts]), "swiftfin_assembly")


def write_outputs(result: BuildResult, folder: Path, params_file: Path,
                  progress: Callable[[str], None] | None = None, params_sha256: str | None = None,
                  cache: FamilyCache | None = None, ros2_package: bool = False, swim: bool = False,
                  checks: Callable[[], None] | None = None) -> dict:
    """Write every file of the build into ``folder`` (which exists and is empty): the parts, the assembly, the
    robot for the simulators with ``mass_properties.json`` (exports.robot; with ``ros2_package`` also its ROS 2
    description package) and ``report.html``. Returns the manifest, which lists them all. ``checks``: the
    running checks' ``join`` (:func:`start_checks`), waited for before the first file that needs their findings
    (the bill of materials, the assembly steps, the report); a failure in them is raised before one of the
    writing's own."""
    (folder / "parts").mkdir()
    files = []
    parts = []
    for b in result.parts:
        entry = {"label": b.spec.label, "family": b.spec.family, "link": b.spec.link, "printed": b.spec.printed,
                 "volume_mm3": round(b.export.volume_mm3, 3),
                 "print_size_mm": [round(v, 3) for v in b.export.print_size_mm], "files": []}
        rec = print_record(b, result.params)
        if rec is not None:           # what `swiftfin check --build` and `swiftfin report` read back
            d = rec.to_dict()
            entry["print_rotation"], entry["print"] = d["rotation_deg"], d
        for kind in FILE_KINDS:
            data = b.export.files.get(kind)
            if data is None:
                continue
            rel = f"parts/{b.spec.label}{kind}"
            (folder / rel).write_bytes(data)
            files.append({"path": rel, "sha256": sha256_bytes(data), "bytes": len(data)})
            entry["files"].append(rel)
        if b.spec.family == "seal":          # a die-cut part: its outline is what the builder orders
            from swiftfin.exports.gasket import gasket_outline_svg_of
            rel = f"parts/{b.spec.label}.svg"
            data = gasket_outline_svg_of(b.spec, b.export.mesh).encode("utf-8")
            (folder / rel).write_bytes(data)
            files.append({"path": rel, "sha256": sha256_bytes(data), "bytes": len(data)})
            entry["files"].append(rel)
        parts.append(entry)
    labels = tuple(b.spec.label for b in result.parts)
    try:
        t0 = time.perf_counter()
        data = stage_memo(result, cache)("assembly_step_file", labels, [list(labels)],
                                         lambda: assembly_step(result))
        result.cad_times_s["assembly.step"] = time.perf_counter() - t0
        (folder / "assembly.step").write_bytes(data)
        files.append({"path": "assembly.step", "sha256": sha256_bytes(data), "bytes": len(data)})
        files += write_robot_and_report(result, folder, params_file, progress, cache, ros2_package=ros2_package,
                                        swim=swim, checks=checks)
    except Exception:
        if checks is not None:
            checks()     # a check's failure first, as a build that checks before it writes would say
        raise
    manifest = make_manifest(files, parts, params_file, params_sha256)
    (folder / MANIFEST_NAME).write_text(manifest_text(manifest))
    return manifest


def write_robot_and_report(result: BuildResult, folder: Path, params_file: Path,
                           progress: Callable[[str], None] | None = None,
                           cache: FamilyCache | None = None, ros2_package: bool = False,
                           swim: bool = False, checks: Callable[[], None] | None = None) -> list[dict]:
    """Mass properties with their validation gate, the simulator files (exports.robot) and report.html, into
    ``folder``; returns their manifest entries. BuildError names the part or link that fails the gate.
    ``checks``: see :func:`write_outputs`."""
    from swiftfin.exports.robot import write_robot
    if progress:
        progress("  mass properties, validation gate and simulator files ...")
    memo = stage_memo(result, cache)
    robot = write_robot(result.params, [b.spec for b in result.parts], folder,
                        meshes={b.spec.label: b.export.mesh for b in result.parts}, memo=memo, jobs=build_jobs(),
                        ros2_package=ros2_package, calibration=result.calibration)
    if checks is not None:
        checks()
    bom_file = write_bom(result, folder)
    steps_file = write_assembly_steps(result, folder)
    if progress:
        progress("  design report ...")
    plots = None
    if cache is not None:
        from swiftfin.prefetch import report_plots

        # drawn by the build's prefetch worker, or here by the report beside its pictures
        plots = functools.partial(report_plots, cache, result.params)
    swimming = None
    if swim:
        if progress:
            progress("  swimming the exported fish in MuJoCo at 1, 2 and 3 Hz (quasi-steady and reactive) ...")
        swimming = swim_results(folder / "robot" / "swiftfin.xml", result.params, build_jobs())
    report_for_build(result, folder, params_file.name, progress=progress, memo=memo, plots=plots, swim=swimming)
    entries = []
    cal_file = write_calibration(result, folder)
    for rel in (sorted(robot["files"]) + [bom_file] + ([steps_file] if steps_file else []) + ([cal_file] if cal_file
                                                                                               else []) + ["report.html"]):
        data = (folder / rel).read_bytes()
        entries.append({"path": rel, "sha256": sha256_bytes(data), "bytes": len(data)})
    return entries




def write_calibration(result: BuildResult, folder: Path) -> str | None:
    """The calibration the build applied, as it was read, into ``folder`` (so that a build says what it was
    calibrated with); its name, or None without one."""
    cal = result.calibration
    if cal is None:
        return None
    (folder / CALIBRATION_NAME).write_bytes(cal.data)
    return CALIBRATION_NAME


def write_assembly_steps(result: BuildResult, folder: Path) -> str | None:
    """``assembly_steps.json`` (cad/assembly_steps.py) into ``folder`` when the build planned them; its name."""
    from swiftfin.cad.assembly_steps import steps_json
    from swiftfin.report.sections import STEPS_NAME

    if result.assembly_plan is None:
        return None
    (folder / STEPS_NAME).write_text(steps_json(result.assembly_plan), encoding="utf-8")
    return STEPS_NAME


def write_bom(result: BuildResult, folder: Path) -> str:
    """``bom.csv`` (exports/bom.py) into ``folder``, with the trim ballast from the build's mass properties;
    returns its name."""
    from swiftfin.cad.fastening import all_fasteners
    from swiftfin.exports.bom import bom_csv, bom_lines
    from swiftfin.report.sections import BOM_NAME, MASS_PROPERTIES_NAME

    mp = None
    mpath = folder / MASS_PROPERTIES_NAME
    if mpath.is_file():
        mp = json.loads(mpath.read_text())
    lines = bom_lines(result.params, [b.spec for b in result.parts], all_fasteners(result.params), mp)
    (folder / BOM_NAME).write_text(bom_csv(lines), encoding="utf-8")
    return BOM_NAME


def build(params_file: str | Path, out_dir: str | Path, cache: FamilyCache | None = None,
          progress: Callable[[str], None] | None = None, ros2_package: bool = False,
          swim: bool = False, calibration: str | Path | None = None) -> BuildResult:
    """Build the design in ``params_file`` into ``out_dir`` (see the module docstring and swiftfin/outdir.py).

    The parameter file is read once: the parts are made from, and the manifest hashes, the bytes parsed.
    ``out_dir`` is checked before any work and replaced only if it holds a previous build and nothing else.
    ``ros2_package``: also write ``robot/swiftfin_description/``, a ROS 2 description package (exports.robot).
    ``swim``: also swim the exported fish in MuJoCo (:func:`swim_results`) and show it in the report.
    ``calibration``: a calibration file (core.calibration; ``swiftfin fit joint`` writes one), read and checked
    before any work: its revised design keys replace the file's, its joints' damping, friction and cable
    stiffness go into the simulator files, and the report's rules use them; a copy goes into the build.
    """
    from swiftfin.layout.design import load_design_source

    params_file = Path(params_file)
    p, raw = load_design_source(params_file)  # ParamError -> exit 2, nothing written
    cal = None
    if calibration is not None:
        from swiftfin.core.calibration import load_calibration
        cal = load_calibration(calibration, p)    # ParamError -> exit 2, nothing written
        changes = cal.changes(p)
        p = cal.revised_params(p)
    out = Path(out_dir)
    keep = (params_file,)
    outdir.check_out_dir(out, keep)
    outdir.remove_stale_temp_dirs(out)
    tmp = outdir.make_temp_dir(out)
    prefetch = checks = None
    try:
        if cache is not None and build_jobs() > 1:
            from swiftfin.prefetch import Prefetch
            prefetch = Prefetch(cache.root, STAGE_MODULES["part_core"], build_jobs())
            prefetch.plots(p)
        result = build_parts(p, cache, progress, prefetch=prefetch)
        place_ballast(result, cache, progress)
        if cal is not None:
            result.calibration, result.calibration_changes = cal, changes
        if progress:
            progress("  checking the assembly over the joints' range of motion ...")
        checks = start_checks(result, cache, progress)     # beside the writing; joined before the report
        if prefetch is not None:
            prefetch.close()
        write_outputs(result, tmp, params_file, progress, params_sha256=sha256_bytes(raw), cache=cache,
                      ros2_package=ros2_package, swim=swim, checks=checks)
        checks()                            # joined already by the report; never into place unchecked
        outdir.swap_into_place(tmp, out, keep)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        if prefetch is not None:
            prefetch.close(cancel=True)     # after a failure: its results are not waited for
        if checks is not None:
            checks.cancel()                 # likewise (nothing to do once joined)
    return result


MATE_WORDS = {"fastener": "by fasteners", "glued": "glued", "pad": "on pads", "bearing": "on bearing fits",
              "clamped": "clamped between the halves (the seam gasket)", "edge": "hull halves meeting on an edge only"}


def summary_table(result: BuildResult) -> str:
    rows = [("part", "family", "link", "volume cm^3", "bbox mm (print)", "time s", "cached")]
    for b in result.parts:
        sx, sy, sz = b.export.print_size_mm
        rows.append((b.spec.label, b.spec.family, str(b.spec.link), f"{b.export.volume_mm3 / 1000:.2f}",
                     f"{sx:.1f} x {sy:.1f} x {sz:.1f}", f"{b.time_s:.2f}", "yes" if b.cached else "no"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths)))
             for r in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    n_print = sum(b.spec.printed for b in result.parts)
    lines.append(f"{len(result.parts)} parts ({n_print} printed); families "
                 f"{sum(result.family_times_s.values()):.1f} s, assembly checks {result.check_time_s:.1f} s")
    st = result.assembly_stats
    if st:
        lines.append(f"assembly checks passed: {st['pairs']} pairs keep print.clearance_assembly_mm over the joints' "
                     f"range, {st['contact_pairs']} declared contacts do not interpenetrate, {st['inside_checked']} "
                     f"internal parts inside the hull ({st['pairs_remembered']} pair results remembered from earlier "
                     f"builds of the same parts)")
    cs = result.cable_stats
    if cs:
        lines.append(f"cables, tubes and leads clear: {cs['cable_pieces']} cable pieces, {cs['tubes']} PTFE tubes "
                     f"and {cs.get('leads', 0)} leads (wiring harness) keep their clearances to every part over the "
                     f"joints' range ({cs['pairs']} pairs, "
                     f"{cs['contact_pairs']} declared contacts, {cs['pairs_remembered']} remembered)")
    if cs.get("worst_tube"):
        lines.append(f"PTFE tubes seated: every tube on its printed shoulder with its mouth open, held both ways "
                     f"(least margin: {cs['worst_tube']}, cable friction {cs['worst_drag_n']:.1f} N at the cable's "
                     f"breaking strength against {cs['worst_hold_n']:.0f} N)")
    fr = result.fastener_report
    if fr is not None and fr.fasteners:
        w = fr.worst_wall()
        kinds = {}
        for f in fr.fasteners:
            kinds[f.kind] = kinds.get(f.kind, 0) + 1
        what = ", ".join(f"{n} {k.replace('_', ' ')}s" for k, n in sorted(kinds.items()))
        worst = (f"; thinnest wall round a hole {w.wall_mm:.2f} mm (needs {w.limit_mm:.2f}): the {w.feature} of "
                 f"{w.fastener} in {w.part}" if w is not None else "")
        hows: dict[str, int] = {}
        for _, _, how, _ in fr.mating_pairs:
            hows[how] = hows.get(how, 0) + 1
        mates = (f"; every touching pair of the contact table joined ({len(fr.mating_pairs)}: "
                 + ", ".join(f"{n} {MATE_WORDS.get(h, h)}" for h, n in sorted(hows.items(), key=lambda t: -t[1]))
                 + ")" if fr.mating_pairs else "")
        lines.append(f"fastener checks passed: {len(fr.fasteners)} fasteners ({what}) in "
                     f"{len(fr.per_part())} parts, walls, engagement, lengths and drivers' paths{worst}{mates}")
    lines.append(thin_wall_summary(result))
    lines.append(bridge_summary(result))
    dr = result.dry_report
    if dr is not None:
        lines.append(dry_wall_summary(result.params, dr))
    plan = result.assembly_plan
    if plan is not None:
        parts = sum(len(s.parts) for s in plan.steps)
        rem = (f", {plan.pairs_remembered} found proved already, earlier in the plan or by an earlier build"
               if plan.pairs_remembered else "")
        lines.append(f"assembly steps: {len(plan.steps)} steps put in {parts} parts and {plan.fastener_count} "
                     f"fasteners; {plan.checked_paths} ways in proved clear of the parts already placed "
                     f"({plan.pair_checks} part pairs along them{rem}); {len(plan.notes)} part(s) not along their "
                     f"family's usual direction (see report.html)")
    return "\n".join(lines)


def thin_wall_summary(result: BuildResult) -> str:
    """The ray-cast wall probe over every printed part (exports/printability.py): what is thinner than two
    perimeters, and than one line width. A finding, not a refusal."""
    lw = result.params.print.line_width_mm
    printed = [bp for bp in result.parts if bp.spec.printed]
    walls = [(bp.spec.label, w) for bp in printed for w in bp.export.thin_walls]
    if not walls:
        return f"walls: none under two perimeters ({2 * lw:g} mm) on the {len(printed)} printed parts (ray-cast probe)"
    under = [(lb, w) for lb, w in walls if w.thickness_mm < lw]
    lb, w = min(walls, key=lambda t: t[1].thickness_mm)
    return (f"walls (ray-cast probe): {len(walls)} region(s) under two perimeters ({2 * lw:g} mm) on "
            f"{len({x for x, _ in walls})} of {len(printed)} printed parts, {len(under)} under one line width "
            f"({lw:g} mm) on {len({x for x, _ in under})}; thinnest: {lb}, {w} (each part's count on its card in report.html)")


def bridge_summary(result: BuildResult) -> str:
    """The bridge rule over every printed part in its print orientation (exports/printability.bridges): each
    nearly horizontal ceiling that spans more than ``print.max_bridge_mm`` between edges with material below, or
    has no such edge. A finding, not a refusal (a slicer supports what it cannot bridge: it is in the support
    area)."""
    limit = result.params.print.max_bridge_mm
    printed = [bp for bp in result.parts if bp.spec.printed]
    found = [(bp.spec.label, b) for bp in printed for b in bp.export.bridges]
    if not found:
        return f"bridges: none over {limit:g} mm (print.max_bridge_mm) on the {len(printed)} printed parts"
    hanging = [(lb, b) for lb, b in found if b.hanging]
    spans = [(lb, b) for lb, b in found if not b.hanging]
    text = (f"bridges over {limit:g} mm (print.max_bridge_mm): {len(spans)} on "
            f"{len({lb for lb, _ in spans})} of {len(printed)} printed parts")
    if spans:
        lb, b = max(spans, key=lambda t: t[1].span_mm)
        text += f"; longest: {lb}, {b}"
    if hanging:
        lb, b = max(hanging, key=lambda t: t[1].area_mm2)
        text += (f"; {len(hanging)} ceiling(s) with no edge on material below (support starts them), the "
                 f"largest: {lb}, {b.area_mm2:.1f} mm^2 at ({', '.join(f'{v:.1f}' for v in b.at_mm)}) mm")
    return text + " (each part's on its card in report.html)"


def dry_wall_summary(p: Params, dr) -> str:
    from swiftfin.cad.dry_check import sealed_part_labels
    from swiftfin.design_rules.rules import gland_rating_m

    worst = min(dr.glands, key=lambda g: gland_rating_m(p, g.packed_mm, g.stroke_mm), default=None)
    glands = "no cable gland"
    if worst is not None:
        rated = gland_rating_m(p, worst.packed_mm, worst.stroke_mm)
        depth = p.environment.design_depth_m
        glands = (f"{len(dr.glands)} cable glands (the least rated to {rated:.2f} m, "
                  f"{'BELOW' if rated < depth else 'over'} the design depth {depth:g} m: {worst.label}, "
                  f"{worst.packed_mm:.1f} mm packed, stroke {worst.stroke_mm:.1f} mm)")
    seams = ("the sealed pieces' halves on the seam gasket (cad/seal.py), their splices bonded with epoxy"
             if any(lb.startswith("seam_gasket") for lb in sealed_part_labels(p)) else
             "NOT sealed: the parting seams between the sealed pieces' halves (a build without the seam gasket)")
    return (f"dry wall closed: {len(dr.openings)} openings through it, each a declared sealed crossing: {glands}, "
            f"{len(dr.screws)} screws bedded in sealant; seams: {seams}")


def stderr_progress(msg: str) -> None:
    """A line on stderr, above the progress bar if one is drawn (``swiftfin.progress``)."""
    say(msg)


SWIM_FREQUENCIES_HZ = (1.0, 2.0, 3.0)


def swim_results(mjcf_path: Path, params: Params, jobs: int | None = 1, duration_s: float = 6.0) -> list[dict]:
    """The exported fish swimming free in MuJoCo at 1, 2 and 3 Hz, with MuJoCo's quasi-steady fluid model alone
    and with Lighthill's reactive force (physics/swim_sim.py): speed, stride U / (f L) and slip U / (f lambda)
    per frequency. Six runs of ``duration_s``, one process each on every core."""
    from swiftfin.exports.parallel import map_parts
    from swiftfin.physics.swim_sim import free_swim_speed_m_s

    runs = [(f, reactive) for f in SWIM_FREQUENCIES_HZ for reactive in (False, True)]
    speeds = map_parts(lambda r: free_swim_speed_m_s(str(mjcf_path), params, r[0], r[1], duration_s), runs, jobs)
    L = params.body.length_mm / 1000
    lam = params.swimming.wavelength_body_lengths * L
    by = dict(zip(runs, speeds))
    return [{"frequency_hz": f, "duration_s": duration_s,
             "quasi_steady_m_s": by[(f, False)], "reactive_m_s": by[(f, True)],
             "stride_quasi_steady": by[(f, False)] / (f * L), "stride_reactive": by[(f, True)] / (f * L),
             "slip_reactive": by[(f, True)] / (f * lam)} for f in SWIM_FREQUENCIES_HZ]


def fastener_bores(p: Params, label: str, rotation_deg) -> tuple[int, tuple]:
    """(how many fastener holes part ``label`` has, those whose ceiling needs support in its print orientation):
    :func:`swiftfin.layout.fastening.bores_in_part` of every fastener, each with its axis' tilt from the print's
    vertical (the rule: :func:`swiftfin.design_rules.rules.supported_bores`)."""
    import math

    import numpy as np

    from swiftfin.cad.fastening import all_fasteners
    from swiftfin.design_rules.printing import Bore
    from swiftfin.exports.files import rotation_matrix
    from swiftfin.layout.fastening import bores_in_part

    up = rotation_matrix(tuple(rotation_deg))[:3, :3].T @ np.array([0.0, 0.0, 1.0])
    n, out = 0, []
    for f in all_fasteners(p):
        for what, d in bores_in_part(f, label):
            n += 1
            tilt = math.degrees(math.acos(min(1.0, abs(float(np.dot(f.axis, up))))))
            if tilt > p.print.support_angle_deg + 1e-6 and d > p.print.max_bridge_mm:
                out.append(Bore(f.label, what, d, tilt))
    return n, tuple(out)


def print_record(part, p: Params):
    """The printability rules' record (:class:`swiftfin.design_rules.printing.PrintRecord`) of a printed part: a
    ``BuiltPart``'s export or a ``ReportPart``; None for a bought part or one whose support was not computed."""
    from swiftfin.design_rules.printing import PrintRecord, Span, Wall

    exp = getattr(part, "export", part)
    label = part.spec.label if hasattr(part, "spec") else part.label
    printed = part.spec.printed if hasattr(part, "spec") else part.printed
    if not printed or getattr(exp, "support_area_mm2", None) is None or exp.print_rotation is None:
        return None
    walls = tuple(Wall(w.thickness_mm, w.limit_mm, w.area_mm2, tuple(w.at_mm), getattr(w, "kind", "wall"))
                  for w in exp.thin_walls)
    spans = tuple(Span(None if b.hanging else b.span_mm, b.limit_mm, b.area_mm2, tuple(b.at_mm)) for b in exp.bridges)
    rot = tuple(float(a) for a in exp.print_rotation)
    checked, bores = fastener_bores(p, label, rot)
    return PrintRecord(label, rot, float(exp.support_area_mm2), walls, spans, checked, bores)


def report_findings(params: Params, parts, mass_properties: dict | None, calibration=None) -> tuple[list, list]:
    """What the report shows and does not compute: the design rules' findings (with the build's mass properties
    and the printed parts' boxes when there are any) and the paper audit's entries."""
    from swiftfin.design_rules import design_findings
    from swiftfin.design_rules.paper_audit import audit_entries
    from swiftfin.report.html import as_report_part

    rparts = [as_report_part(x) for x in parts] if parts else []
    boxes = {x.label: x.print_size_mm for x in rparts if x.printed and x.print_size_mm}
    records = {r.label: r for r in (print_record(x, params) for x in rparts) if r is not None}
    findings = design_findings(params, mass_properties, boxes, calibration, records)
    gaskets = [x.spec for x in parts or () if hasattr(x, "spec") and x.spec.family == "seal"]
    if gaskets:
        from swiftfin.exports.gasket import gasket_numbers
        from swiftfin.design_rules.rules import built_seam_gasket_findings
        per = [built_seam_gasket_findings(params, gasket_numbers(params, g)) for g in gaskets]
        # one finding per rule: the gasket with the least margin (the head's alone on the default design)
        findings = [*findings, *(min(fs, key=lambda f: f.margin) for fs in zip(*per))]
    return findings, list(audit_entries())


def report_for_build(result, out_dir, params_name: str = "swiftfin.toml",
                     progress: Callable[[str], None] | None = None, fit_dir=None, memo=None,
                     plots=None, swim: list[dict] | None = None) -> Path:
    """The report of a finished ``swiftfin.pipeline.build`` (``result``: its BuildResult) into its folder: the
    parts as built, the mass table from ``out_dir/mass_properties.json`` when the build wrote one. For
    ``swiftfin build`` to call after the files are in place."""
    from swiftfin.report.html import MASS_PROPERTIES_NAME, write_report

    out = Path(out_dir)
    mp, note = None, ""
    mpath = out / MASS_PROPERTIES_NAME
    if mpath.is_file():
        try:
            mp, note = json.loads(mpath.read_text()), f"From {MASS_PROPERTIES_NAME} in this build."
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            note = f"{MASS_PROPERTIES_NAME} in this build is not readable JSON ({exc})."
    findings, audit = report_findings(result.params, result.parts, mp, result.calibration)
    rules_note = ""
    if result.calibration is not None:
        rules_note = (f"Evaluated with the measured values of {CALIBRATION_NAME} (a copy of "
                      f"{result.calibration.path}, in this build): " + ("; ".join(result.calibration_changes)
                                                                       or "none of its values applies") + ".")
    return write_report(result.params, out, parts=result.parts, mass_properties=mp, fit_dir=fit_dir, rules_note=rules_note,
                        findings=findings, audit=audit, progress=progress, params_name=params_name, mass_note=note,
                        memo=memo, plots=plots, jobs=build_jobs(), swim=swim)
