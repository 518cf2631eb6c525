"""The calibration file: physical values measured on a real joint, which ``swiftfin fit joint`` writes and
``swiftfin build --calibration`` and ``swiftfin check --calibration`` read (issue 14: close the loop).

A second input file beside the parameter file, so it lives with it in the foundation: this module parses and
validates it and knows nothing of how a value was fitted (``swiftfin.calibration.closing``) or where it is used
(``swiftfin.layout.servo`` for the simulator files' joints, ``swiftfin.layout.loads`` for the rules)::

    # swiftfin calibration: written by `swiftfin fit joint`
    [source]
    log = "bench_log.csv"
    log_sha256 = "..."
    design = "swiftfin.toml"
    design_sha256 = "..."

    [joint_4]                         # 1-based, as `swiftfin fit --joint`
    hinge_damping_nm_s_rad = { value = 0.0202, std = 5e-5, effect = "viscous_friction", confidence = "high" }
    hinge_friction_nm = { value = 0.019, std = 4e-4, effect = "coulomb_friction", confidence = "high" }

    [design]                          # design keys the measurement revises (its schema's range applies)
    "cable.youngs_modulus_gpa" = { value = 0.21, std = 0.002, effect = "cable_compliance", confidence = "high" }

Every value is a table ``{value, std, effect, confidence}`` (``std`` >= 0, the fit's standard error; ``effect``
the named effect it comes from). What a quantity means and where it goes is :data:`JOINT_QUANTITIES`. A bad
file is one :class:`~swiftfin.core.params.ParamError` naming the file, every bad key, its value and what was
expected (exit 2 at the command line).
"""
from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from swiftfin.core.params import (ParamError, Problem, _suggest, decode_text, get_key, params_from_dict,
                                  read_file_bytes, to_dict)
from swiftfin.core.schema import Params

WHAT = ("calibration file", "the calibration file")
FILE_NAME = "calibration.toml"
"""The name ``swiftfin fit joint`` writes it under, and the copy a calibrated build keeps."""

#: name -> (unit, where it is used). Applied: into the simulator files and the rules' load model. Recorded: kept
#: in the file for the record, used by neither (the reason given).
JOINT_QUANTITIES: dict[str, tuple[str, str]] = {
    "hinge_damping_nm_s_rad": ("N m s/rad", "applied: the joint's viscous damping (MJCF/URDF/SDF damping) and a "
                                            "c w torque in the rules' load model"),
    "hinge_friction_nm": ("N m", "applied: the joint's dry friction (MJCF frictionloss, URDF/SDF friction) and a "
                                 "tau_c sign(w) torque in the rules' load model"),
    "joint_stiffness_nm_rad": ("N m/rad", "applied: the cable pair's stiffness at the joint, in series with the "
                                          "stepper's in the MJCF position servo (kp)"),
    "dead_band_rad": ("rad", "recorded: slack in the drive; no simulator joint has a dead band (re-tension the "
                             "cable instead)"),
    "added_inertia_kg_m2": ("kg m^2", "recorded: inertia beyond the bench model's; the simulators take inertia "
                                      "from the mass properties and added mass from their fluid model"),
    "drag_coefficient_nm_s2_rad2": ("N m s^2/rad^2", "recorded: the simulators' fluid model gives the drag"),
    "spool_radius_ratio": ("-", "recorded: effective / design spool-to-arm ratio (a cable riding high in the "
                                "groove, a worn sector)"),
    "sensor_offset_rad": ("rad", "recorded: a property of the bench's sensor, not of the robot"),
    "sensor_delay_s": ("s", "recorded: a property of the bench's sensor, not of the robot"),
    "creep_per_travel": ("rad/rad", "recorded: cable creep round the drum per joint radian travelled"),
    "slip_rad": ("rad", "recorded: joint angle lost per missed-step event"),
}
APPLIED = ("hinge_damping_nm_s_rad", "hinge_friction_nm", "joint_stiffness_nm_rad")
#: design keys a calibration may revise (the schema's range applies to the revised value)
DESIGN_KEYS = ("cable.youngs_modulus_gpa",)
CONFIDENCES = ("high", "medium", "low")
SOURCE_KEYS = ("log", "log_sha256", "design", "design_sha256", "fit_report", "note")


