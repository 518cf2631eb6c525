"""``swiftfin check [PARAMS] [--json FILE]``: apply the design rules and print a table of findings.

Exit codes: 0 when no rule fails (PASS, INFO, WARN and NOT_EVALUATED do not fail), 1 when any rule fails,
2 for a bad parameter file or a bad --mass-properties / --parts-bbox file.

In CI::

    swiftfin check swiftfin.toml --json build/check.json   # the job fails on exit code 1 (or 2)

e.g. as a GitHub Actions step after ``make build`` has set up ``.venv``::

    - name: design rules
      run: .venv/bin/swiftfin check swiftfin.toml --json build/check.json
    - uses: actions/upload-artifact@v4
      if: always()
      with: {name: design-rules, path: build/check.json}

A WARN (e.g. more redirecting guides than the paper's budget) or a NOT_EVALUATED rule (mass properties not
given) does not fail the job; read the "why:" lines under the table.

``--mass-properties FILE``: a build's ``mass_properties.json``, or JSON ``{"total_mass_kg": m, "com_m": [x, y, z],
"cob_m": [x, y, z], "displaced_volume_m3": V}`` in the body frame; without it the floating rules report
NOT_EVALUATED. ``--parts-bbox FILE``: JSON ``{"label": [dx, dy, dz], ...}`` in mm, print orientation; without it
the bed rule uses the layout's estimate of the largest parts. ``--build DIR``: a build folder; its
``mass_properties.json`` and its ``manifest.json`` (the printed parts' boxes and their printability records: support
area, thin walls, bridges; without it the print.support / thin_walls / bridges rules report NOT_EVALUATED); an
explicit --mass-properties or --parts-bbox wins over the folder's. ``--loads`` also prints the load model's numbers
per joint and the sensitivity of its outputs to the uncertain coefficients.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from swiftfin.design_rules import MassProperties, RuleContext, Severity, run_rules, verdict
from swiftfin.layout.loads import sensitivity_table
from swiftfin.layout.design import load_design
from swiftfin.core.errors import UserError
from swiftfin.core.params import ParamError, Problem, decode_text, read_file_bytes
from swiftfin.commands import DESIGN_HELP


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    ap.add_argument("params_file", nargs="?", default=None, help=DESIGN_HELP)
    ap.add_argument("--json", metavar="FILE", help="also write the findings as JSON")
    ap.add_argument("--mass-properties", metavar="FILE", help="JSON mass properties of the built robot")
    ap.add_argument("--parts-bbox", metavar="FILE", help="JSON print-orientation bounding boxes of the built parts [mm]")
    ap.add_argument("--build", metavar="DIR",
                    help="a build folder (swiftfin build --out DIR): its mass properties, its printed parts' boxes "
                         "and their printability (support, thin walls, bridges) as the build measured them")
    ap.add_argument("--loads", action="store_true", help="print the per-joint loads and their sensitivities")
    ap.add_argument("--calibration", metavar="FILE",
                    help="a calibration file (swiftfin fit joint writes one): the rules use the measured cable "
                         "stiffness and the hinges' measured damping and friction")
    ap.set_defaults(func=run)


MASS_PROPERTIES = ("mass properties file (JSON)", "the mass-properties file")   # (in messages, in the heading)
BBOX = ("parts bounding-box file (JSON)", "the parts bounding-box file")


def _read_json(path: str, side: tuple[str, str]):
    """The JSON in a side file (MASS_PROPERTIES or BBOX); any problem is named as one in that file, not in the
    parameter file."""
    what, kind = side
    text = decode_text(read_file_bytes(path, what, kind), path, what, kind)   # a directory, FIFO or device: said so
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ParamError(path, [Problem("(file)", path, f"is not readable JSON ({exc}); expected a {what}")],
                         kind) from None
    except RecursionError:
        raise ParamError(path, [Problem("(file)", path, f"is nested too deeply to read; expected a {what}")],
                         kind) from None


def _bboxes(path: str) -> dict:
    raw = _read_json(path, BBOX)
    if not isinstance(raw, dict) or not raw:
        raise ParamError(path, [Problem("(file)", type(raw).__name__, "expected a JSON object {label: [dx, dy, dz]}")],
                         BBOX[1])
    probs, out = [], {}
    for k, v in raw.items():
        if (isinstance(v, list) and len(v) == 3 and all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                                         and math.isfinite(c) and c > 0 for c in v)):
            out[k] = tuple(float(c) for c in v)
        else:
            probs.append(Problem(k, v, "expected three positive sizes [dx, dy, dz] in mm"))
    if probs:
        raise ParamError(path, probs, BBOX[1])
    return out


MANIFEST = ("build manifest (JSON)", "the build's manifest")


def read_build_dir(folder: str):
    """(mass properties or None, printed parts' boxes, print records) of a build folder: its ``manifest.json``
    (required) and its ``mass_properties.json`` (when the build wrote one). Errors name the folder or the file."""
    d = Path(folder)
    man = d / "manifest.json"
    if not d.is_dir() or not man.is_file():
        raise UserError(f"{folder}: {'no manifest.json in it' if d.is_dir() else 'not a folder'}; expected a build "
                        f"folder (swiftfin build --out {folder})")
    from swiftfin.design_rules.printing import records_from_manifest
    boxes, records = records_from_manifest(_read_json(str(man), MANIFEST), str(man))
    if not records:
        raise UserError(f"{man}: no printed part has a \"print\" entry (written by builds since 2026-11-28); "
                        f"rebuild with `swiftfin build --out {folder}`")
    mpath = d / "mass_properties.json"
    mp = None
    if mpath.is_file():
        raw = _read_json(str(mpath), MASS_PROPERTIES)
        mp = MassProperties.from_dict(raw, str(mpath))
    return mp, boxes, records


def _write_json(path: str, data) -> None:
    out = Path(path)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(data, indent=2))
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc}") from None


def _fmt(v) -> str:
    return "-" if v is None else f"{v:.4g}"


def format_table(findings) -> str:
    rows = [("rule", "value", "limit", "margin", "verdict")]
    for f in findings:
        rows.append((f.rule_id, f.value_text() + ("" if f.unit == "-" or f.value is None else f" {f.unit}"),
                     f.limit_text(), f.margin_text(), f.severity.name))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = []
    for n, r in enumerate(rows):
        lines.append("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)


def loads_report(ctx: RuleContext) -> dict:
    jl, dl = ctx.loads, ctx.drive
    per_joint = []
    for j in range(ctx.p.joints.count):
        per_joint.append({
            "joint": j + 1,
            "amplitude_deg": math.degrees(float(np.abs(jl.joint_angle_rad[:, j]).max())),
            "peak_torque_nm": float(jl.peak_torque_nm[j]),
            "peak_torque_components_nm": {k: float(v[j]) for k, v in jl.peak_components_nm.items()},
            "peak_tension_n": float(dl.peak_tension_n[j]),
            "min_tension_n": float(dl.min_tension_n[j]),
            "peak_spool_tension_n": float(dl.peak_spool_tension_n[j]),
            "peak_motor_torque_nm": float(dl.peak_motor_torque_nm[j]),
            "route_efficiency": float(dl.route_efficiency[j]),
            "peak_step_rate_full_steps_s": float(dl.step_rate_full_steps_s[:, j].max()),
        })
    return {"per_joint": per_joint, "mean_mechanical_power_w": jl.mean_power_w,
            "mean_positive_power_w": jl.mean_positive_power_w,
            "link_masses": [{"mass_kg": float(m.mass_kg), "com_station_m": float(m.com_station_m),
                             "izz_com_kg_m2": float(m.izz_com_kg_m2)} for m in jl.link_masses]}


def run(args) -> int:
    params = load_design(args.params_file)
    cal = None
    if args.calibration:
        from swiftfin.core.calibration import load_calibration
        cal = load_calibration(args.calibration, params)
        before, params = params, cal.revised_params(params)
    mp = None
    if args.mass_properties:
        mp = MassProperties.from_dict(_read_json(args.mass_properties, MASS_PROPERTIES), args.mass_properties)
    boxes = _bboxes(args.parts_bbox) if args.parts_bbox else None
    records = None
    if args.build:
        built_mp, built_boxes, records = read_build_dir(args.build)
        mp = mp if mp is not None else built_mp
        boxes = boxes if boxes is not None else built_boxes
    ctx = RuleContext(params, mass_properties=mp, part_bboxes_mm=boxes, calibration=cal, print_records=records)
    findings = run_rules(ctx)
    worst = verdict(findings)
    print(f"swiftfin check {args.params_file}")
    if cal is not None:
        changes = cal.changes(before)
        print(f"calibrated by {args.calibration}: " + ("; ".join(changes) if changes else "nothing to apply"))
    print(format_table(findings))
    notes = [f for f in findings if f.severity >= Severity.NOT_EVALUATED and f.detail]
    if notes:
        print("\nwhy:")
        for f in notes:
            print(f"  {f.rule_id} ({f.severity.name}): {f.detail}")
    counts = {s.name: sum(1 for f in findings if f.severity is s) for s in Severity}
    print(f"\nverdict: {worst.name}  (" + ", ".join(f"{v} {k}" for k, v in counts.items() if v) + ")")
    report = {"params_file": str(args.params_file), "calibration": args.calibration, "verdict": worst.name,
              "findings": [f.to_dict() for f in findings]}
    if args.loads or args.json:
        report["loads"] = loads_report(ctx)
    if args.loads:
        sens = sensitivity_table(params)
        report["sensitivity"] = sens
        lr = report["loads"]
        print("\nloads at the design point (layout/loads.py):")
        print("  joint  amp[deg]  tau_peak[N m]  T_peak[N]  T_min[N]  motor[N m]  steps/s  route_eff")
        for r in lr["per_joint"]:
            print(f"  {r['joint']:5d}  {r['amplitude_deg']:8.2f}  {r['peak_torque_nm']:13.3f}  {r['peak_tension_n']:9.1f}"
                  f"  {r['min_tension_n']:8.1f}  {r['peak_motor_torque_nm']:10.3f}  {r['peak_step_rate_full_steps_s']:7.0f}"
                  f"  {r['route_efficiency']:9.3f}")
        print(f"  mean mechanical power {lr['mean_mechanical_power_w']:.2f} W "
              f"(positive part {lr['mean_positive_power_w']:.2f} W)")
        outs = list(next(iter(sens.values())))
        print("\nsensitivity d log(output) / d log(coefficient):")
        print("  " + "coefficient".ljust(38) + "".join(o.ljust(24) for o in outs))
        for k, row in sens.items():
            print("  " + k.ljust(38) + "".join(f"{row[o]:+.3f}".ljust(24) for o in outs))
    if args.json:
        _write_json(args.json, report)
    sys.stdout.flush()
    return 1 if worst >= Severity.FAIL else 0
