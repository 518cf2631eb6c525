"""``swiftfin report [PARAMS] --out DIR [--fit DIR] [--solve FILE]``: the design report, ``DIR/report.html``.

One self-contained page (pictures and styles inlined, no network): the assembly and every printable part
rendered off-screen, the design rules, the mass table, the efficiency / tail-beat / body-wave plots, the paper
audit and, with ``--fit FITDIR``, the before/after plots and effects of a ``swiftfin fit`` run; with ``--solve
FILE``, the trade-offs of a ``swiftfin solve --json FILE`` run (the nearest passing design, the Pareto front).

Where the parts come from:

* DIR holds a build of the same parameter file (``manifest.json`` whose ``params_sha256`` matches, and
  ``assembly.step``): the parts are read from it, and the mass table from ``DIR/mass_properties.json`` when
  the build wrote one (otherwise the page says the mass properties were not computed in this build);
* otherwise the parts are built in memory as ``swiftfin build`` makes them, the trim ballast included, and the
  mass properties computed here (``--no-mass`` skips that), the parts, the mass model and the pictures through the
  rebuild cache (``--no-cache``: a temporary one, removed after). Nothing but ``report.html`` is written to DIR.

Progress goes to stderr, a line per step, only when stderr is a terminal.
"""
from __future__ import annotations

import hashlib
import json
import sys
import time
from pathlib import Path

from swiftfin.layout.design import load_design
from swiftfin.core.errors import UserError
from swiftfin.commands import DESIGN_HELP