@dataclass(frozen=True)
class Measured:
    """One measured value with its standard error and the effect of the fit it comes from."""
    value: float
    std: float
    effect: str
    confidence: str = "high"


@dataclass(frozen=True)
class JointCalibration:
    joint: int                                   # 1-based
    values: dict[str, Measured] = field(default_factory=dict)

    def get(self, name: str) -> float | None:
        m = self.values.get(name)
        return None if m is None else m.value


@dataclass(frozen=True)
class Calibration:
    source: dict[str, str]
    joints: tuple[JointCalibration, ...] = ()
    design: dict[str, Measured] = field(default_factory=dict)
    path: str = "<memory>"

    def joint(self, j: int) -> JointCalibration | None:
        """The calibration of joint ``j`` (1-based), or None."""
        return next((jc for jc in self.joints if jc.joint == j), None)

    def revised_params(self, p: Params) -> Params:
        """``p`` with the design keys this calibration revises, validated as a parameter file is (a value
        outside its key's range is refused, naming this file)."""
        if not self.design:
            return p
        raw = to_dict(p)
        for key, m in self.design.items():
            sec, name = key.split(".", 1)
            raw[sec][name] = m.value
        try:
            return params_from_dict(raw, self.path)
        except ParamError as exc:
            probs = [Problem(f"design.\"{pr.key}\"", pr.value, pr.expected) for pr in exc.problems]
            raise ParamError(self.path, probs, WHAT[1]) from None

    def changes(self, p: Params) -> list[str]:
        """One line per value this calibration changes or adds, for the commands to print."""
        out = [f"{key}: {get_key(p, key):g} -> {m.value:.4g} (+- {m.std:.2g}, {m.effect})"
               for key, m in self.design.items()]
        for jc in self.joints:
            for name in APPLIED:
                m = jc.values.get(name)
                if m is not None:
                    out.append(f"joint {jc.joint} {name}: {m.value:.4g} (+- {m.std:.2g}, {m.effect})")
        return out


def _measured(where: str, raw, out: list[Problem]) -> Measured | None:
    if not isinstance(raw, dict):
        out.append(Problem(where, raw, "expected a table { value = ..., std = ..., effect = \"...\" }"))
        return None
    bad = [k for k in raw if k not in ("value", "std", "effect", "confidence")]
    for k in bad:
        out.append(Problem(f"{where}.{k}", raw[k], "unknown key: a value has value, std, effect and confidence"
                           + _suggest(k, ("value", "std", "effect", "confidence"))))
    ok = not bad
    for k in ("value", "std"):
        v = raw.get(k)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            out.append(Problem(f"{where}.{k}", "(missing)" if v is None else v, "expected a finite number"))
            ok = False
    if ok and raw["std"] < 0:
        out.append(Problem(f"{where}.std", raw["std"], "a standard error is >= 0"))
        ok = False
    eff = raw.get("effect", "")
    if not isinstance(eff, str):
        out.append(Problem(f"{where}.effect", eff, "expected the name of the fitted effect (text)"))
        ok = False
    conf = raw.get("confidence", "high")
    if conf not in CONFIDENCES:
        out.append(Problem(f"{where}.confidence", conf, f"expected one of {', '.join(CONFIDENCES)}"))
        ok = False
    return Measured(float(raw["value"]), float(raw["std"]), eff, conf) if ok else None


