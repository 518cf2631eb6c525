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
from dataclasses import dataclass, field
from typing import NamedTuple
from pathlib import Path

from swiftfin.core.params import (ParamError, Problem, get_key, params_from_dict, parse_toml_bytes,
                                  read_file_bytes, suggest, to_dict)
from swiftfin.core.schema import Params

WHAT = ("calibration file", "the calibration file")
FILE_NAME = "calibration.toml"
"""The name ``swiftfin fit joint`` writes it under, and the copy a calibrated build keeps."""

class Quantity(NamedTuple):
    unit: str
    lowest: float | None        # None: any sign
    strict: bool                # lowest excluded
    use: str                    # applied (simulator files, rules) or recorded only, and why


#: What a joint's calibration may hold. Applied: into the simulator files and the rules' load model. Recorded: kept
#: in the file for the record, used by neither (the reason given).
JOINT_QUANTITIES: dict[str, Quantity] = {
    "hinge_damping_nm_s_rad": Quantity("N m s/rad", 0.0, False,
                                       "applied: the joint's viscous damping (MJCF/URDF/SDF damping) and a c w "
                                       "torque in the rules' load model"),
    "hinge_friction_nm": Quantity("N m", 0.0, False, "applied: the joint's dry friction (MJCF frictionloss, URDF/SDF "
                                                    "friction) and a tau_c sign(w) torque in the rules' load model"),
    "joint_stiffness_nm_rad": Quantity("N m/rad", 0.0, True,
                                       "applied: the whole drive's stiffness between command and joint (stepper and "
                                       "cables in series), the MJCF position servo's kp"),
    "dead_band_rad": Quantity("rad", 0.0, False, "recorded: slack in the drive; no simulator joint has a dead band "
                                                 "(re-tension the cable instead)"),
    "added_inertia_kg_m2": Quantity("kg m^2", None, False,
                                    "recorded: inertia about the hinge beyond the bench model's (negative: a lighter "
                                    "link); the simulators take inertia from the mass properties and added mass "
                                    "from their fluid model"),
    "drag_coefficient_nm_s2_rad2": Quantity("N m s^2/rad^2", 0.0, False,
                                            "recorded: the simulators' fluid model gives the drag"),
    "spool_radius_ratio": Quantity("-", 0.0, True, "recorded: effective / design spool-to-arm ratio (a cable riding "
                                                   "high in the groove, a worn sector)"),
    "sensor_offset_rad": Quantity("rad", None, False, "recorded: a property of the bench's sensor, not of the robot"),
    "sensor_delay_s": Quantity("s", 0.0, False, "recorded: a property of the bench's sensor, not of the robot"),
    "creep_per_travel": Quantity("rad/rad", None, False,
                                 "recorded: cable creep round the drum per joint radian travelled"),
    "slip_rad": Quantity("rad", None, False, "recorded: joint angle lost per missed-step event"),
    "motor_holding_torque_nm": Quantity("N m", 0.0, True,
                                        "recorded: the torque the stepper gave on the bench, below its catalogue "
                                        "value (check the driver's current setting before changing the design)"),
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

    def get(self, name: str, default: float | None = None) -> float | None:
        """The measured value of ``name``, or ``default`` when the file has none."""
        m = self.values.get(name)
        return default if m is None else m.value


@dataclass(frozen=True)
class Calibration:
    source: dict[str, str]
    joints: tuple[JointCalibration, ...] = ()
    design: dict[str, Measured] = field(default_factory=dict)
    path: str = "<memory>"
    data: bytes = b""               # the file as read (a calibrated build keeps this copy)

    def joint(self, j: int) -> JointCalibration | None:
        """The calibration of joint ``j`` (1-based), or None."""
        return next((jc for jc in self.joints if jc.joint == j), None)

    def per_joint(self, name: str, n: int, default: float = 0.0) -> list[float]:
        """``name``'s measured value at joints 1..n, ``default`` where the file has none."""
        return [default if (jc := self.joint(j)) is None else jc.get(name, default) for j in range(1, n + 1)]

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
                           + suggest(k, ("value", "std", "effect", "confidence"))))
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