# Pictures need less than the exports: 0.1 mm is about half a pixel of the 2x supersampled assembly view
# (2400 px across 520 mm), and it tessellates ~3x fewer triangles than the default 0.05 mm / 10 deg.
PICTURE_TOLERANCE_MM = 0.1
PICTURE_ANGULAR_TOLERANCE_DEG = 15.0


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    ap.add_argument("params_file", nargs="?", default=None, help=DESIGN_HELP)
    ap.add_argument("--out", default="build", help="build folder; report.html is written here (default: build/)")
    ap.add_argument("--fit", metavar="FITDIR", default=None,
                    help="a `swiftfin fit` output folder (fit_report.json and PNG plots) to include")
    ap.add_argument("--solve", metavar="SOLVE.json", default=None,
                    help="a `swiftfin solve --json` result to include: the nearest passing design and the Pareto "
                         "front over speed, mass and power")
    ap.add_argument("--cache-dir", default=None, help="rebuild cache when the parts must be built "
                                                      "(default: $SWIFTFIN_CACHE_DIR or .cache/swiftfin/)")
    ap.add_argument("--no-cache", action="store_true", help="do not read or write the rebuild cache")
    ap.add_argument("--no-mass", action="store_true",
                    help="do not compute mass properties when DIR has no mass_properties.json")
    ap.set_defaults(func=run)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def build_in_dir(out: Path, params_file: Path) -> dict | None:
    """The manifest of the build in ``out`` if it is a build of ``params_file`` with an assembly.step."""
    man = out / "manifest.json"
    if not man.is_file() or not (out / "assembly.step").is_file():
        return None
    try:
        manifest = json.loads(man.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    if not isinstance(manifest, dict) or manifest.get("params_sha256") != _sha256(params_file):
        return None
    return manifest


def parts_from_build_dir(out: Path, manifest: dict, p, progress) -> list:
    """ReportParts from a build folder: rest-pose meshes from ``assembly.step`` (product names = labels),
    family / link / print facts from ``manifest.json``."""
    import build123d as bd

    from swiftfin.exports.files import tessellate
    from swiftfin.report.html import ReportPart

    progress(f"reading {out / 'assembly.step'}")
    try:
        shape = bd.import_step(str(out / "assembly.step"))
    except Exception as exc:  # noqa: BLE001 - OCC raises many types for an unreadable STEP
        raise UserError(f"{out / 'assembly.step'}: cannot read the assembly STEP ({type(exc).__name__}: {exc}); "
                        "rebuild with `swiftfin build`") from None
    entries = manifest.get("parts", [])
    wanted = {e.get("label") for e in entries}
    solids = {}
    stack = [shape]
    while stack:   # the STEP tree: the assembly product, then one product per part
        node = stack.pop()
        label = getattr(node, "label", "")
        if label in wanted and label not in solids:
            solids[label] = node
            continue
        stack.extend(getattr(node, "children", ()) or ())
    missing = [e.get("label") for e in entries if e.get("label") not in solids]
    if missing or not entries:
        raise UserError(f"{out / 'assembly.step'}: parts {', '.join(map(str, missing[:5])) or '(none)'} of "
                        f"manifest.json are not in the assembly; rebuild with `swiftfin build`")
    from swiftfin.design_rules.printing import records_from_manifest
    _, records = records_from_manifest(manifest, str(out / "manifest.json"))
    parts = []
    for k, e in enumerate(entries):
        progress(f"tessellating part {k + 1}/{len(entries)}: {e['label']}")
        mesh = tessellate(solids[e["label"]], max(p.export.mesh_tolerance_mm, PICTURE_TOLERANCE_MM),
                          max(p.export.mesh_angular_tolerance_deg, PICTURE_ANGULAR_TOLERANCE_DEG))
        size = e.get("print_size_mm")
        parts.append(ReportPart(e["label"], e.get("family", ""), int(e.get("link", 0)), bool(e.get("printed", True)),
                                mesh.vertices, mesh.faces, tuple(size) if size else None, e.get("volume_mm3"),
                                tuple(e["print_rotation"]) if e.get("print_rotation") else None,
                                **_print_facts(records.get(e["label"]))))
    return parts


def _print_facts(rec) -> dict:
    """A ReportPart's printability fields from its manifest record (none when the manifest has none)."""
    if rec is None:
        return {}
    return {"support_area_mm2": rec.support_area_mm2, "thin_walls": rec.walls, "bridges": rec.bridges}


def _read_mass_properties(path: Path):
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UserError(f"{path}: not readable JSON ({exc}); rebuild or delete it") from None
    if not isinstance(data, dict):
        raise UserError(f"{path}: expected a JSON object of mass properties, got {type(data).__name__}")
    return data


def _read_solve(path: Path) -> dict:
    """The JSON ``swiftfin solve --json`` wrote, checked for what the report reads (UserError naming the file)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UserError(f"--solve {path}: no such file (expected the JSON of `swiftfin solve --json FILE`)") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UserError(f"--solve {path}: not readable JSON ({exc})") from None
    if not isinstance(data, dict) or not isinstance(data.get("changes"), list) or "passes" not in data:
        raise UserError(f"--solve {path}: not a `swiftfin solve --json` result (expected an object with "
                        f"'passes' and a 'changes' list)")
    front = data.get("front")
    if front is not None:
        pts = front.get("points") if isinstance(front, dict) else None
        need = ("speed_m_s", "mass_kg", "power_w", "binding")
        if not isinstance(pts, list) or not all(isinstance(q, dict) and all(
                isinstance(q.get(k), (int, float, str)) for k in need) for q in pts):
            raise UserError(f"--solve {path}: its 'front' needs a 'points' list, each with "
                            f"{', '.join(need)}")
    return data


def run(args) -> int:
    from swiftfin.report.html import MASS_PROPERTIES_NAME, Progress

    t0 = time.perf_counter()
    params_file = Path(args.params_file)
    p = load_design(params_file)  # ParamError -> exit 2, nothing written
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UserError(f"{out} exists and is not a folder; choose another --out")
    if args.fit is not None and not Path(args.fit).is_dir():
        raise UserError(f"--fit {args.fit}: no such folder (expected the output folder of `swiftfin fit`)")
    solve = _read_solve(Path(args.solve)) if args.solve is not None else None
    progress = Progress()
    manifest = build_in_dir(out, params_file)
    mp, note = None, ""
    if manifest is not None:
        parts = parts_from_build_dir(out, manifest, p, progress)
        mpath = out / MASS_PROPERTIES_NAME
        if mpath.is_file():
            mp, note = _read_mass_properties(mpath), f"From {mpath}."
        else:
            note = f"The build in {out} wrote no {MASS_PROPERTIES_NAME}."
        return _write(args, p, out, params_file, parts, mp, note, progress, t0, solve)
    # no build of this design in DIR: the parts built in memory with the trim ballast, as `swiftfin build` makes
    # them, and the mass model and the pictures through the same rebuild cache (a temporary one with --no-cache)
    import functools

    from swiftfin.cache import command_cache
    from swiftfin.pipeline import build_jobs, build_parts, place_ballast, stage_memo
    from swiftfin.prefetch import report_plots

    progress(f"no build of {params_file} in {out}/: building the parts in memory")
    with command_cache(args.no_cache, args.cache_dir) as cache:
        result = build_parts(p, cache, progress)
        place_ballast(result, cache, progress)
        parts, memo = result.parts, stage_memo(result, cache)
        if args.no_mass:
            note = "Skipped (--no-mass)."
        else:
            try:
                from swiftfin.exports.massprops import mass_properties, report_to_dict
            except ImportError:
                note = "exports.massprops is not part of this installation."
            else:
                import trimesh

                progress("computing mass properties (printed parts: walls, skins and infill)")
                # the build's own meshes: the triangles exports.massprops would make again (same tessellator)
                meshes = {b.spec.label: trimesh.Trimesh(b.export.mesh.vertices, b.export.mesh.faces, process=False)
                          for b in parts if b.spec.printed}
                mp = report_to_dict(p, mass_properties(p, [b.spec for b in parts], meshes, memo=memo,
                                                       jobs=build_jobs()))
                note = "Computed for this report (the folder held no build of this parameter file)."
        return _write(args, p, out, params_file, parts, mp, note, progress, t0, solve, memo=memo,
                      plots=functools.partial(report_plots, cache, p), jobs=build_jobs())


def _write(args, p, out: Path, params_file: Path, parts, mp, note: str, progress, t0: float, solve: dict | None,
           memo=None, plots=None, jobs: int | None = 1) -> int:
    """The rules, the audit and report.html from the parts and mass properties found or made by :func:`run`."""
    from swiftfin.pipeline import report_findings
    from swiftfin.report.html import ReportTiming, write_report

    progress("applying the design rules and recomputing the paper audit")
    findings, audit = report_findings(p, parts, mp)
    timing = ReportTiming()
    path = write_report(p, out, parts=parts, mass_properties=mp, fit_dir=args.fit, findings=findings, audit=audit,
                        progress=progress, params_name=params_file.name, mass_note=note, timing=timing,
                        solve=solve, solve_name=Path(args.solve).name if args.solve else "", memo=memo,
                        plots=plots, jobs=jobs)
    size = path.stat().st_size
    print(f"swiftfin report: wrote {path} ({size / 1e6:.2f} MB; pictures {timing.render_s:.1f} s, plots "
          f"{timing.plots_s:.1f} s, total {time.perf_counter() - t0:.1f} s)")
    sys.stdout.flush()
    return 0