def calibration_from_dict(raw: dict, p: Params, source: str = "<dict>") -> Calibration:
    """Validate a parsed calibration file against the design ``p`` (joints 1..count, design keys in range)."""
    out: list[Problem] = []
    src, joints, design = {}, [], {}
    for top, val in raw.items():
        if top == "source":
            if not isinstance(val, dict):
                out.append(Problem("source", val, "expected a table of text"))
                continue
            for k, v in val.items():
                if k not in SOURCE_KEYS:
                    out.append(Problem(f"source.{k}", v, f"unknown key (expected {', '.join(SOURCE_KEYS)})"
                                       + _suggest(k, SOURCE_KEYS)))
                elif not isinstance(v, str):
                    out.append(Problem(f"source.{k}", v, "expected text"))
                else:
                    src[k] = v
        elif top.startswith("joint_"):
            tail = top[len("joint_"):]
            if not tail.isdigit() or tail != str(int(tail)) or not 1 <= int(tail) <= p.joints.count:
                out.append(Problem(top, "(table)", f"expected joint_1 .. joint_{p.joints.count} (the design's "
                                                   f"joints, 1-based)"))
                continue
            if not isinstance(val, dict):
                out.append(Problem(top, val, "expected a table of measured values"))
                continue
            values = {}
            for name, m in val.items():
                if name not in JOINT_QUANTITIES:
                    out.append(Problem(f"{top}.{name}", m, "unknown quantity" + _suggest(name, JOINT_QUANTITIES)))
                    continue
                got = _measured(f"{top}.{name}", m, out)
                if got is None:
                    continue
                if name in ("hinge_damping_nm_s_rad", "hinge_friction_nm", "dead_band_rad", "added_inertia_kg_m2",
                            "drag_coefficient_nm_s2_rad2", "sensor_delay_s") and got.value < 0:
                    out.append(Problem(f"{top}.{name}.value", got.value, "expected >= 0"))
                elif name in ("joint_stiffness_nm_rad", "spool_radius_ratio") and got.value <= 0:
                    out.append(Problem(f"{top}.{name}.value", got.value, "expected > 0"))
                else:
                    values[name] = got
            joints.append(JointCalibration(int(tail), values))
        elif top == "design":
            if not isinstance(val, dict):
                out.append(Problem("design", val, "expected a table of design keys"))
                continue
            for key, m in val.items():
                if key not in DESIGN_KEYS:
                    out.append(Problem(f"design.\"{key}\"", m, f"not a key a calibration revises (expected "
                                                               f"{', '.join(DESIGN_KEYS)})"
                                       + _suggest(key, DESIGN_KEYS)))
                    continue
                got = _measured(f"design.\"{key}\"", m, out)
                if got is not None:
                    design[key] = got
        else:
            out.append(Problem(top, "(table)", "unknown table (expected source, joint_N, design)"
                               + _suggest(top, ("source", "design", "joint_1"))))
    if out:
        raise ParamError(source, out, WHAT[1])
    cal = Calibration(src, tuple(sorted(joints, key=lambda jc: jc.joint)), design, source)
    cal.revised_params(p)          # a revised key out of its range: refused now, naming this file
    return cal


def load_calibration(path: str | Path, p: Params) -> Calibration:
    """Read and validate a calibration file for the design ``p``."""
    name = str(path)
    text = decode_text(read_file_bytes(path, *WHAT), name, *WHAT)
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParamError(name, [Problem("(syntax)", str(exc), "the file is not valid TOML")], WHAT[1]) from None
    except (ValueError, RecursionError) as exc:
        raise ParamError(name, [Problem("(syntax)", type(exc).__name__, "the file is not valid TOML")],
                         WHAT[1]) from None
    return calibration_from_dict(raw, p, name)


def _value_toml(m: Measured) -> str:
    return (f"{{ value = {m.value!r}, std = {m.std!r}, effect = \"{m.effect}\", "
            f"confidence = \"{m.confidence}\" }}")


def calibration_toml(cal: Calibration) -> str:
    """The file :func:`load_calibration` reads, with a comment per quantity saying where it is used."""
    lines = ["# swiftfin calibration: physical values fitted from a measured joint log (swiftfin fit joint).",
             "# Use it with `swiftfin build --calibration FILE` and `swiftfin check --calibration FILE`.", "",
             "[source]"]
    lines += [f"{k} = {json.dumps(v, ensure_ascii=False)}" for k, v in cal.source.items()]
    for jc in cal.joints:
        lines += ["", f"[joint_{jc.joint}]"]
        for name, m in jc.values.items():
            unit, use = JOINT_QUANTITIES[name]
            lines += [f"# [{unit}] {use}", f"{name} = {_value_toml(m)}"]
    if cal.design:
        lines += ["", "[design]   # design keys the measurement revises"]
        lines += [f"\"{k}\" = {_value_toml(m)}" for k, m in cal.design.items()]
    return "\n".join(lines) + "\n"


def sha256_file(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
