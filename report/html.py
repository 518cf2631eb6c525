"""The design report's page: assembles one self-contained HTML page (``DIR/report.html``) per build.

Everything is inlined: pictures and plots as base64 ``data:image/png`` URIs, the style sheet in a ``<style>``
element, system fonts only, no script, no link to anything outside the file; it opens offline anywhere.

Sections (ids in :data:`SECTIONS`): overview (the design's key numbers), assembly (rendered exterior and a
cut-away without the upper hull halves), parts (a picture of every printable part with its printed mass and
print settings; bought parts in a table), design rules (failing first, coloured by verdict, with margins),
mass (per part, per link, total mass and buoyancy), transmission efficiency (the paper's Figure 8 recomputed),
one tail-beat (joint angles, step rates), body wave, paper audit, and the fit (when a fit folder is given).
A section whose inputs are missing says so on the page instead of showing invented numbers.

This module assembles the page: the report's inputs (:class:`ReportPart`), the pictures, the plots, the page
frame and the file. The sections are in :mod:`swiftfin.report.sections`, the HTML builders in
:mod:`swiftfin.report.markup`, the style sheet and colours in :mod:`swiftfin.report.assets`.
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from swiftfin import __version__
from swiftfin.core.schema import Params
from swiftfin.report.assets import CSS, FAMILY_COLORS, OTHER_COLOR
from swiftfin.report.markup import esc
from swiftfin.report.robot import robot_section
from swiftfin.report.sections import (BOM_NAME, FIT_REPORT_NAME, MASS_PROPERTIES_NAME, STEPS_NAME, assembly_section,
                                      audit_section, read_steps, steps_section,
                                      bom_section, read_bom,
                                      fit_section, mass_section, overview_section, parts_section, plot_section,
                                      rules_section, solve_section, sorted_findings)

__all__ = ["ASSEMBLY_VIEW_FACE_FRACTION", "FIT_REPORT_NAME", "MASS_PROPERTIES_NAME", "REPORT_NAME", "SECTIONS",
           "Progress", "ReportPart", "ReportTiming", "as_report_part", "build_page", "render_pictures",
           "sorted_findings", "standard_plots", "write_report"]

REPORT_NAME = "report.html"

SECTIONS = (("overview", "Overview"), ("assembly", "Assembly"), ("steps", "Assembly steps"), ("parts", "Parts"),
            ("bom", "Bill of materials"),
            ("rules", "Design rules"),
            ("mass", "Mass"), ("robot", "Robot"), ("efficiency", "Efficiency"), ("tailbeat", "Tail-beat"), ("wave", "Body wave"),
            ("audit", "Paper audit"), ("fit", "Fit"), ("solve", "Trade-offs"))


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
    support_area_mm2: float | None = None      # overhang needing support in the print orientation
    orientations: tuple = ()                   # (rotation, support mm^2, fits) of the orientations tried
    thin_walls: tuple = ()                     # exports.printability.ThinWall of the part (body frame)
    bridges: tuple = ()                        # exports.printability.Bridge over print.max_bridge_mm (body frame)


def as_report_part(part) -> ReportPart:
    """A ReportPart from a ReportPart or a ``swiftfin.pipeline.BuiltPart``."""
    if isinstance(part, ReportPart):
        return part
    spec, exp = part.spec, part.export
    return ReportPart(spec.label, spec.family, int(spec.link), bool(spec.printed), np.asarray(exp.mesh.vertices),
                      np.asarray(exp.mesh.faces), tuple(float(v) for v in exp.print_size_mm), float(exp.volume_mm3),
                      tuple(float(v) for v in (exp.print_rotation if getattr(exp, "print_rotation", None)
                                               is not None else spec.print_rotation)), spec.mass_kg,
                      getattr(exp, "support_area_mm2", None), tuple(getattr(exp, "orientations", ()) or ()),
                      tuple(getattr(exp, "thin_walls", ()) or ()), tuple(getattr(exp, "bridges", ()) or ()))


class Progress:
    """A line per step on a terminal (stderr), nothing when stderr is not a TTY (CI logs)."""

    def __init__(self, enabled: bool | None = None, stream=None):
        self.stream = stream or sys.stderr
        self.enabled = (hasattr(self.stream, "isatty") and self.stream.isatty()) if enabled is None else enabled
        self.t0 = time.perf_counter()

    def __call__(self, msg: str) -> None:
        if self.enabled:
            print(f"  [{time.perf_counter() - self.t0:6.1f} s] {msg}", file=self.stream, flush=True)


# ----------------------------------------------------------------------------------------------- pictures, plots
#: share of each part's triangles drawn in an assembly view (vertex clustering, per part, so that a part's view
#: mesh does not change when another part does): about 120 000 of the default design's ~330 000, still smaller
#: than the pixels of the hull's curvature at 2400 x 860 supersampled pixels for 520 mm of fish.
ASSEMBLY_VIEW_FACE_FRACTION = 0.35


def view_mesh(memo, label: str, vertices, faces) -> tuple:
    """A part's mesh for the assembly views: ``ASSEMBLY_VIEW_FACE_FRACTION`` of its triangles (vertex clustering),
    from the memo (stage "view_mesh") when it has it."""
    from swiftfin.exports.parallel import memoized
    from swiftfin.report.render import cluster_decimate

    n = max(200, int(ASSEMBLY_VIEW_FACE_FRACTION * len(faces)))
    return memoized(memo, "view_mesh", (label,), [n], lambda: cluster_decimate(vertices, faces, n))


#: what is already in place in an exploded view, and the camera of every step's picture
PLACED_COLOR = (0.80, 0.80, 0.80)
STEP_VIEW = (900, 330, 62.0, 30.0)


class _NotStored(Exception):
    """A picture the store does not hold (render_pictures looks them up before it hands out the rest)."""


def render_pictures(parts: list[ReportPart], steps: dict | None, progress: Callable[[str], None],
                    memo=None, jobs: int | None = 1, tasks: dict | None = None
                    ) -> tuple[dict, dict[str, bytes], dict[int, bytes], float, dict]:
    """Every picture of the report, rendered on ``jobs`` processes (one picture each, the largest first):
    the assembly ({'exterior', 'cutaway'}), one picture per printed part and, with ``steps`` (the build's
    ``assembly_steps.json``), one exploded view per step that puts parts in (:func:`step_scenes`).
    Returns (assembly pictures, part pictures by label, step pictures by number, seconds taken, the tasks'
    results by name).
    ``memo(stage, labels, extra, compute)``: the application's store of pictures and view meshes, keyed by the
    parts' content (None: render every picture). ``tasks``: {name: a function of no arguments} run on the same
    processes, before the pictures (the plots, the robot's picture)."""
    from swiftfin.report.render import CREASE_DEG, MeshItem, corner_normals, load_kernel, png_bytes, render

    from swiftfin.exports.parallel import map_parts, memoized

    t0 = time.perf_counter()
    items = {p.label: MeshItem(p.vertices, p.faces, FAMILY_COLORS.get(p.family, OTHER_COLOR), p.label) for p in parts}

    def view_item(it: MeshItem) -> MeshItem:
        v, f = view_mesh(memo, it.name, it.vertices, it.faces)
        return MeshItem(v, f, it.color, it.name)

    view = {label: view_item(it) for label, it in items.items()}
    cut = [view[p.label] for p in parts if not (p.family == "hull" and p.label.endswith("_upper"))]
    printed = [p for p in parts if p.printed]
    # (key, scene, camera (w, h, azimuth, elevation), extra key words of the stored picture)
    scenes = [(("assembly", "exterior"), list(view.values()), (1200, 430, 62, 22), []),
              (("assembly", "cutaway"), cut, (1200, 430, 58, 40), [])]
    drawn = step_scenes(parts, steps or {}, view) if steps else []
    scenes += [(("step", number), scene, STEP_VIEW, extra) for number, scene, extra in reversed(drawn)]
    scenes += [(("part", p.label), [items[p.label]], (360, 250, 62, 28), []) for p in printed]
    progress(f"rendering the assembly (exterior; cut-away, upper hull halves hidden), {len(printed)} parts and "
             f"{len(drawn)} exploded assembly steps")

    normals: dict[int, np.ndarray] = {}     # by the faces array: a part drawn in up to 24 views, shifted or not

    def with_normals(it: MeshItem) -> MeshItem:
        if id(it.faces) not in normals:
            normals[id(it.faces)] = corner_normals(it.vertices, it.faces, CREASE_DEG)
        return dataclasses.replace(it, normals=normals[id(it.faces)])

    def picture(scene, compute=None) -> bytes:
        _key, what, (w, h, az, el), extra = scene
        return memoized(memo, "picture", tuple(it.name for it in what),
                        [w, h, az, el, [list(it.color) for it in what], [len(it.faces) for it in what]] + extra,
                        compute or (lambda: png_bytes(render([with_normals(it) for it in what], w, h,
                                                             azimuth_deg=az, elevation_deg=el, max_faces=10**9))))

    def not_stored():
        raise _NotStored       # raised before the store writes anything: a lookup only

    pngs = {}
    for scene in scenes:       # the stored pictures here; only the others go to the workers
        try:
            pngs[scene[0]] = picture(scene, not_stored)
        except _NotStored:
            pass
    todo = [scene for scene in scenes if scene[0] not in pngs]
    tasks = dict(tasks or {})

    def job(item):
        return item() if callable(item) else picture(item)

    if todo:
        load_kernel()          # once here, not once in each forked worker
    done = map_parts(job, list(tasks.values()) + todo, jobs)
    results = dict(zip(tasks, done))
    pngs.update(zip((key for key, *_ in todo), done[len(tasks):]))
    out = {name: png for (kind, name), png in pngs.items() if kind == "assembly"}
    pics = {name: png for (kind, name), png in pngs.items() if kind == "part"}
    step_pics = {name: pngs[("step", name)] for name, _scene, _extra in drawn}
    return out, pics, step_pics, time.perf_counter() - t0, results


def step_scenes(parts: list[ReportPart], steps: dict, view: dict) -> list[tuple[int, list, list]]:
    """The exploded view of every step that puts parts in: (step number, scene, stored picture's key words).
    The parts already in place in light grey, the step's parts in their family's colour, set back against
    their way in by ``explode_mm``; the parts not yet in are not drawn. ``view``: {label: MeshItem} of the
    assembly views' meshes."""
    from swiftfin.report.render import MeshItem

    by = {p.label: p for p in parts}
    placed: list[str] = []
    out = []
    for s in steps.get("steps", []):
        if not (s.get("parts") and all(q in by for q in s["parts"])):
            continue
        shift = -float(s.get("explode_mm", 0.0)) * np.asarray(s.get("vector", (0, 0, 0)), float)
        scene = [MeshItem(view[q].vertices, view[q].faces, PLACED_COLOR, q) for q in placed]
        scene += [MeshItem(view[q].vertices + shift, view[q].faces, FAMILY_COLORS.get(by[q].family, OTHER_COLOR), q)
                  for q in s["parts"]]
        out.append((s["number"], scene, [[round(float(c), 3) for c in shift], len(placed)]))
        placed += s["parts"]
    return out


@functools.lru_cache(maxsize=4)
def standard_plots(params: Params) -> tuple:
    """The efficiency, tail-beat and body-wave plots of a design (pure functions of the frozen Params, so
    they are computed once per design in a process)."""
    from swiftfin.report import plots

    return plots.efficiency_plot(params), plots.joint_plot(params), plots.wave_plot(params)


# ----------------------------------------------------------------------------------------------- page
@dataclass
class ReportTiming:
    render_s: float = 0.0
    plots_s: float = 0.0
    total_s: float = 0.0
    steps: dict = field(default_factory=dict)


def build_page(params: Params, parts=None, mass_properties: dict | None = None, fit_dir=None, *, findings,
               audit, progress: Callable[[str], None] | None = None, params_name: str = "swiftfin.toml",
               mass_note: str = "", timing: ReportTiming | None = None, memo=None, plots=None,
               jobs: int | None = 1, robot_dir: Path | None = None, swim: list[dict] | None = None,
               bom: list[dict] | None = None, steps: dict | None = None, solve: dict | None = None,
               solve_name: str = "", rules_note: str = "") -> str:
    """The report page as a string (see :func:`write_report`); ``rules_note``: a line above the rules (what
    they were evaluated with); ``plots``: the three plots of :func:`standard_plots`, or a function of no arguments
    that makes them (run on the pictures' processes, beside them). ``bom``: the rows of the build's ``bom.csv``;
    ``steps``: the build's ``assembly_steps.json``; ``solve``: a ``swiftfin solve --json`` result."""
    progress = progress or (lambda msg: None)
    timing = timing if timing is not None else ReportTiming()
    t_start = time.perf_counter()
    rparts = [as_report_part(x) for x in parts] if parts is not None else None
    pics = part_pics = None
    step_pics = {}
    tasks: dict = {}

    def timed_plots(make):
        t = time.perf_counter()
        return make(), time.perf_counter() - t

    if plots is None:
        try:
            hash(params)
            plot_fn = standard_plots
        except TypeError:   # a Params holding an unhashable value: compute without the cache
            plot_fn = standard_plots.__wrapped__
        tasks["plots"] = lambda: timed_plots(lambda: plot_fn(params))
    elif callable(plots):
        tasks["plots"] = lambda: timed_plots(plots)
    if robot_dir is not None and (robot_dir / "swiftfin.urdf").is_file():
        from swiftfin.report.render import png_bytes, render
        from swiftfin.report.robot import read_robot, robot_items

        from swiftfin.exports.parallel import memoized

        robot = read_robot(robot_dir)
        drawn = hashlib.sha256((robot_dir / "swiftfin.urdf").read_bytes())     # what the picture shows
        for path in sorted({c for lk in robot["links"].values() for c in lk["collisions"]}):
            drawn.update(path.read_bytes())
        tasks["robot"] = lambda: memoized(memo, "robot_picture", (), [drawn.hexdigest()],
                                          lambda: png_bytes(render(robot_items(robot), 1200, 430, azimuth_deg=62,
                                                                   elevation_deg=22)))
    if tasks:
        progress("plotting the efficiency curves (paper Fig. 8), one tail-beat and the body wave"
                 + (", and rendering the robot's collision shapes, joint axes and link frames" if "robot" in tasks
                    else ""))
    if rparts:     # the plots and the robot's picture on the same processes as the pictures
        pics, part_pics, step_pics, timing.render_s, results = render_pictures(rparts, steps, progress, memo, jobs,
                                                                               tasks)
    else:
        from swiftfin.exports.parallel import map_parts
        results = dict(zip(tasks, map_parts(lambda run: run(), list(tasks.values()), jobs)))
    if "plots" in results:
        plots, timing.plots_s = results["plots"]
    eff, beat, wave = plots
    robot_pic = results.get("robot")
    progress("writing the page")
    body = {
        "overview": overview_section(params, rparts, mass_properties, findings, audit, params_name),
        "assembly": assembly_section(pics, rparts or []),
        "steps": steps_section(steps, step_pics),
        "parts": parts_section(params, rparts, part_pics, mass_properties),
        "bom": bom_section(bom),
        "rules": rules_section(findings, rules_note),
        "mass": mass_section(params, mass_properties, mass_note),
        "robot": robot_section(robot_dir, robot_pic, swim),
        "efficiency": plot_section(eff, "transmission efficiency against frequency"),
        "tailbeat": plot_section(beat, "joint angles and step rates over one tail-beat"),
        "wave": plot_section(wave, "body wave envelope"),
        "audit": audit_section(audit),
        "fit": fit_section(Path(fit_dir) if fit_dir is not None else None),
        "solve": solve_section(solve, _solve_plot(solve), solve_name),
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


def _solve_plot(solve: dict | None):
    if not solve or not (solve.get("front") or {}).get("points"):
        return None
    from swiftfin.report.plots import pareto_plot
    return pareto_plot(solve["front"])


def write_report(params: Params, out_dir, parts=None, mass_properties: dict | None = None, fit_dir=None, *,
                 findings, audit, progress: Callable[[str], None] | None = None,
                 params_name: str = "swiftfin.toml", mass_note: str = "",
                 timing: ReportTiming | None = None, memo=None, plots=None, jobs: int | None = 1,
                 swim: list[dict] | None = None, solve: dict | None = None, solve_name: str = "",
                 rules_note: str = "") -> Path:
    """Write ``out_dir/report.html`` and return its path.

    ``parts``: ReportParts or ``swiftfin.pipeline.BuiltPart``s (None: no pictures, the page says so);
    ``mass_properties``: the content of ``mass_properties.json`` (None: the page says it was not computed);
    ``fit_dir``: a ``swiftfin fit`` output folder; ``findings`` / ``audit``: the design rules' findings and the
    paper audit's entries, computed by the caller (the report shows, it does not compute); ``plots``: the
    (efficiency, tail-beat, wave) plots of :func:`standard_plots` when the caller has them (its cache). The robot
    section reads ``out_dir/robot/`` when the folder holds a build's simulator files, the bill of materials
    ``out_dir/bom.csv`` when the build wrote one; ``swim``: the swimming
    results of ``swiftfin.pipeline.swim_results`` to show there; ``solve``: a ``swiftfin solve --json`` result
    (``solve_name`` its file) for the trade-offs section.
    The file is written to a temporary name and renamed, so a failed report never leaves half a page.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    robot_dir = out / "robot" if (out / "robot" / "swiftfin.urdf").is_file() else None
    bom = read_bom(out / BOM_NAME) if (out / BOM_NAME).is_file() else None
    steps = read_steps(out / STEPS_NAME) if (out / STEPS_NAME).is_file() else None
    page = build_page(params, parts, mass_properties, fit_dir, findings=findings, audit=audit, progress=progress,
                      params_name=params_name, mass_note=mass_note, timing=timing, memo=memo, plots=plots,
                      jobs=jobs, robot_dir=robot_dir, swim=swim, bom=bom, steps=steps, solve=solve,
                      solve_name=solve_name, rules_note=rules_note)
    path = out / REPORT_NAME
    tmp = out / f".{REPORT_NAME}.tmp"
    tmp.write_text(page, encoding="utf-8")
    tmp.replace(path)
    return path