def _measured_table(where: str, raw, allowed, check, out: list[Problem],
                    unknown: str = "unknown quantity") -> dict[str, Measured]:
    """The ``{name: {value, std, effect, confidence}}`` table at ``where``, its names among ``allowed`` (else
    ``unknown``); ``check(name, measured)`` gives what is wrong with a value, or None."""
    if not isinstance(raw, dict):
        out.append(Problem(where, raw, "expected a table of measured values"))
        return {}
    values = {}
    for name, m in raw.items():
        key = f"{where}.\"{name}\"" if "." in name else f"{where}.{name}"
        if name not in allowed:
            out.append(Problem(key, m, f"{unknown} (expected one of {', '.join(allowed)})"
                               + suggest(name, allowed)))
            continue
        got = _measured(key, m, out)
        problem = None if got is None else check(name, got)
        if problem:
            out.append(Problem(f"{key}.value", got.value, problem))
        elif got is not None:
            values[name] = got
    return values


def _joint_value_problem(name: str, m: Measured) -> str | None:
    q = JOINT_QUANTITIES[name]
    if q.lowest is None or m.value > q.lowest or (m.value == q.lowest and not q.strict):
        return None
    return f"expected {'>' if q.strict else '>='} {q.lowest:g} {q.unit}"


def calibration_from_dict(raw: dict, p: Params, source: str = "<dict>", data: bytes = b"") -> Calibration:
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
                                       + suggest(k, SOURCE_KEYS)))
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
            joints.append(JointCalibration(int(tail), _measured_table(top, val, tuple(JOINT_QUANTITIES),
                                                                      _joint_value_problem, out)))
        elif top == "design":       # a revised key's range is the schema's: checked on the revised design below
            design = _measured_table("design", val, DESIGN_KEYS, lambda name, m: None, out,
                                     "not a key a calibration revises")
        else:
            out.append(Problem(top, "(table)", "unknown table (expected source, joint_N, design)"
                               + suggest(top, ("source", "design", "joint_1"))))
    if out:
        raise ParamError(source, out, WHAT[1])
    cal = Calibration(src, tuple(sorted(joints, key=lambda jc: jc.joint)), design, source, data)
    cal.revised_params(p)          # a revised key out of its range: refused now, naming this file
    return cal


def load_calibration(path: str | Path, p: Params) -> Calibration:
    """Read and validate a calibration file for the design ``p``."""
    name = str(path)
    data = read_file_bytes(path, *WHAT)
    return calibration_from_dict(parse_toml_bytes(data, name, *WHAT), p, name, data)


def _value_toml(m: Measured) -> str:
    return (f"{{ value = {m.value!r}, std = {m.std!r}, effect = {json.dumps(m.effect)}, "
            f"confidence = {json.dumps(m.confidence)} }}")


def calibration_toml(cal: Calibration) -> str:
    """The file :func:`load_calibration` reads, with a comment per quantity saying where it is used."""
    lines = ["# swiftfin calibration: physical values fitted from a measured joint log (swiftfin fit joint).",
             "# Use it with `swiftfin build --calibration FILE` and `swiftfin check --calibration FILE`.", "",
             "[source]"]
    lines += [f"{k} = {json.dumps(v, ensure_ascii=False)}" for k, v in cal.source.items()]
    for jc in cal.joints:
        lines += ["", f"[joint_{jc.joint}]"]
        for name, m in jc.values.items():
            q = JOINT_QUANTITIES[name]
            lines += [f"# [{q.unit}] {q.use}", f"{name} = {_value_toml(m)}"]
    if cal.design:
        lines += ["", "[design]   # design keys the measurement revises"]
        lines += [f"\"{k}\" = {_value_toml(m)}" for k, m in cal.design.items()]
    return "\n".join(lines) + "\n"


def sha256_file(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()
